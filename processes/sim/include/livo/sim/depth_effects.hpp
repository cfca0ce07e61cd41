// The depth image of an RGB-D camera (rig.camera.depth): the renderer's exact z-depth per pixel
// turned into what a stereo depth camera delivers, with range-dependent noise, a working range and
// holes at depth discontinuities and in random blobs (keys under `sim.depth`).
#pragma once

#include <cstdint>
#include <vector>

#include "livo/sim/random.hpp"

namespace livo::sim {

/// Defaults: an Intel RealSense D435-class active stereo camera.
///  - Noise: the RMS depth error of a stereo camera grows with the square of the distance,
///    sigma = z^2 s / (f B) (Grunnet-Jepsen, Sweetser, Woodfill, "Tuning depth cameras for best
///    performance", Intel white paper, 2019). D435: baseline B = 50 mm, f = 424 / tan(87 deg / 2)
///    = 447 px at 848 x 480, subpixel s = 0.08 (the white paper's typical value): 0.0036 / m.
///    Plus a floor for the quantisation and calibration ripple seen at close range.
///  - Range: minimum depth (min-Z) about 0.2 m at 848 x 480 and a maximum of about 10 m (Intel
///    RealSense D400 series datasheet, rev. 2019).
///  - Holes: stereo matching fails where one imager sees what the other cannot (a band of pixels at
///    each depth discontinuity, the occlusion shadow) and on surfaces its projector and texture do
///    not reach (blobs: dark, shiny or transparent patches); a few per cent of a typical indoor view.
struct DepthEffects {
  double noise_floor = 0.001;    // m, sigma at z = 0
  double noise_per_m2 = 0.0036;  // 1/m: sigma(z) = noise_floor + noise_per_m2 z^2
  double min_range = 0.2;        // m: nearer is no depth
  double max_range = 10.0;       // m: farther is no depth
  double edge_jump = 0.05;       // relative depth step between 4-neighbours that is a discontinuity
                                 // (also a pixel beside one without depth, e.g. sky)
  int edge_hole_px = 2;          // width of the band without depth on each side of a discontinuity (0: none)
  double hole_fraction = 0.02;   // expected share of pixels inside random blobs without depth
  double hole_radius_px = 6.0;   // mean radius of a blob (radii uniform in [0.5, 1.5] x this)

  double sigmaAt(double z) const { return noise_floor + noise_per_m2 * z * z; }
};

/// Millimetres per pixel (0: no depth) from the exact z-depth in metres per pixel (0: none, e.g.
/// sky or glass), row-major width x height. Everything random comes from `rng`: the blobs first,
/// then one normal draw per pixel that keeps its depth, in pixel order.
std::vector<uint16_t> measureDepth(const std::vector<float>& z_exact, int width, int height, const DepthEffects& e,
                                   Random rng);

}  // namespace livo::sim

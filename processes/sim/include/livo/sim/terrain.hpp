// Graded ground a ground vehicle drives on: z = h(x, y) = base + grade profiles + rolling relief,
// with exact gradient and Hessian (the car's attitude and the IMU follow from them).
// - A grade profile is a road designer's grade line along one horizontal direction: heights at
//   stations (the points of vertical intersection), straight grades between them and a parabolic
//   vertical curve of `curve_length` centred on each station (flat before the first and after the
//   last), so h is C1 with a piecewise constant second derivative. A ramp is two stations; a crowned
//   deck is a profile across the road (stations at -half width, 0, +half width).
// - Rolling relief is a sum of plane waves amplitude * sin(2 pi (d . p) / wavelength + phase); its
//   steepest grade is 2 pi amplitude / wavelength.
#pragma once

#include <vector>

#include "livo/so3.hpp"

namespace livo::sim {

struct GradeProfile {
  double direction_deg = 0.0;    // the station axis: 0 along +x, 90 along +y
  Vec2 origin = Vec2::Zero();    // the point of station 0, m
  std::vector<double> stations;  // m along the axis, increasing, at least 2
  std::vector<double> heights;   // m, one per station
  double curve_length = 20.0;    // m, of each vertical curve (centred on its station)
};

struct ReliefWave {
  double amplitude = 0.0;      // m
  double wavelength = 100.0;   // m
  double direction_deg = 0.0;  // direction the crests advance in: 0 along +x
  double phase_deg = 0.0;
};

struct TerrainOptions {
  double base = 0.0;  // m, the height where no profile or wave adds anything
  std::vector<GradeProfile> profiles;
  std::vector<ReliefWave> relief;
};

/// h(x, y), its gradient and its Hessian.
struct GroundJet {
  double height = 0.0;
  Vec2 gradient = Vec2::Zero();
  Eigen::Matrix2d hessian = Eigen::Matrix2d::Zero();
};

class Terrain {
 public:
  /// Throws std::invalid_argument for stations that do not increase, overlapping vertical curves,
  /// sizes that disagree, non-positive lengths or non-finite numbers.
  explicit Terrain(const TerrainOptions& options);

  GroundJet at(double x, double y) const;
  double height(double x, double y) const { return at(x, y).height; }

  /// Bounds over the whole plane: of |gradient| (the steepest grade) and of the Hessian's
  /// spectral norm (the sharpest curvature, 1/m).
  double maxGrade() const { return max_grade_; }
  double maxCurvature() const { return max_curvature_; }
  const TerrainOptions& options() const { return options_; }

 private:
  struct Profile {
    Vec2 direction, origin;
    std::vector<double> stations, heights;
    std::vector<double> grades;  // grades[i] runs into station i; grades[0] = grades[n] = 0
    double curve_length = 0.0;
  };
  struct Wave {
    Vec2 direction;                        // unit
    double wavenumber = 0.0, phase = 0.0;  // rad/m, rad
    double amplitude = 0.0;                // m
  };
  /// Height, slope and second derivative of a profile at station s.
  static void profileAt(const Profile& p, double s, double out[3]);

  TerrainOptions options_;
  std::vector<Profile> profiles_;
  std::vector<Wave> waves_;
  double max_grade_ = 0.0, max_curvature_ = 0.0;
};

}  // namespace livo::sim

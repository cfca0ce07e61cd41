// The iterated ESIKF update on the photometric residuals (paper eqs. 11-18), coarse to fine over
// the image pyramid, of the whole filter state: the pose and the camera's calibration are measured
// (photometric_residual.hpp), the rest moves through its correlation with them. At each level the
// patches correlating well enough at the current iterate are the measurement, and
// livo::informationStep (common/esikf_update.hpp) takes Gauss-Newton steps from the iterate
// against the original prior until the step is small; the next finer level starts where the
// coarser one ended. The image's measurement is then tested against the prior (a chi-square
// consistency gate) and fused with the reference floor (below). The result is checked: photometric
// cost not grown and the pose step within absolute bounds.
#pragma once

#include <string>
#include <vector>

#include "livo/camera_projection.hpp"
#include "livo/esikf_update.hpp"
#include "livo/filter_state.hpp"
#include "livo/vio/image_pyramid.hpp"
#include "livo/vio/photometric_residual.hpp"
#include "livo/vio/vio_options.hpp"

namespace livo::vio {

struct DirectUpdateResult {
  bool valid = false;
  std::string why;    // when not valid
  FilterState state;  // posterior (the prior when not valid)
  StateCovariance covariance = StateCovariance::Zero();
  int iterations = 0;           // Gauss-Newton steps over all levels
  int num_measurements = 0;     // scalar residuals of the last step
  int patches = 0;              // patches of the last step
  double cost_prior = 0.0;      // Huber cost per residual at level 0 over the final patches:
  double cost_post = 0.0;       //   at the prior and at the aligned pose (the posterior without floors)
  ConsistencyTest consistency;  // of the image's measurement against the prior
};

/// The reference floor of an image at body attitude R_W_I: the mean of its patches' reference pose
/// covariances (UpdateOptions::reference_floor), the rotation block turned into the body frame of
/// the pose error [δθ δp] (right perturbation of R_W_I).
Mat6 referenceFloor(const std::vector<TrackedPatch>& patches, const Mat3& R_W_I);

/// Runs the update from the prior (at the image stamp, with the camera's calibration; the shutter's
/// omega_I is the body rate); fills each patch's active / ncc / rms (level 0, at the posterior).
DirectUpdateResult directUpdate(const FilterState& prior, const StateCovariance& P_prior, const ImagePyramid& pyramid,
                                const CameraProjection& camera, const PhotometricOptions& photometric,
                                const UpdateOptions& update, std::vector<TrackedPatch>* patches,
                                const RollingShutter& shutter = RollingShutter());

}  // namespace livo::vio

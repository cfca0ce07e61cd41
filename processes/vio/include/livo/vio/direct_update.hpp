// The iterated ESIKF update on the photometric residuals (paper eqs. 11-18), coarse to fine over
// the image pyramid: at each level the patches correlating well enough at the current iterate
// are the measurement, and livo::informationStep (common/esikf_update.hpp) takes Gauss-Newton
// steps from the iterate against the original prior until the step is small; the next finer
// level starts where the coarser one ended. The posterior covariance is that of the last step at
// level 0. The result is then checked: photometric cost not grown, the pose step within the
// prior's uncertainty (Mahalanobis) and within absolute bounds.
#pragma once

#include <string>
#include <vector>

#include "livo/camera_projection.hpp"
#include "livo/filter_state.hpp"
#include "livo/vio/image_pyramid.hpp"
#include "livo/vio/photometric_residual.hpp"
#include "livo/vio/vio_options.hpp"

namespace livo::vio {

struct DirectUpdateResult {
  bool valid = false;
  std::string why;                    // when not valid
  FilterState state;                  // posterior (the prior when not valid)
  Mat18 covariance = Mat18::Zero();
  int iterations = 0;                 // Gauss-Newton steps over all levels
  int num_measurements = 0;           // scalar residuals of the last step
  int patches = 0;                    // patches of the last step
  double cost_prior = 0.0;            // Huber cost per residual at level 0 over the final patches:
  double cost_post = 0.0;             //   at the prior and at the posterior
  double mahalanobis = 0.0;           // squared, of the pose step against the prior covariance
  Vec3 camera_rotation = Vec3::Zero();  // estimated correction φ of T_I_C (when estimated)
  Mat3 camera_rotation_cov = Mat3::Zero();
};

/// Runs the update; fills each patch's active / ncc / rms (level 0, at the posterior).
DirectUpdateResult directUpdate(const FilterState& prior, const Mat18& P_prior, const ImagePyramid& pyramid,
                                const CameraProjection& camera, const Pose3& T_I_C, const PhotometricOptions& photometric,
                                const UpdateOptions& update, std::vector<TrackedPatch>* patches,
                                const RollingShutter& shutter = RollingShutter(),
                                const Mat3* camera_rotation_cov = nullptr);

}  // namespace livo::vio

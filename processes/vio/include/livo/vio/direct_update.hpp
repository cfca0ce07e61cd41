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
  double cost_post = 0.0;             //   at the prior and at the aligned pose (the posterior without floors)
  double mahalanobis = 0.0;           // squared, of the pose step against the prior covariance
  CalibrationVector calibration = CalibrationVector::Zero();  // the correction c (when estimated)
  CalibrationMatrix calibration_cov = CalibrationMatrix::Zero(); // its posterior covariance
};

/// The camera calibration as a nuisance of the update (CalibrationInformation): eliminated from
/// every Gauss-Newton step by its Schur complement against its own prior N(0, covariance),
/// uncorrelated with the filter (Schmidt-like), then solved for. Only the entries with a positive
/// prior variance are estimated; the others stay 0.
struct CalibrationPrior {
  CalibrationMatrix covariance = CalibrationMatrix::Zero();
  Vec3 omega_I = Vec3::Zero();  // body rate at the image, rad/s (the δt column, with the state's velocity)
  double time_offset = 0.0;     // s, the δt estimated so far: the state is moved by it before projecting
};

/// The position floor of an image seen from camera centre c_W (world, m²): a camera rotated by ε
/// against the LiDAR-registered body sees a reference patch captured a baseline b away shifted as
/// if it had moved by ε × b; with ε ~ N(0, rotation_std² I) that is σ² [b]× [b]×ᵀ, averaged over the
/// patches. Nothing along the baselines (a corridor's axis keeps its information).
Mat3 calibrationFloor(const std::vector<TrackedPatch>& patches, const Vec3& c_W, double rotation_std);

/// The reference floor of an image at body attitude R_W_I: the mean of its patches' reference pose
/// covariances (UpdateOptions::reference_floor), the rotation block turned into the body frame of
/// the pose error [δθ δp] (right perturbation of R_W_I).
Mat6 referenceFloor(const std::vector<TrackedPatch>& patches, const Mat3& R_W_I);

/// Runs the update; fills each patch's active / ncc / rms (level 0, at the posterior).
DirectUpdateResult directUpdate(const FilterState& prior, const Mat18& P_prior, const ImagePyramid& pyramid,
                                const CameraProjection& camera, const Pose3& T_I_C, const PhotometricOptions& photometric,
                                const UpdateOptions& update, std::vector<TrackedPatch>* patches,
                                const RollingShutter& shutter = RollingShutter(),
                                const CalibrationPrior* calibration = nullptr);

}  // namespace livo::vio

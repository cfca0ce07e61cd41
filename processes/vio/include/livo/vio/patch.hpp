// Image patches of the point-patch map: the 8x8 patch the residual is computed on, the 16x16
// patch stored per observation and level (a margin so the reference can be warped into the
// current view and re-centred where the state's camera calibration projects the point into the
// reference image), and the affine warp between two views of a map point.
//
// Warp model: the fronto-parallel approximation. The surface around the point is taken as the
// plane through it perpendicular to the reference camera's ray, and the warp is that plane's
// homography linearised at the point (both projections with their distortion), i.e. the 2x2
// map from current pixel offsets to reference pixel offsets. No surface normal is needed; for
// the view changes at which the map refreshes patches the error is a small fraction of a pixel
// over an 8x8 patch.
#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "livo/camera_projection.hpp"
#include "livo/so3.hpp"
#include "livo/vio/image_pyramid.hpp"

namespace livo::vio {

constexpr int kPatch = 8;                        // residual patch side (pixels of a level)
constexpr int kPatchArea = kPatch * kPatch;
constexpr int kWindow = kPatch + 2;              // with a one-pixel margin for gradients
constexpr int kStored = 16;                      // stored reference patch side
constexpr int kStoredArea = kStored * kStored;
constexpr int kMaxLevels = 4;

/// Level-0 border a point needs so that every level's window and stored patch fit.
inline double patchBorder(int levels) { return (0.5 * kStored + 1.0) * static_cast<double>(1 << (levels - 1)); }

/// Samples the stored patches (kStored^2 per level, rounded to 8 bits) of a point seen at
/// level-0 pixel u0; false if one does not fit in its level.
bool extractStoredPatches(const ImagePyramid& pyramid, const Eigen::Vector2d& u0, int levels, uint8_t* out);

/// The 2x2 warp A with (reference pixel offset) = A (current pixel offset) for the map point p_W,
/// fronto-parallel to the reference ray; false if p_W does not project into both cameras.
bool affineWarp(const CameraProjection& camera, const Pose3& T_W_Ccur, const Pose3& T_W_Cref, const Vec3& p_W,
                Eigen::Matrix2d* A);

/// The reference patch warped into the current view: out[j*kPatch + i] is the stored patch
/// (one level) at `shift` + A (i - 3.5, j - 3.5) from its centre (shift: where the reference image
/// sees the point now, relative to where the patch was cut, in the level's pixels). With gx, gy
/// also the derivative of each sample with respect to the shift (the bilinear interpolant's
/// gradient). False if that leaves the stored patch.
bool warpReferencePatch(const uint8_t* stored_level, const Eigen::Matrix2d& A, const Eigen::Vector2d& shift, float* out,
                        float* gx = nullptr, float* gy = nullptr);

/// Mean |dI/dx| + |dI/dy| (central differences) over the kPatch x kPatch patch at u (level
/// coordinates of `level`); -1 if it does not fit.
float patchGradient(const ImagePyramid& pyramid, int level, const Eigen::Vector2d& u);

}  // namespace livo::vio

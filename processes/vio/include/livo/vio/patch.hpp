// Image patches of the point-patch map: the 8x8 patch the residual is computed on, the 16x16
// patch stored per observation and level (a margin so the reference can be warped into the
// current view and re-centred where the state's camera calibration projects the point into the
// reference image), and the affine warp between two views of a map point.
//
// Warp model: the surface around the point is the plane through it with the LiDAR's normal where
// the map knows one (FAST-LIVO2's), else perpendicular to the reference camera's ray (the
// fronto-parallel approximation); the warp is that plane's homography linearised at the point
// (both projections with their distortion), i.e. the 2x2 map from current pixel offsets to
// reference pixel offsets. On a surface seen obliquely the fronto-parallel warp is off by the
// change of foreshortening between the views (a floor seen 60 deg off its normal, views 10 deg
// apart: 30 % of the patch's extent).
#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "livo/camera_projection.hpp"
#include "livo/so3.hpp"
#include "livo/vio/image_pyramid.hpp"

namespace livo::vio {

constexpr int kPatch = 8;  // residual patch side (pixels of a level)
constexpr int kPatchArea = kPatch * kPatch;
constexpr int kWindow = kPatch + 2;  // with a one-pixel margin for gradients
constexpr int kStored = 16;          // stored reference patch side
constexpr int kStoredArea = kStored * kStored;
constexpr int kMaxLevels = 4;

/// Level-0 border a point needs so that every level's window and stored patch fit.
inline double patchBorder(int levels) { return (0.5 * kStored + 1.0) * static_cast<double>(1 << (levels - 1)); }

/// Samples the stored patches (kStored^2 per level, rounded to 8 bits) of a point seen at
/// level-0 pixel u0; false if one does not fit in its level.
bool extractStoredPatches(const ImagePyramid& pyramid, const Eigen::Vector2d& u0, int levels, uint8_t* out);

/// Below this |cos| between the surface normal and the reference ray the plane is seen nearly
/// edge-on (beyond 80 deg) and the warp falls back to fronto-parallel.
constexpr double kMinNormalIncidence = 0.17;

/// The 2x2 warp A with (reference pixel offset) = A (current pixel offset) for the map point p_W on
/// the plane with normal `normal_W` (zero or nearly edge-on to the reference ray: fronto-parallel
/// to that ray); false if p_W does not project into both cameras.
bool affineWarp(const CameraProjection& camera, const Pose3& T_W_Ccur, const Pose3& T_W_Cref, const Vec3& p_W,
                const Vec3& normal_W, Eigen::Matrix2d* A);

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

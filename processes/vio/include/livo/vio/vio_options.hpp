// Options of the direct photometric VIO core, with their defaults (README.md lists them as the
// `vio:` config keys). Plain structs: the core never reads files.
#pragma once

#include <string>

namespace livo::vio {

/// The point-patch map (paper 2.3.2): one LiDAR point per voxel, each with the patches it was
/// observed in; bounded like the LIO map by a radius around the camera and a point count.
struct MapOptions {
  double voxel_size = 0.3;          // m: at most one map point per voxel
  double radius = 30.0;             // m: points farther from the camera are dropped
  int max_points = 10000;           // beyond this the least recently seen points are dropped
  int max_observations = 4;         // patches kept per point (the oldest goes first)
  int recent_scans = 2;             // REGISTERED_SCANs kept as the source of new points and occluders
  double plane_snap_max_rms = 0.0;  // m: a scan's point for a voxel is moved onto the plane of all the
                                    // scan's points in that voxel when they lie this close to it
                                    // (RMS) and spread twice as wide as thick; 0: raw points
  int plane_snap_min_points = 6;    // fewer points in the voxel: the raw point is kept
  double normal_max_rms = 0.0;      // m: a map point takes the normal of its voxel's scan points
                                    // when at least normal_min_points lie this close to their plane
                                    // (RMS) and spread over it (voxelPoints); the patch warp then
                                    // follows that plane; 0: no normals, the fronto-parallel warp
  int normal_min_points = 6;
};

/// Which map points take part in an update.
struct SelectionOptions {
  int grid_cell_px = 32;                   // at most one tracked point per grid cell of the image
  double min_depth = 0.3;                  // m
  double max_depth = 30.0;                 // m
  int depth_cell_px = 6;                   // cell of the occlusion depth buffer
  double occlusion_tolerance = 0.1;        // m: a point this much (plus the relative part) behind
  double occlusion_tolerance_rel = 0.1;    //    the nearest LiDAR/map point in its cell is occluded
  double max_view_angle_deg = 30.0;        // reference patches seen from farther off are not used
  double depth_edge_radius_px = 16.0;      // the LiDAR/map points this close to a point in the image ...
  double depth_edge_tolerance = 0.03;      // ... must lie on a plane with it to within this (m) ...
  double depth_edge_tolerance_rel = 0.03;  // ... plus this fraction of its depth; else it sits on a
                                           // depth edge: not tracked, not added (parallax breaks
                                           // the patch)
  double view_angle_weight = 1.0;          // reference score: angle (deg) * this
  double error_weight = 0.2;               //   + photometric error of the patch (grey levels) * this
  double age_weight = 0.05;                //   + age (s) * this; the lowest score is the reference
};

/// The photometric residual (paper eq. 10) and its robust weighting.
struct PhotometricOptions {
  int pyramid_levels = 3;         // 1..4; the update runs coarse to fine
  double noise_std = 30.0;        // grey levels per pixel: R = noise_std^2 I (see README: far above
                                  // the sensor noise, as the patch residuals are correlated)
  double huber_threshold = 10.0;  // grey levels: residuals beyond get weight threshold / |r|
  bool affine_brightness = true;  // per-patch gain and offset (else offset only)
  double min_gain = 0.5;          // gain bounds, relative to the exposure-time ratio (1 if unknown)
  double max_gain = 2.0;
  double min_ncc = 0.3;    // a patch correlating worse at the start of a level is dropped
  double point_std = 0.0;  // m per axis: how well a map point's position is known (the
                           // LiDAR's range noise: rig.lidar.range_noise_std unless set); each
                           // patch's point is eliminated against it (accumulate()); 0: exact
  // How well the body's motion from a reference image to the current one is known (the LIO's
  // relative accuracy): each patch's reference pose is a nuisance with this uncertainty,
  // eliminated likewise; otherwise a relative error of the trajectory over a patch's baseline b
  // looks like a camera rotation of about error / b and would be taken for one. 0: exact.
  // The rotation's: what the LIO's relative rotations are off by over a reference's life (room_hard
  // tuning seeds 1-3 against the truth: 0.04-0.07 deg per axis below 5 deg turned, 0.07-0.11 at 5-10)
  double reference_rotation_std_deg = 0.1;     // deg per axis
  double reference_translation_std = 0.001;    // m per axis, plus ...
  double reference_translation_per_m = 0.005;  // ... this fraction of the baseline
};

/// What the posterior covariance of a photometric update counts (the step always uses all the
/// photometric information): kFull, all of it, as for an independent measurement; kBeyondPrior,
/// only what exceeds the prior direction by direction (livo::informationBeyondPrior), since the
/// patches and map points are the filter's own past estimates and their errors are correlated
/// with its state (README).
enum class CovarianceUpdate { kFull, kBeyondPrior };

/// The iterated ESIKF update and its acceptance tests.
struct UpdateOptions {
  int max_iterations = 4;         // per pyramid level
  double convergence_rot = 1e-4;  // rad
  double convergence_pos = 1e-4;  // m
  int min_patches = 15;           // fewer usable patches: no update (valid = 0)
  // The consistency gate: the image's measurement of the pose and the camera's calibration (where
  // it says at least a hundredth of what the prior knows), tested against prior plus measurement
  // covariance (chi-square, as many degrees of freedom as such directions, livo::consistencyTest);
  // an update beyond this quantile is not adopted.
  double gate_probability = 0.999;
  // The share of an image's information on the camera's calibration that the update takes: the
  // images of a second reuse the same map points and reference patches, whose errors they share,
  // so their information on the constant calibration is not independent from image to image
  // (about one in `1 / scale` is new). The calibration then accumulates what is new, as a Kalman
  // filter of a constant should. 1: every image counted in full.
  double calibration_information_scale = 0.2;
  double max_step_pos = 0.3;  // m
  double max_step_rot_deg = 5.0;
  CovarianceUpdate covariance = CovarianceUpdate::kBeyondPrior;  // "full" or "beyond_prior"
  // Scale of the reference floor: a reference patch was cut at the pose the filter had then, so
  // the image measures the current pose only as well as its references' poses were known. Each
  // observation keeps that pose covariance; an image's pose measurement gets the floor
  // scale × mean_i(P_ref,i) over its patches (referenceFloor). 0: the references are taken as exact.
  double reference_floor = 1.0;
  // rad/s: an image updates the gyro bias only while the prior's 1-sigma on it (largest axis) is
  // above this, i.e. while the filter is still finding it. The camera's rotation against the
  // LiDAR-registered body is known to a few tenths of a degree, and that offset pulls every image's
  // attitude the same way while the LiDAR pulls it back; a filter free to explain the tug of war
  // with a gyro bias learns a wrong one, and the accelerometer bias follows (0.7 m/s² in a
  // corridor, after which a 180° turn drives the velocity off by metres per second). Below it the
  // update considers the bias (Schmidt: kept at the prior, its correlations updated) and leaves it
  // to the IMU and the LiDAR. 0: always updated.
  double gyro_bias_std_to_update = 1e-4;
};

/// Map maintenance after each image (paper 2.3.2).
struct MaintenanceOptions {
  int new_point_cell_px = 32;           // grid for new points: cells with no tracked point get one
  double min_gradient = 3.0;            // grey levels / pixel (level 1): weaker candidates are skipped
  int max_new_points = 200;             // per image
  double refresh_angle_deg = 10.0;      // a new patch when the view turned this far from every patch
  double refresh_distance_ratio = 1.3;  // ... or the distance changed by this factor
  double refresh_error = 12.0;          // ... or the reference's residual RMS grew beyond this (grey levels)
  double outlier_ncc = 0.5;             // no new patch from a view correlating worse (occluded, moved)
};

struct VioOptions {
  MapOptions map;
  SelectionOptions selection;
  PhotometricOptions photometric;
  UpdateOptions update;
  MaintenanceOptions maintenance;
};

/// Throws std::invalid_argument naming the first option out of range.
void validate(const VioOptions& o);

}  // namespace livo::vio

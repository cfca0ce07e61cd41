#include "livo/loop/loop_config.hpp"

#include <ostream>

namespace livo::loop {

LoopNodeOptions readLoopNodeOptions(const Config& root) {
  LoopNodeOptions o;
  const Config s = root.optionalSection("loop");
  if (s.isNull()) return o;
  const Config ch = s.optionalSection("channels");
  ch.readOptional("keyframe", o.keyframe_channel);
  ch.readOptional("loop_correction", o.loop_correction_channel);
  s.readOptional("output_dir", o.output_dir);
  s.readOptional("global_map_voxel", o.global_map_voxel);
  LoopCloserOptions& c = o.core;
  s.readOptional("coarse_voxel", c.coarse.voxel_size);
  s.readOptional("fpfh_normal_radius", c.coarse.normal_radius);
  s.readOptional("fpfh_radius", c.coarse.feature_radius);
  s.readOptional("max_keypoints", c.coarse.max_keypoints);
  s.readOptional("keypoint_nms_radius", c.coarse.keypoints.nms_radius);
  s.readOptional("fine_voxel", c.fine_voxel_size);
  s.readOptional("feature_cache_keyframes", c.feature_cache_keyframes);
  s.readOptional("search_radius", c.candidates.search_radius);
  s.readOptional("exclude_recent_s", c.candidates.exclude_recent_s);
  s.readOptional("max_candidates", c.candidates.max_candidates);
  s.readOptional("cooldown_keyframes", c.candidates.cooldown_keyframes);
  s.readOptional("noise_bound", c.registration.quatro.noise_bound);
  s.readOptional("quasi_so3", c.registration.quatro.quasi_so3);
  s.readOptional("max_correspondence_distance", c.registration.gicp.max_correspondence_distance);
  s.readOptional("min_coarse_inliers", c.registration.acceptance.min_coarse_inliers);
  s.readOptional("max_fitness", c.registration.acceptance.max_fitness);
  s.readOptional("min_overlap", c.registration.acceptance.min_overlap);
  s.readOptional("min_translation_eigenvalue", c.registration.acceptance.min_translation_eigenvalue);
  s.readOptional("min_translation_eigenvalue_ratio", c.registration.acceptance.min_translation_eigenvalue_ratio);
  s.readOptional("odometry_rotation_floor", c.odometry_rotation_floor);
  s.readOptional("odometry_translation_floor", c.odometry_translation_floor);
  s.readOptional("odometry_rotation_per_m", c.odometry_rotation_per_m);
  s.readOptional("odometry_translation_per_m", c.odometry_translation_per_m);
  s.readOptional("loop_rotation_sigma", c.loop_rotation_sigma);
  s.readOptional("loop_translation_sigma", c.loop_translation_sigma);
  s.readOptional("registration_information", c.registration_information);
  s.readOptional("loop_min_rotation_sigma", c.loop_information.min_rotation_sigma);
  s.readOptional("loop_fitness_rotation_sigma", c.loop_information.fitness_rotation_sigma);
  s.readOptional("loop_roll_pitch_sigma", c.loop_information.roll_pitch_sigma);
  s.readOptional("loop_min_translation_sigma", c.loop_information.min_translation_sigma);
  s.readOptional("loop_max_rotation_sigma", c.loop_information.max_rotation_sigma);
  s.readOptional("loop_max_translation_sigma", c.loop_information.max_translation_sigma);
  s.readOptional("loop_min_constrained_fraction", c.loop_information.min_constrained_fraction);
  s.readOptional("consistency_check", c.consistency_check);
  s.readOptional("consistency_chi2", c.consistency_chi2);
  s.readOptional("min_correction_translation", c.min_correction_translation);
  s.readOptional("min_correction_rotation", c.min_correction_rotation);
  s.readOptional("correction_chi2", c.correction_chi2);
  s.readOptional("correction_from_optimum", c.correction_from_optimum);
  s.readOptional("optimize_at_exit", c.optimize_at_exit);
  s.readOptional("gravity_prior_sigma", c.gravity_prior_sigma);
  if (!(c.gravity_prior_sigma >= 0)) throw ConfigError(s.where("gravity_prior_sigma") + ": must be >= 0 (0: off)");
  s.readOptional("odometry_covariance_from_filter", c.odometry_covariance_from_filter);
  s.readOptional("odometry_covariance_scale", c.odometry_covariance_scale);
  s.readOptional("compose_held_calibration", c.compose_held_calibration);
  if (!(c.odometry_covariance_scale > 0)) throw ConfigError(s.where("odometry_covariance_scale") + ": must be > 0");
  s.readOptional("merge_distance", c.merge_distance);
  s.checkAllUsed();
  if (c.coarse.voxel_size <= 0 || c.fine_voxel_size <= 0 || c.candidates.search_radius <= 0 ||
      c.registration.quatro.noise_bound <= 0)
    throw ConfigError(s.where("coarse_voxel") + ": voxel sizes, search_radius and noise_bound must be > 0");
  if (c.merge_distance < 0 || c.min_correction_translation < 0 || c.min_correction_rotation < 0)
    throw ConfigError(s.where("merge_distance") + ": merge_distance and min_correction_* must be >= 0");
  if (!(c.correction_chi2 >= 0)) throw ConfigError(s.where("correction_chi2") + ": must be >= 0 (0: off)");
  const LoopInformationOptions& li = c.loop_information;
  if (!(li.min_rotation_sigma > 0 && li.min_translation_sigma > 0 && li.max_rotation_sigma > li.min_rotation_sigma &&
        li.max_translation_sigma > li.min_translation_sigma && li.min_constrained_fraction >= 0 &&
        li.fitness_rotation_sigma >= 0 && li.roll_pitch_sigma >= 0 && li.min_constrained_fraction < 1))
    throw ConfigError(s.where("loop_min_rotation_sigma") +
                      ": loop_min_*_sigma must be > 0, loop_max_*_sigma greater than them and "
                      "loop_min_constrained_fraction in [0, 1)");
  if (!(c.loop_rotation_sigma > 0 && c.loop_translation_sigma > 0))
    throw ConfigError(s.where("loop_rotation_sigma") + ": loop_rotation_sigma and loop_translation_sigma must be > 0");
  if (!(c.consistency_chi2 > 0)) throw ConfigError(s.where("consistency_chi2") + ": consistency_chi2 must be > 0");
  return o;
}

void printOptions(const LoopNodeOptions& o, std::ostream& os) {
  const LoopCloserOptions& c = o.core;
  const AcceptanceOptions& a = c.registration.acceptance;
  os << "loop: input " << o.keyframe_channel << "; output " << o.loop_correction_channel << "; files "
     << (o.output_dir.empty() ? std::string("none") : o.output_dir + "/{keyframes.tum,loops.json,global_map.ply}")
     << "\n  candidates within " << c.candidates.search_radius << " m, older than " << c.candidates.exclude_recent_s
     << " s, at most " << c.candidates.max_candidates << " per keyframe, " << c.candidates.cooldown_keyframes
     << " keyframes of cooldown\n  coarse: voxel " << c.coarse.voxel_size << " m, FPFH radius "
     << c.coarse.feature_radius << " m, at most " << c.coarse.max_keypoints << " keypoints, noise bound "
     << c.registration.quatro.noise_bound << " m; fine: voxel " << c.fine_voxel_size << " m, GICP max distance "
     << c.registration.gicp.max_correspondence_distance << " m\n  accepted with at least " << a.min_coarse_inliers
     << " coarse inliers, fitness <= " << a.max_fitness << ", overlap >= " << a.min_overlap << "; consistency check "
     << (c.consistency_check ? "on" : "off") << " (chi2 " << c.consistency_chi2 << "); a correction only beyond "
     << c.min_correction_translation << " m / " << c.min_correction_rotation << " rad and chi2 " << c.correction_chi2
     << (c.correction_from_optimum ? ", where the optimum moves the keyframe as much" : "")
     << "; odometry edges weighted by "
     << (c.odometry_covariance_from_filter ? "the odometry's increment covariances (the drift model where none)"
                                           : "the drift model")
     << (c.compose_held_calibration ? "" : " without their held-calibration part") << "\n";
}

}  // namespace livo::loop

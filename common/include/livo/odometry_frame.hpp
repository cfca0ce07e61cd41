// The frame an odometry process's poses are in, and a loop correction as it adopts one
// (lcmtypes/loop_correction_t.lcm): shared by livo-lio and livo-lio-graph, which adopt
// LOOP_CORRECTION the same way. The message side (parsing, the adoption checks) is in
// livo/loop_correction_message.hpp.
#pragma once

#include <cstdint>

#include "livo/so3.hpp"

namespace livo {

/// The frame an estimator's poses are in: its odometry epoch (+1 at every reset) and the newest
/// loop correction adopted in it.
struct OdometryFrame {
  int32_t epoch = 0;
  int64_t correction_id = 0;        // 0: the raw odometry frame O of the epoch
  Pose3 T_C_O = Pose3::Identity();  // odometry_to_corrected of that correction
};

/// A corrected keyframe pose of a loop correction.
struct KeyframePose {
  int64_t id;
  Pose3 pose;  // corrected W_T_I
};

/// A loop correction to adopt: its id, T_Ck_O, and T_Ck_Cj from the previous correction j.
struct LoopCorrection {
  int64_t id = 0;
  int64_t previous_id = 0;
  Pose3 T_Ck_O = Pose3::Identity();
  Pose3 T_Ck_Cj = Pose3::Identity();
};

/// The rigid transform that moves poses of `frame` onto the correction's frame C_k: T_Ck_Cj when
/// the frame is the correction's predecessor j, T_Ck_O * T_C_O^-1 when corrections were missed.
inline Pose3 correctionStep(const OdometryFrame& frame, const LoopCorrection& correction) {
  return correction.previous_id == frame.correction_id ? correction.T_Ck_Cj
                                                       : Pose3(correction.T_Ck_O * frame.T_C_O.inverse());
}

}  // namespace livo

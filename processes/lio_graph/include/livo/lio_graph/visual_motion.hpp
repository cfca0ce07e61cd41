// The visual subsystem's estimate (livo-vio-feature's VISUAL_STATE) as livo-lio-graph uses it: the
// body's motion between two times, in the body frame of the first (the visual world V and the
// graph's W are unrelated, so only relative motion passes between them). The paper's "visual
// subsystem assists motion distortion correction": the deskew's translation and the scan-matching
// guess come from it when it covers the sweep.
#pragma once

#include <cstdint>
#include <deque>

#include "livo/so3.hpp"

namespace livo::lio_graph {

struct VisualSample {
  int64_t utime = 0;               // IMU clock
  Pose3 pose = Pose3::Identity();  // V_T_I
  int32_t epoch = 0;               // the visual subsystem's; a new one starts a new frame V
};

class VisualMotion {
 public:
  /// Buffers a sample; false (with why) if it is not later than the previous one of its epoch or
  /// not finite. A new epoch drops the older samples. Samples older than `keep_s` before the
  /// newest are dropped.
  bool add(const VisualSample& s, std::string* why = nullptr, double keep_s = 2.0);
  /// T_I0_I1, the body at t1 in the body at t0, interpolated between the samples around each; false
  /// unless both lie within the buffered span.
  bool relative(int64_t t0, int64_t t1, Pose3* T_0_1) const;
  int64_t newest() const { return samples_.empty() ? INT64_MIN : samples_.back().utime; }
  bool empty() const { return samples_.empty(); }

 private:
  bool at(int64_t t, Pose3* pose) const;
  std::deque<VisualSample> samples_;
};

}  // namespace livo::lio_graph

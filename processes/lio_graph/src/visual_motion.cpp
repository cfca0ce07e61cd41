#include "livo/lio_graph/visual_motion.hpp"

#include <string>

#include "livo/time.hpp"

namespace livo::lio_graph {

bool VisualMotion::add(const VisualSample& s, std::string* why, double keep_s) {
  if (!s.pose.matrix().allFinite()) {
    if (why) *why = "non-finite visual state";
    return false;
  }
  if (!samples_.empty() && s.epoch != samples_.back().epoch) samples_.clear();
  if (!samples_.empty() && s.utime <= samples_.back().utime) {
    if (why) *why = "visual state not later than the previous one";
    return false;
  }
  samples_.push_back(s);
  while (samples_.size() > 2 && samples_.front().utime < s.utime - toUtime(keep_s)) samples_.pop_front();
  return true;
}

bool VisualMotion::at(int64_t t, Pose3* pose) const {
  if (samples_.empty() || t < samples_.front().utime || t > samples_.back().utime) return false;
  size_t k = 0;
  while (k + 1 < samples_.size() && samples_[k + 1].utime < t) ++k;
  const VisualSample& a = samples_[k];
  if (k + 1 == samples_.size() || a.utime == t) {
    *pose = a.pose;
    return true;
  }
  const VisualSample& b = samples_[k + 1];
  const double s = static_cast<double>(t - a.utime) / static_cast<double>(b.utime - a.utime);
  const Mat3 R = a.pose.linear() * so3::Exp(s * so3::Log(Mat3(a.pose.linear().transpose() * b.pose.linear())));
  *pose = se3::fromRotationTranslation(R, (1.0 - s) * a.pose.translation() + s * b.pose.translation());
  return true;
}

bool VisualMotion::relative(int64_t t0, int64_t t1, Pose3* T_0_1) const {
  Pose3 a, b;
  if (!at(t0, &a) || !at(t1, &b)) return false;
  *T_0_1 = a.inverse() * b;
  return true;
}

}  // namespace livo::lio_graph

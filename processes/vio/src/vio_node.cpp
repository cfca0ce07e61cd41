#include "livo/vio/vio_node.hpp"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <iomanip>
#include <sstream>

#include "livo/correction_frames.hpp"
#include "livo/message_checks.hpp"
#include "livo/messages.hpp"
#include "livo/time.hpp"
#include "livo/vio/vio_messages.hpp"

namespace livo::vio {

namespace {
constexpr size_t kAnsweredIds = 64;

NodeOptions nodeOptions(const VioNodeOptions& o, bool quiet) {
  NodeOptions n;
  n.name = o.name;
  n.quiet = quiet;
  return n;
}
}  // namespace

VioNode::VioNode(lcm::LCM& lcm, VioNodeOptions options, bool quiet)
    : options_(std::move(options)),
      node_(lcm, nodeOptions(options_, quiet)),
      vio_(options_.core, options_.camera),
      offset_us_(toUtime(options_.camera_time_offset_s)),
      tolerance_us_(toUtime(options_.time_tolerance_s)) {
  node_.declareOutput(options_.state_posterior_channel);
  node_.subscribe<image_t>(options_.camera_channel, [this](const image_t& m) { onImage(m); });
  node_.subscribe<filter_state_t>(options_.state_prior_channel, [this](const filter_state_t& m) { onPrior(m); });
  node_.subscribe<registered_scan_t>(options_.registered_scan_channel,
                                     [this](const registered_scan_t& m) { onScan(m); });
  node_.subscribe<loop_correction_t>(options_.loop_correction_channel,
                                     [this](const loop_correction_t& m) { onCorrection(m); });
  // lockstep playback need not wait for what publishes nothing here: a scan only joins the map,
  // and an image is only buffered while no prior waits for one
  node_.setQuietWindows([this] {
    std::vector<Node::QuietWindow> w{Node::QuietWindow::always(options_.registered_scan_channel)};
    if (pending_.empty()) w.push_back(Node::QuietWindow::always(options_.camera_channel));
    return w;
  });
}

void VioNode::onImage(const image_t& m) {
  BufferedImage b;
  b.t = m.utime + offset_us_;
  if (!readGreyImage(rawImage(m), options_.camera.width, options_.camera.height, options_.image_check, &b.image,
                     &b.problem)) {
    node_.reject(options_.camera_channel, b.problem);
    b.image.pixels.release();
    ++counts_.bad_images;
  } else {
    ++counts_.images;
  }
  b.image.utime = b.t;
  const auto it =
      std::upper_bound(images_.begin(), images_.end(), b.t, [](int64_t t, const BufferedImage& e) { return t < e.t; });
  images_.insert(it, std::move(b));
  resolve();
}

MapFrame::Placed VioNode::placeInMap(int32_t epoch, int64_t correction_id) {
  return frame_.place(epoch, correction_id, [&](int32_t old_epoch) {
    // the LIO was reset: its new odometry frame has nothing to do with the map's
    node_.warn("odometry epoch " + std::to_string(epoch) + " (LIO reset): dropping the map of epoch " +
               std::to_string(old_epoch) + " (" + std::to_string(vio_.map().size()) + " points) and " +
               std::to_string(pending_.size()) + " waiting priors");
    vio_.reset();
    pending_.clear();
    ++counts_.epochs_started;
  });
}

void VioNode::onPrior(const filter_state_t& m) {
  const StatePrior prior = decodePrior(m);
  const MapFrame::Placed placed = placeInMap(prior.epoch, prior.correction_id);
  if (placed.placement == MapFrame::Placement::kOldEpoch) {
    // lio was reset since: it ignores any answer, so none is sent
    node_.reject(options_.state_prior_channel, "prior " + std::to_string(prior.request_id) + " " + placed.why);
    return;
  }
  if (placed.placement == MapFrame::Placement::kUnknownFrame) {
    keep(prior, placed.why);
    return;
  }
  if (std::find(answered_ids_.begin(), answered_ids_.end(), prior.request_id) != answered_ids_.end() ||
      std::any_of(pending_.begin(), pending_.end(),
                  [&](const StatePrior& p) { return p.request_id == prior.request_id; })) {
    node_.reject(options_.state_prior_channel, "duplicate prior (request id already seen): not answered again");
    return;
  }
  if (placed.moved) {
    // the map and the prior are in different loop corrections (it was made before lio adopted the
    // newest one the map has): the image could only be matched after moving one onto the other
    keep(prior, "prior made in another loop correction than the map's (" + std::to_string(prior.correction_id) +
                    " vs " + std::to_string(frame_.correctionId()) + ")");
    return;
  }
  const auto it = std::upper_bound(pending_.begin(), pending_.end(), prior.utime,
                                   [](int64_t t, const StatePrior& p) { return t < p.utime; });
  pending_.insert(it, prior);
  resolve();
}

void VioNode::resolve() {
  while (!pending_.empty()) {
    const StatePrior prior = pending_.front();
    // the image at the prior's time (the nearest within the tolerance)
    auto best = images_.end();
    for (auto it = images_.begin(); it != images_.end(); ++it)
      if (std::llabs(it->t - prior.utime) <= tolerance_us_ &&
          (best == images_.end() || std::llabs(it->t - prior.utime) < std::llabs(best->t - prior.utime)))
        best = it;
    if (best != images_.end()) {
      pending_.pop_front();
      const BufferedImage image = std::move(*best);
      for (auto it = images_.begin(); it != best; ++it) counts_.unused_images += it->problem.empty();
      images_.erase(images_.begin(), best + 1);  // it and everything older are used up
      if (!image.problem.empty())
        keep(prior, "bad image at the prior's time: " + image.problem);
      else
        process(prior, image);
      // older priors cannot get an image any more (pending_ is sorted; they were answered above)
      continue;
    }
    const bool newer_image = !images_.empty() && images_.back().t > prior.utime + tolerance_us_;
    const bool newer_prior = pending_.size() > 1;
    if (newer_image || newer_prior || static_cast<int>(pending_.size()) > options_.max_buffered_images) {
      pending_.pop_front();
      keep(prior, newer_image ? "no image at the prior's time (a newer image came)"
                              : "no image at the prior's time (a newer prior came)");
      continue;
    }
    break;  // wait for the image
  }
  trimImages();
}

void VioNode::trimImages() {
  if (images_.empty()) return;
  const int64_t horizon = images_.back().t - toUtime(options_.image_buffer_s);
  while (!images_.empty() &&
         (images_.front().t < horizon || static_cast<int>(images_.size()) > options_.max_buffered_images)) {
    if (images_.front().problem.empty()) ++counts_.unused_images;
    images_.pop_front();
  }
}

void VioNode::process(const StatePrior& prior, const BufferedImage& image) {
  if (!prior.problem.empty()) {
    node_.reject(options_.state_prior_channel, prior.problem);
    keep(prior, prior.problem);
    return;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const ImageResult r = vio_.processImage(image.image, prior.x, prior.P, prior.body_rate);
  node_.recordWork("image", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  if (!r.valid) {
    keep(prior, r.why);
    return;
  }
  node_.publish(options_.state_posterior_channel, toPosterior(prior.message, options_.name, r.state, r.covariance, true,
                                                              r.iterations, r.num_measurements));
  answered_ids_.push_back(prior.request_id);
  if (answered_ids_.size() > kAnsweredIds) answered_ids_.pop_front();
  ++counts_.priors;
  ++counts_.updated;
}

void VioNode::keep(const StatePrior& prior, const std::string& why) {
  node_.publish(options_.state_posterior_channel, keptPrior(prior.message, options_.name));
  answered_ids_.push_back(prior.request_id);
  if (answered_ids_.size() > kAnsweredIds) answered_ids_.pop_front();
  ++counts_.priors;
  ++counts_.kept;
  kept_reasons_.add(why);
  const std::string key = ReasonCounts::key(why);  // reasons with numbers grouped by their text
  auto it = last_warned_.find(key);
  if (it == last_warned_.end() || prior.utime - it->second >= 1000000 || prior.utime < it->second) {
    last_warned_[key] = prior.utime;
    node_.warn("prior " + std::to_string(prior.request_id) + " at " + std::to_string(prior.utime) +
               " kept (valid = 0): " + why);
  }
}

void VioNode::reportKeptReasons() {
  if (!kept_reasons_.empty()) node_.warn(kept_reasons_.summary("priors kept"));
}

void VioNode::onScan(const registered_scan_t& m) {
  if (const std::string why = registeredScanProblem(m); !why.empty()) {
    node_.reject(options_.registered_scan_channel, why);
    return;
  }
  const MapFrame::Placed placed = placeInMap(m.epoch, m.correction_id);
  if (placed.placement != MapFrame::Placement::kUse) {
    node_.reject(options_.registered_scan_channel, placed.why);
    return;
  }
  const point_cloud_t& c = m.cloud;
  if (placed.moved) {  // made before lio adopted the map's correction: moved onto it
    std::vector<Vec3> points(static_cast<size_t>(c.num_points));
    for (size_t i = 0; i < points.size(); ++i) points[i] = placed.to_map * Vec3(c.x[i], c.y[i], c.z[i]);
    vio_.addScan(m.utime, points);
  } else {
    vio_.addScan(m.utime, c.x.data(), c.y.data(), c.z.data(), static_cast<size_t>(c.num_points));
  }
  ++counts_.scans;
}

void VioNode::onCorrection(const loop_correction_t& m) {
  Pose3 T_Ck_O;
  if (const std::string why = correctionTransform(m, &T_Ck_O); !why.empty()) {
    node_.reject(options_.loop_correction_channel, "loop correction: " + why);
    return;
  }
  const MapFrame::CorrectionStep step = frame_.addCorrection(m.correction_id, m.epoch, T_Ck_O);
  if (!step.apply) {
    node_.info("loop correction " + std::to_string(m.correction_id) + " not applied: " + step.why);
    return;
  }
  const Pose3& T = step.unlisted;
  vio_.applyCorrection(T);
  std::ostringstream s;
  s << "loop correction: moved " << vio_.map().size() << " map points by " << T.translation().norm() << " m";
  node_.info(s.str());
}

}  // namespace livo::vio

// The livo-vio node on LCM's in-process memq:// provider, fed with images and scans of the
// simulated room: every STATE_PRIOR answered exactly once with its request id and utime, a
// prior waiting for its image, a prior without an image kept, bad images and malformed
// messages refused and counted, the camera time offset, loop corrections, and identical
// posteriors for identical inputs.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include <lcm/lcm-cpp.hpp>

#include "livo/filter_state_message.hpp"
#include "livo/messages.hpp"
#include "livo/progress_t.hpp"
#include "livo/vio/vio_node.hpp"
#include "sim_fixture.hpp"

using namespace livo;
using namespace livo::vio;

namespace {

std::string roomConfig(const std::string& extra = "") {
  std::ifstream f(std::string(LIVO_SOURCE_DIR) + "/config/sim/room.yaml");
  std::stringstream s;
  s << f.rdbuf();
  std::string text = s.str();
  // the shipped config may carry an empty `vio: {}` for the pipeline script: a test's own vio
  // section replaces it (with two vio keys the test's would be ignored)
  if (extra.rfind("vio:", 0) == 0)
    if (const size_t at = text.find("\nvio: {}\n"); at != std::string::npos) text.erase(at + 1, 8);
  return text + extra;
}

const livo_test::SimScene& scene() {
  static const livo_test::SimScene s;
  return s;
}

// The seed image, the update image and a third one, rendered once per test process.
constexpr double kT0 = 6.0, kT1 = 6.05, kT2 = 6.1;
const GreyImage& rendered(int k) {
  static const std::vector<GreyImage> images = {scene().image(kT0, 1), scene().image(kT1, 2), scene().image(kT2, 3)};
  return images[static_cast<size_t>(k)];
}

image_t imageMsg(const GreyImage& g, int64_t utime) {
  image_t m{};
  m.utime = utime;
  m.frame = "C";
  m.width = g.pixels.cols;
  m.height = g.pixels.rows;
  m.row_stride = g.pixels.cols;
  m.encoding = image_t::ENCODING_GRAY8;
  m.exposure_time = g.exposure_time;
  m.data.assign(g.pixels.datastart, g.pixels.dataend);
  m.size = static_cast<int32_t>(m.data.size());
  return m;
}

registered_scan_t scanMsg(int64_t utime, const std::vector<Vec3>& points, const Pose3& T_W_I) {
  registered_scan_t s{};
  s.utime = utime;
  poseTo(T_W_I, s.position, s.orientation);
  point_cloud_t& c = s.cloud;
  c.utime = utime - 100000;
  c.frame = "W";
  c.sweep_duration = 0.1f;
  for (const Vec3& p : points) {
    c.x.push_back(static_cast<float>(p.x()));
    c.y.push_back(static_cast<float>(p.y()));
    c.z.push_back(static_cast<float>(p.z()));
  }
  c.num_points = static_cast<int32_t>(points.size());
  c.intensity.assign(points.size(), 0.0f);
  c.time_offset.assign(points.size(), 0.0f);
  c.ring.assign(points.size(), -1);
  return s;
}

// A prior as lio sends it: with the body rate at its time (the true one here).
filter_state_t priorMsg(int64_t utime, int64_t id, const FilterState& x, const StateCovariance& P) {
  const double t = static_cast<double>(utime - scene().utime(0.0)) * 1e-6;
  return toFilterState(utime, x, P, id, "lio", scene().bodyRate(t));
}

FilterState offsetState(const FilterState& x) {
  StateVector d = StateVector::Zero();
  d.head<3>() = Vec3(0.2, 0.3, -0.1).normalized() * (0.4 * M_PI / 180.0);
  d.segment<3>(3) = Vec3(-0.01, 0.02, 0.01).normalized() * 0.025;
  return x.boxplus(d);
}

const StateCovariance& priorP() {
  static const StateCovariance P = livo_test::priorCovariance(1.0 * M_PI / 180.0, 0.05);
  return P;
}

// The seed's prior is the truth, and its covariance says so (0.03 deg, 1 mm): the references cut
// there carry it (vio.update.reference_floor).
const StateCovariance& seedP() {
  static const StateCovariance P = livo_test::priorCovariance(5e-4, 0.001);
  return P;
}

template <class M>
std::vector<uint8_t> encode(const M& m) {
  std::vector<uint8_t> b(static_cast<size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

// A VioNode and an observer of its STATE_POSTERIOR on one memq:// bus.
struct Harness {
  lcm::LCM lcm{"memq://"};
  std::unique_ptr<VioNode> vio;
  Node observer{lcm, NodeOptions{"observer", "PROGRESS_OBS", "HEALTH_OBS", 0.0, false, true, {}}};
  std::vector<filter_state_t> posteriors;
  std::vector<std::vector<uint8_t>> posterior_bytes;

  explicit Harness(const std::string& config = roomConfig()) {
    EXPECT_TRUE(lcm.good());
    vio = std::make_unique<VioNode>(lcm, readVioNodeOptions(Config::fromString(config)), true);
    observer.subscribeRaw("STATE_POSTERIOR", [this](const void* data, int size) {
      const auto* b = static_cast<const uint8_t*>(data);
      posterior_bytes.emplace_back(b, b + size);
      filter_state_t m;
      EXPECT_EQ(m.decode(data, 0, size), size);
      posteriors.push_back(m);
    });
  }
  template <class M>
  void send(const std::string& channel, const M& m) {
    lcm.publish(channel, &m);
    drain();
  }
  void sendRaw(const std::string& channel, const std::vector<uint8_t>& bytes) {
    lcm.publish(channel, bytes.data(), static_cast<unsigned>(bytes.size()));
    drain();
  }
  void drain() {
    while (lcm.handleTimeout(0) > 0) {
    }
  }
  channel_stats_t stats(const std::string& channel) const {
    for (const auto& c : vio->node().channelStats())
      if (c.channel == channel) return c;
    return channel_stats_t{};
  }
  // Two scans before kT0, the seed image and its prior at the true pose (answered valid = 0: the
  // map is empty; the map is then seeded).
  void seed(int64_t id = 1) {
    const auto& s = scene();
    send("REGISTERED_SCAN", scanMsg(s.utime(kT0 - 0.1), s.sweep(kT0 - 0.2, 1), s.bodyPose(kT0 - 0.1)));
    send("REGISTERED_SCAN", scanMsg(s.utime(kT0), s.sweep(kT0 - 0.1, 2), s.bodyPose(kT0)));
    send("CAMERA", imageMsg(rendered(0), s.utime(kT0)));
    send("STATE_PRIOR", priorMsg(s.utime(kT0), id, s.trueState(kT0), seedP()));
  }
};

double positionError(const filter_state_t& m, const FilterState& truth) {
  return (vec3From(m.position) - truth.pos).norm();
}

}  // namespace

TEST(VioNode, ReadsTheRigAndAStrictVioSection) {
  const VioNodeOptions d = readVioNodeOptions(Config::fromString(roomConfig()));
  EXPECT_EQ(d.camera.width, 640);
  EXPECT_DOUBLE_EQ(d.camera.fx, 400.0);
  EXPECT_NEAR(d.camera.distortion[0], -0.05, 1e-12);
  EXPECT_EQ(d.camera_channel, "CAMERA");
  EXPECT_DOUBLE_EQ(d.camera_time_offset_s, 0.0);
  EXPECT_EQ(d.core.photometric.pyramid_levels, 3);
  const VioNodeOptions o = readVioNodeOptions(Config::fromString(roomConfig(
      "vio:\n  name: vio2\n  channels: {state_prior: PRIOR2}\n  map: {voxel_size: 0.25, max_points: 5000}\n"
      "  photometric: {noise_std: 8.0, affine_brightness: false}\n  update: {max_iterations: 3, covariance: full}\n"
      "  new_points: {min_gradient: 4.0}\n  refresh: {angle_deg: 12.0}\n  selection: {depth_edge_radius_px: 20}\n")));
  EXPECT_EQ(o.name, "vio2");
  EXPECT_EQ(o.state_prior_channel, "PRIOR2");
  EXPECT_DOUBLE_EQ(o.core.map.voxel_size, 0.25);
  EXPECT_EQ(o.core.map.max_points, 5000);
  EXPECT_DOUBLE_EQ(o.core.photometric.noise_std, 8.0);
  EXPECT_FALSE(o.core.photometric.affine_brightness);
  EXPECT_EQ(o.core.update.max_iterations, 3);
  EXPECT_DOUBLE_EQ(o.core.maintenance.min_gradient, 4.0);
  EXPECT_DOUBLE_EQ(o.core.maintenance.refresh_angle_deg, 12.0);
  EXPECT_DOUBLE_EQ(o.core.selection.depth_edge_radius_px, 20.0);
  EXPECT_EQ(d.core.update.covariance, CovarianceUpdate::kBeyondPrior);
  EXPECT_EQ(o.core.update.covariance, CovarianceUpdate::kFull);
  EXPECT_DOUBLE_EQ(d.core.map.plane_snap_max_rms, 0.0);  // off unless asked for
  EXPECT_THROW(readVioNodeOptions(Config::fromString(roomConfig("vio:\n  update: {covariance: half}\n"))), ConfigError);
  EXPECT_THROW(readVioNodeOptions(Config::fromString(roomConfig("vio:\n  map: {voxel_sise: 0.3}\n"))), ConfigError);
  // the map points are LiDAR returns: known to the rig's range noise unless vio.photometric.point_std says
  EXPECT_DOUBLE_EQ(d.core.photometric.point_std, 0.01);  // rig.lidar.range_noise_std
  // the consistency gate and the calibration's share of an image's information
  const VioNodeOptions g = readVioNodeOptions(Config::fromString(roomConfig(
      "vio:\n  photometric: {point_std: 0.02, reference_rotation_std_deg: 0.05, reference_translation_std: 0.002,\n"
      "                reference_translation_per_m: 0.01}\n"
      "  update: {gate_probability: 0.99, calibration_information_scale: 0.1}\n")));
  EXPECT_DOUBLE_EQ(g.core.photometric.point_std, 0.02);
  EXPECT_DOUBLE_EQ(g.core.photometric.reference_rotation_std_deg, 0.05);
  EXPECT_DOUBLE_EQ(g.core.photometric.reference_translation_std, 0.002);
  EXPECT_DOUBLE_EQ(g.core.photometric.reference_translation_per_m, 0.01);
  EXPECT_DOUBLE_EQ(g.core.update.gate_probability, 0.99);
  EXPECT_DOUBLE_EQ(g.core.update.calibration_information_scale, 0.1);
  EXPECT_DOUBLE_EQ(d.core.update.gate_probability, 0.999);
  // the keys of what was removed (the camera's calibration is now the filter's state, the body rate
  // comes with the prior, the Mahalanobis test is the consistency gate) are unknown keys: refused
  for (const char* removed :
       {"vio:\n  calibration: {camera_rotation_std_deg: 0.3}\n", "vio:\n  calibration: {time_offset_std: 0.002}\n",
        "vio:\n  rotation_calibration: {enabled: true}\n", "vio:\n  rotation_calibration: {against: filter}\n",
        "vio:\n  update: {calibration_rotation_std_deg: 0.3}\n", "vio:\n  update: {max_mahalanobis: 50}\n",
        "vio:\n  channels: {imu: IMU}\n", "vio:\n  channels: {camera_free_state: STATE_CAMERA_FREE}\n"}) {
    try {
      readVioNodeOptions(Config::fromString(roomConfig(removed)));
      ADD_FAILURE() << "accepted a removed key: " << removed;
    } catch (const ConfigError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("unknown key"), std::string::npos) << removed << " -> " << what;
    }
  }
  EXPECT_THROW(readVioNodeOptions(Config::fromString(roomConfig("vio:\n  photometric: {pyramid_levels: 7}\n"))),
               ConfigError);
  EXPECT_THROW(readVioNodeOptions(Config::fromString(roomConfig("vio:\n  image_buffer_s: -1\n"))), ConfigError);
  std::string offset = roomConfig();
  offset.replace(offset.find("    color: false"), 16, "    color: false\n    time_offset_s: 0.02");
  EXPECT_DOUBLE_EQ(readVioNodeOptions(Config::fromString(offset)).camera_time_offset_s, 0.02);
  // the rig's rolling-shutter readout (a datasheet number): 0 by default, at most one frame
  EXPECT_DOUBLE_EQ(d.camera.rolling_shutter_s, 0.0);
  std::string readout = roomConfig();
  readout.replace(readout.find("    color: false"), 16, "    color: false\n    rolling_shutter_s: 0.02");
  EXPECT_DOUBLE_EQ(readVioNodeOptions(Config::fromString(readout)).camera.rolling_shutter_s, 0.02);
  for (const char* bad : {"-0.001", "0.06"}) {  // 20 Hz: a frame is 0.05 s
    std::string b = roomConfig();
    b.replace(b.find("    color: false"), 16, std::string("    color: false\n    rolling_shutter_s: ") + bad);
    EXPECT_THROW(readVioNodeOptions(Config::fromString(b)), ConfigError) << bad;
  }
  std::string no_camera = roomConfig();
  const size_t c0 = no_camera.find("  camera:\n"), c1 = no_camera.find("sim:");
  no_camera.erase(c0, c1 - c0);
  EXPECT_THROW(readVioNodeOptions(Config::fromString(no_camera)), ConfigError);
}

TEST(VioNode, AnswersEveryPriorOnceWithItsRequestIdAndUpdates) {
  Harness h;
  const auto& s = scene();
  h.seed(41);
  ASSERT_EQ(h.posteriors.size(), 1u);
  EXPECT_EQ(h.posteriors[0].request_id, 41);
  EXPECT_EQ(h.posteriors[0].utime, s.utime(kT0));
  EXPECT_EQ(h.posteriors[0].valid, 0);  // nothing in the map yet
  EXPECT_EQ(h.posteriors[0].source, "vio");
  EXPECT_GT(h.vio->estimator().map().size(), 50u);
  // the body rate is the prior's (filter_state_t.angular_velocity): the patches cut keep it
  const Vec3 rate = vec3From(priorMsg(s.utime(kT0), 41, s.trueState(kT0), seedP()).angular_velocity);
  EXPECT_GT(rate.norm(), 0.0);
  for (const MapPoint& m : h.vio->estimator().map().points()) EXPECT_EQ(m.observations[0].view.omega_I, rate);

  const FilterState truth = s.trueState(kT1), prior = offsetState(truth);
  h.send("CAMERA", imageMsg(rendered(1), s.utime(kT1)));
  EXPECT_EQ(h.posteriors.size(), 1u);  // an image alone is not answered
  h.send("STATE_PRIOR", priorMsg(s.utime(kT1), 42, prior, priorP()));
  ASSERT_EQ(h.posteriors.size(), 2u);
  const filter_state_t& post = h.posteriors[1];
  EXPECT_EQ(post.request_id, 42);
  EXPECT_EQ(post.utime, s.utime(kT1));
  ASSERT_EQ(post.valid, 1);
  EXPECT_GT(post.iterations, 0);
  EXPECT_GE(post.num_measurements, 50 * 64);
  EXPECT_NEAR((prior.pos - truth.pos).norm(), 0.025, 1e-9);
  EXPECT_LT(positionError(post, truth), 0.005);
  EXPECT_LT(so3::Log(truth.rot.transpose() * quatFromWxyz(post.orientation).toRotationMatrix()).norm(),
            0.1 * M_PI / 180.0);
  // the covariance shrank on the pose; the calibration the prior holds fixed (zero rows and columns)
  // is left so, and the camera's extrinsic and time shift come back as the prior's
  const StateCovariance P = matrixFrom<FilterState::kDim>(post.covariance);
  const double trace_post = P.topLeftCorner<6, 6>().trace(), trace_prior = priorP().topLeftCorner<6, 6>().trace();
  EXPECT_LT(trace_post, 0.5 * trace_prior);
  EXPECT_TRUE(P.rightCols<2 * FilterState::kCalibrationDim>().isZero(0.0));
  EXPECT_TRUE(isUsableCovariance(P));
  FilterState x_post;
  StateCovariance P_post;
  ASSERT_TRUE(fromFilterState(post, &x_post, &P_post));
  EXPECT_TRUE(x_post.camera.pose().isApprox(s.camera().T_I_C, 1e-12));
  EXPECT_EQ(x_post.camera.dt, 0.0);
  EXPECT_EQ(h.vio->counts().priors, 2);
  EXPECT_EQ(h.vio->counts().updated, 1);
  EXPECT_EQ(h.vio->counts().kept, 1);
  EXPECT_EQ(h.vio->node().published("STATE_POSTERIOR"), 2);
}

TEST(VioNode, HoldsAPriorUntilItsImageArrives) {
  Harness h;
  const auto& s = scene();
  h.seed();
  const FilterState truth = s.trueState(kT1);
  h.send("STATE_PRIOR", priorMsg(s.utime(kT1), 2, offsetState(truth), priorP()));
  EXPECT_EQ(h.posteriors.size(), 1u);  // waiting
  h.send("CAMERA", imageMsg(rendered(1), s.utime(kT1)));
  ASSERT_EQ(h.posteriors.size(), 2u);
  EXPECT_EQ(h.posteriors[1].request_id, 2);
  EXPECT_EQ(h.posteriors[1].valid, 1);
  EXPECT_LT(positionError(h.posteriors[1], truth), 0.005);
}

TEST(VioNode, APriorWithoutItsImageIsKeptWhenANewerImageOrPriorComes) {
  Harness h;
  const auto& s = scene();
  h.seed();
  // no image at kT1: answered valid = 0 once the image of kT2 arrives
  h.send("STATE_PRIOR", priorMsg(s.utime(kT1), 2, s.trueState(kT1), priorP()));
  EXPECT_EQ(h.posteriors.size(), 1u);
  h.send("CAMERA", imageMsg(rendered(2), s.utime(kT2)));
  ASSERT_EQ(h.posteriors.size(), 2u);
  EXPECT_EQ(h.posteriors[1].request_id, 2);
  EXPECT_EQ(h.posteriors[1].valid, 0);
  EXPECT_EQ(h.posteriors[1].utime, s.utime(kT1));
  // the kept prior is echoed
  EXPECT_EQ(std::vector<double>(h.posteriors[1].covariance,
                                h.posteriors[1].covariance + FilterState::kDim * FilterState::kDim),
            std::vector<double>(priorP().data(), priorP().data() + FilterState::kDim * FilterState::kDim));
  // the image of kT2 still serves its own prior
  h.send("STATE_PRIOR", priorMsg(s.utime(kT2), 3, offsetState(s.trueState(kT2)), priorP()));
  ASSERT_EQ(h.posteriors.size(), 3u);
  EXPECT_EQ(h.posteriors[2].request_id, 3);
  EXPECT_EQ(h.posteriors[2].valid, 1);
  // a prior without an image followed by a newer prior: the first is kept, the second waits
  h.send("STATE_PRIOR", priorMsg(s.utime(7.0), 4, s.trueState(7.0), priorP()));
  h.send("STATE_PRIOR", priorMsg(s.utime(7.05), 5, s.trueState(7.05), priorP()));
  ASSERT_EQ(h.posteriors.size(), 4u);
  EXPECT_EQ(h.posteriors[3].request_id, 4);
  EXPECT_EQ(h.posteriors[3].valid, 0);
  EXPECT_EQ(h.vio->keptReasons().count("no image at the prior's time"), 1u);
}

TEST(VioNode, BadImagesAreRejectedAndTheirPriorsKept) {
  Harness h;
  const auto& s = scene();
  h.seed();
  GreyImage black = rendered(1);
  black.pixels = cv::Mat(black.pixels.size(), CV_8UC1, cv::Scalar(2));
  h.send("CAMERA", imageMsg(black, s.utime(kT1)));
  h.send("STATE_PRIOR", priorMsg(s.utime(kT1), 2, s.trueState(kT1), priorP()));
  GreyImage white = rendered(2);
  white.pixels = cv::Mat(white.pixels.size(), CV_8UC1, cv::Scalar(255));
  h.send("CAMERA", imageMsg(white, s.utime(kT2)));
  h.send("STATE_PRIOR", priorMsg(s.utime(kT2), 3, s.trueState(kT2), priorP()));
  image_t small = imageMsg(rendered(2), s.utime(7.0));
  small.width = 320;  // wrong size for the rig
  h.send("CAMERA", small);
  h.send("STATE_PRIOR", priorMsg(s.utime(7.0), 4, s.trueState(7.0), priorP()));
  image_t jpeg = imageMsg(rendered(2), s.utime(7.05));
  jpeg.encoding = image_t::ENCODING_JPEG;  // raw bytes are no JPEG
  h.send("CAMERA", jpeg);
  h.send("STATE_PRIOR", priorMsg(s.utime(7.05), 5, s.trueState(7.05), priorP()));
  ASSERT_EQ(h.posteriors.size(), 5u);
  for (size_t i = 1; i < 5; ++i) {
    EXPECT_EQ(h.posteriors[i].request_id, static_cast<int64_t>(i + 1));
    EXPECT_EQ(h.posteriors[i].valid, 0);
  }
  EXPECT_EQ(h.stats("CAMERA").rejected, 4);
  EXPECT_EQ(h.vio->counts().bad_images, 4);
  int64_t bad = 0;
  for (const auto& [why, n] : h.vio->keptReasons())
    if (why.rfind("bad image at the prior's time: ", 0) == 0) bad += n;
  EXPECT_EQ(bad, 4);
}

TEST(VioNode, MalformedMessagesAreCountedAndNotAnswered) {
  Harness h;
  const auto& s = scene();
  const std::vector<uint8_t> garbage(100, 0x42);
  h.sendRaw("STATE_PRIOR", garbage);
  h.sendRaw("CAMERA", garbage);
  h.sendRaw("REGISTERED_SCAN", garbage);
  h.sendRaw("LOOP_CORRECTION", garbage);
  EXPECT_TRUE(h.posteriors.empty());
  EXPECT_EQ(h.stats("STATE_PRIOR").decode_failures, 1);
  EXPECT_EQ(h.stats("CAMERA").decode_failures, 1);
  EXPECT_EQ(h.stats("REGISTERED_SCAN").decode_failures, 1);
  EXPECT_EQ(h.stats("LOOP_CORRECTION").decode_failures, 1);
  // a decodable prior with NaN is answered (valid = 0) and counted as rejected; so is a scan
  // with NaN in its pose
  h.send("CAMERA", imageMsg(rendered(0), s.utime(kT0)));
  filter_state_t nan = priorMsg(s.utime(kT0), 7, s.trueState(kT0), seedP());
  nan.position[1] = NAN;
  h.send("STATE_PRIOR", nan);
  ASSERT_EQ(h.posteriors.size(), 1u);
  EXPECT_EQ(h.posteriors[0].request_id, 7);
  EXPECT_EQ(h.posteriors[0].valid, 0);
  EXPECT_EQ(h.stats("STATE_PRIOR").rejected, 1);
  registered_scan_t bad = scanMsg(s.utime(kT0), {Vec3(1, 2, 3)}, s.bodyPose(kT0));
  bad.orientation[0] = NAN;
  h.send("REGISTERED_SCAN", bad);
  EXPECT_EQ(h.stats("REGISTERED_SCAN").rejected, 1);
  // a duplicate request id is not answered twice
  h.send("STATE_PRIOR", priorMsg(s.utime(kT0), 7, s.trueState(kT0), seedP()));
  EXPECT_EQ(h.posteriors.size(), 1u);
  EXPECT_EQ(h.stats("STATE_PRIOR").rejected, 2);
}

TEST(VioNode, UsesTheCameraTimeOffset) {
  std::string config = roomConfig();
  config.replace(config.find("    color: false"), 16, "    color: false\n    time_offset_s: 0.02");
  Harness h(config);
  const auto& s = scene();
  // images stamped 20 ms before the IMU-clock time of the priors
  const int64_t off = 20000;
  h.send("REGISTERED_SCAN", scanMsg(s.utime(kT0 - 0.1), s.sweep(kT0 - 0.2, 1), s.bodyPose(kT0 - 0.1)));
  h.send("REGISTERED_SCAN", scanMsg(s.utime(kT0), s.sweep(kT0 - 0.1, 2), s.bodyPose(kT0)));
  h.send("CAMERA", imageMsg(rendered(0), s.utime(kT0) - off));
  h.send("STATE_PRIOR", priorMsg(s.utime(kT0), 1, s.trueState(kT0), seedP()));
  h.send("CAMERA", imageMsg(rendered(1), s.utime(kT1) - off));
  h.send("STATE_PRIOR", priorMsg(s.utime(kT1), 2, offsetState(s.trueState(kT1)), priorP()));
  ASSERT_EQ(h.posteriors.size(), 2u);
  EXPECT_EQ(h.posteriors[1].utime, s.utime(kT1));
  EXPECT_EQ(h.posteriors[1].valid, 1);
  EXPECT_LT(positionError(h.posteriors[1], s.trueState(kT1)), 0.005);
}

TEST(VioNode, LoopCorrectionMovesTheMap) {
  Harness h;
  const auto& s = scene();
  h.seed();
  const Vec3 before = h.vio->estimator().map().point(0).position;
  const Pose3 T = se3::fromRotationTranslation(so3::Exp(Vec3(0.0, 0.0, 0.05)), Vec3(0.3, -0.2, 0.0));
  loop_correction_t c{};
  c.utime = s.utime(kT0);
  c.correction_id = 1;
  poseTo(T, c.correction_position, c.correction_orientation);
  poseTo(T, c.odometry_to_corrected_position, c.odometry_to_corrected_orientation);
  c.num_keyframes = 0;
  h.send("LOOP_CORRECTION", c);
  EXPECT_TRUE(h.vio->estimator().map().point(0).position.isApprox(T * before, 1e-9));
  // priors now come in the corrected frame: the update still finds the (corrected) truth
  FilterState truth = s.trueState(kT1);
  truth.rot = T.linear() * truth.rot;
  truth.pos = T * truth.pos;
  h.send("CAMERA", imageMsg(rendered(1), s.utime(kT1)));
  filter_state_t corrected_prior = priorMsg(s.utime(kT1), 2, offsetState(truth), priorP());
  corrected_prior.correction_id = 1;  // lio adopted the correction
  h.send("STATE_PRIOR", corrected_prior);
  ASSERT_EQ(h.posteriors.size(), 2u);
  EXPECT_EQ(h.posteriors[1].valid, 1);
  EXPECT_EQ(h.posteriors[1].correction_id, 1);
  EXPECT_LT(positionError(h.posteriors[1], truth), 0.005);
}

TEST(VioNode, IdenticalInputsGiveIdenticalPosteriors) {
  std::vector<std::vector<uint8_t>> runs[2];
  for (auto& run : runs) {
    Harness h;
    const auto& s = scene();
    h.seed();
    h.send("CAMERA", imageMsg(rendered(1), s.utime(kT1)));
    h.send("STATE_PRIOR", priorMsg(s.utime(kT1), 2, offsetState(s.trueState(kT1)), priorP()));
    h.send("STATE_PRIOR", priorMsg(s.utime(kT2), 3, offsetState(s.trueState(kT2)), priorP()));
    h.send("CAMERA", imageMsg(rendered(2), s.utime(kT2)));
    ASSERT_EQ(h.posteriors.size(), 3u);
    EXPECT_EQ(h.posteriors[1].valid, 1);
    EXPECT_EQ(h.posteriors[2].valid, 1);
    run = h.posterior_bytes;
  }
  EXPECT_EQ(runs[0], runs[1]);
}

// The promises vio sends with its PROGRESS (lockstep playback does not wait for what they cover)
// hold: a scan never makes it publish, nor an image while no prior waits; once a prior waits for
// its image, CAMERA is no longer promised, and that image is answered.
TEST(VioNode, QuietPromisesHold) {
  struct Watcher {
    progress_t last{};
    bool have = false;
    void on(const lcm::ReceiveBuffer* rbuf, const std::string&) {
      progress_t p;
      if (p.decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) <= 0 || p.node != "vio") return;
      last = p;
      have = true;
    }
    bool covers(const std::string& channel) const {
      for (int i = 0; have && i < last.num_quiet; ++i)
        if (last.quiet_channel[i] == channel && last.quiet_from[i] == std::numeric_limits<int64_t>::min() &&
            last.quiet_before[i] == std::numeric_limits<int64_t>::max())
          return true;
      return false;
    }
  };
  Harness h;
  Watcher w;
  h.lcm.subscribe("PROGRESS", &Watcher::on, &w);
  const auto& s = scene();
  int covered = 0;
  auto send = [&](const std::string& channel, const auto& m) {
    const bool quiet = w.covers(channel);
    const size_t before = h.posteriors.size();
    h.send(channel, m);
    if (quiet) {
      ++covered;
      EXPECT_EQ(h.posteriors.size(), before) << channel << " was promised quiet";
    }
  };
  send("REGISTERED_SCAN", scanMsg(s.utime(kT0 - 0.1), s.sweep(kT0 - 0.2, 1), s.bodyPose(kT0 - 0.1)));
  EXPECT_TRUE(w.covers("REGISTERED_SCAN"));
  EXPECT_TRUE(w.covers("CAMERA"));
  send("REGISTERED_SCAN", scanMsg(s.utime(kT0), s.sweep(kT0 - 0.1, 2), s.bodyPose(kT0)));
  send("CAMERA", imageMsg(rendered(0), s.utime(kT0)));
  send("STATE_PRIOR", priorMsg(s.utime(kT0), 1, s.trueState(kT0), seedP()));
  ASSERT_EQ(h.posteriors.size(), 1u);
  const FilterState truth = s.trueState(kT1);
  send("STATE_PRIOR", priorMsg(s.utime(kT1), 2, offsetState(truth), priorP()));  // waits for its image
  EXPECT_FALSE(w.covers("CAMERA"));
  EXPECT_TRUE(w.covers("REGISTERED_SCAN"));
  send("CAMERA", imageMsg(rendered(1), s.utime(kT1)));
  ASSERT_EQ(h.posteriors.size(), 2u);
  EXPECT_EQ(h.posteriors[1].valid, 1);
  EXPECT_TRUE(w.covers("CAMERA"));
  send("CAMERA", imageMsg(rendered(2), s.utime(kT2)));
  EXPECT_EQ(h.posteriors.size(), 2u);
  EXPECT_EQ(covered, 3);  // the second scan, the first and the third image (priors are never promised)
}

// The livo-lio node on LCM's in-process memq:// provider: config reading, outputs for a short
// synthetic run, identical ODOMETRY bytes whatever the interleaving of the input channels, and
// refusal of bad messages without stopping.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <optional>

#include "bus_messages.hpp"
#include "livo/filter_state_message.hpp"
#include "livo/image_t.hpp"
#include "livo/lio/lio_node.hpp"
#include "livo/loop_correction_t.hpp"
#include "livo/message_registry.hpp"
#include "livo/messages.hpp"
#include "livo/progress_t.hpp"
#include "livo/wheel_odometry_t.hpp"
#include "synthetic_messages.hpp"
#include "synthetic_world.hpp"

using namespace livo;
using namespace livo::lio;

namespace {
const char* kConfig = R"(
rig:
  channels: {imu: IMU, lidar: LIDAR, camera: CAMERA, wheel: WHEEL, ground_truth: GROUND_TRUTH}
  imu: {rate_hz: 200, gyro_noise_density: 1.7e-4, gyro_random_walk: 1.9e-5, accel_noise_density: 2.0e-3, accel_random_walk: 3.0e-3, gravity: 9.81}
  lidar: {model: VLP-16, rate_hz: 10, min_range: 0.5, max_range: 100.0, range_noise_std: 0.01, dropout_probability: 0.02,
          T_I_L: {translation: [0.05, 0.0, 0.1], rpy_deg: [0.0, 0.0, 90.0]}}
  camera: {width: 640, height: 480, fx: 400.0, fy: 400.0, cx: 319.5, cy: 239.5, distortion: [0.0, 0.0, 0.0, 0.0],
           rate_hz: 20, color: false, T_I_C: {translation: [0.08, 0.0, 0.02], rpy_deg: [-90, 0, -90]}}
lio:
  init: {window_s: 0.5}
  keyframe: {min_distance: 0.5}
)";

struct Outputs {
  std::vector<std::vector<uint8_t>> odometry_bytes;
  std::vector<odometry_t> odometry;
  std::vector<registered_scan_t> scans;
  std::vector<keyframe_t> keyframes;
};

using livo_test::encode;
using livo_test::Message;

struct RunSetup {
  std::string config = kConfig;
  /// Called with a stand-in VIO node before the run (e.g. to answer STATE_PRIOR).
  std::function<void(Node& observer)> attach;
  LioNode::HandoffCounts* handoff = nullptr;  // filled after the run
  int64_t* rejected_posteriors = nullptr;     // filled after the run
  LioNode::SweepCounts* sweeps = nullptr;     // filled after the run
  /// Called around each input message (published, then handled by every node before the next).
  std::function<void(const Message&)> before_each, after_each;
};

constexpr int64_t kBaseTime = 1'000'000'000;  // the synthetic sequence's first stamp

Outputs runNode(const std::vector<Message>& messages, int64_t* rejected = nullptr, const RunSetup& setup = {}) {
  lcm::LCM lcm("memq://");
  EXPECT_TRUE(lcm.good());
  LioNodeOptions opts = readLioNodeOptions(Config::fromString(setup.config));
  LioNode node(lcm, opts, true);
  Outputs out;
  Node observer(lcm, NodeOptions{"observer", "PROGRESS_OBS", "HEALTH_OBS", 0.0, false, true, {}});
  // a stand-in VIO on the real PROGRESS channel, so lio sees its subscriptions
  Node vio(lcm, NodeOptions{"fake_vio", "PROGRESS", "HEALTH_VIO", 0.0, true, true, {}});
  if (setup.attach) setup.attach(vio);
  observer.subscribeRaw("ODOMETRY", [&](const void* data, int size) {
    const auto* b = static_cast<const uint8_t*>(data);
    out.odometry_bytes.emplace_back(b, b + size);
    odometry_t o;
    o.decode(data, 0, size);
    out.odometry.push_back(o);
  });
  observer.subscribe<registered_scan_t>("REGISTERED_SCAN", [&](const registered_scan_t& m) { out.scans.push_back(m); });
  observer.subscribe<keyframe_t>("KEYFRAME", [&](const keyframe_t& m) { out.keyframes.push_back(m); });
  if (setup.before_each || setup.after_each) {
    for (const Message& m : messages) {
      if (setup.before_each) setup.before_each(m);
      livo_test::publishAll(lcm, {m});
      if (setup.after_each) setup.after_each(m);
    }
  } else {
    livo_test::publishAll(lcm, messages);
  }
  if (rejected) {
    *rejected = 0;
    for (const auto& c : node.node().channelStats()) *rejected += c.rejected + c.decode_failures;
  }
  if (setup.handoff) *setup.handoff = node.handoffCounts();
  if (setup.sweeps) *setup.sweeps = node.sweepCounts();
  if (setup.rejected_posteriors) {
    *setup.rejected_posteriors = 0;
    for (const auto& c : node.node().channelStats())
      if (c.channel == "STATE_POSTERIOR") *setup.rejected_posteriors = c.rejected;
  }
  return out;
}

// 3 s in the room: IMU at 200 Hz and 30 sweeps, each message keyed by its arrival in "sensor
// order" (a sweep arrives at its end, an IMU sample at its stamp).
synth::SyntheticSequence syntheticSequence() {
  synth::SequenceSpec spec;
  spec.duration = 3.0;
  spec.imu_error = synth::realisticImu();
  spec.lidar.range_noise_std = 0.01;
  spec.T_I_L = se3::fromRotationTranslation(so3::Exp(Vec3(0.0, 0.0, M_PI / 2)), Vec3(0.05, 0.0, 0.1));
  return synth::SyntheticSequence(spec);
}

std::vector<Message> syntheticRun() {
  const synth::SyntheticSequence seq = syntheticSequence();
  std::vector<Message> msgs;
  for (const auto& s : seq.imu()) msgs.push_back(encode(s.utime, "IMU", synth::imuMessage(s)));
  for (int k = 0; k < seq.numScans(); ++k)
    msgs.push_back(encode(seq.scanEndUtime(k), "LIDAR", synth::cloudMessage(seq.scan(k))));
  livo_test::sortByArrival(&msgs);
  return msgs;
}
}  // namespace

TEST(LioNode, ReadsTheRigSchemaAndStrictLioSection) {
  const LioNodeOptions o = readLioNodeOptions(Config::fromString(kConfig));
  EXPECT_EQ(o.imu_channel, "IMU");
  EXPECT_DOUBLE_EQ(o.core.imu_noise.accel_random_walk, 3.0e-3);
  EXPECT_NEAR(o.core.extrinsics.T_I_L.translation().z(), 0.1, 1e-12);
  EXPECT_NEAR(so3::Log(Mat3(o.core.extrinsics.T_I_L.linear())).z(), M_PI / 2, 1e-12);
  EXPECT_DOUBLE_EQ(o.core.keyframe.min_distance, 0.5);
  EXPECT_FALSE(o.core.wheel.enabled);
  std::string bad = std::string(kConfig) + "  map: {voxel_sise: 1.0}\n";
  EXPECT_THROW(readLioNodeOptions(Config::fromString(bad)), ConfigError);
  // a wheel section under rig enables the wheel update
  std::string wheel = std::string(kConfig);
  wheel.insert(wheel.find("  camera:"),
               "  wheel: {rate_hz: 50, track_width: 0.5, speed_noise_std: 0.02, "
               "T_I_B: {translation: [0, 0, -0.3], rpy_deg: [0, 0, 0]}}\n");
  const LioNodeOptions w = readLioNodeOptions(Config::fromString(wheel));
  EXPECT_TRUE(w.core.wheel.enabled);
  EXPECT_NEAR(w.core.wheel.T_I_B.translation().z(), -0.3, 1e-12);
}

// A value out of range is refused naming its own key, not a neighbour checked in the same line.
TEST(LioNode, RefusesOutOfRangeValuesNamingTheKey) {
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"  point_stride: 0\n", "lio.point_stride"},
      {"  scan_voxel_size: 0\n", "lio.scan_voxel_size"},
      {"  reseed_after_s: 0\n", "lio.reseed_after_s"},
      {"  map: {max_points_per_voxel: 0}\n", "lio.map.max_points_per_voxel"},
      {"  map: {seen_through: {ray_stride: 0}}\n", "lio.map.seen_through.ray_stride"},
      {"  matching: {num_neighbors: 2}\n", "lio.matching.num_neighbors"},
      {"  esikf: {max_iterations: 0}\n", "lio.esikf.max_iterations"},
  };
  for (const auto& [line, key] : bad) {
    std::string why = "accepted";
    try {
      readLioNodeOptions(Config::fromString(std::string(kConfig) + line));
    } catch (const ConfigError& e) {
      why = e.what();
    }
    EXPECT_NE(why.find(key + ":"), std::string::npos) << line << " -> " << why;
  }
}

TEST(LioNode, PublishesOdometryScansAndKeyframes) {
  LioNode::SweepCounts sweeps;
  RunSetup setup;
  setup.sweeps = &sweeps;
  const Outputs out = runNode(syntheticRun(), nullptr, setup);
  // 30 sweeps, the first ~5 during the IMU initialisation
  EXPECT_GE(out.odometry.size(), 24u);
  EXPECT_EQ(out.scans.size(), out.odometry.size());
  EXPECT_GE(out.keyframes.size(), 2u);
  for (const auto& o : out.odometry) {
    EXPECT_TRUE(allFinite(o.position, 3) && allFinite(o.pose_covariance, 36));
    EXPECT_EQ(o.parent_frame, "W");
    EXPECT_EQ(o.degenerate, 0);
  }
  for (size_t i = 1; i < out.odometry.size(); ++i) EXPECT_GT(out.odometry[i].utime, out.odometry[i - 1].utime);
  // the first sweep seeds the map (no residual), every later one is a LiDAR update
  EXPECT_EQ(out.odometry.front().num_residuals, 0);
  for (size_t i = 1; i < out.odometry.size(); ++i) EXPECT_GT(out.odometry[i].num_residuals, 0);
  EXPECT_EQ(sweeps.published, static_cast<int64_t>(out.odometry.size()));
  EXPECT_EQ(sweeps.tracked, sweeps.published - 1);
  EXPECT_EQ(sweeps.predicted, 0);
  EXPECT_EQ(sweeps.degenerate, 0);
  EXPECT_EQ(out.scans.back().cloud.frame, "W");
  EXPECT_GT(out.scans.back().cloud.num_points, 20000);
  EXPECT_EQ(out.scans.back().utime, out.odometry.back().utime);
  EXPECT_EQ(out.keyframes.front().cloud.frame, "I");
  EXPECT_EQ(out.keyframes.front().id, 0);
}

// ODOMETRY.num_residuals counts the measurements the published pose used: none on a sweep kept at
// the IMU prediction (report.md counts those), whatever its rejected registration had matched.
TEST(LioNode, PredictedSweepsPublishNoResiduals) {
  ScanResult r;
  r.status = ScanResult::Status::kPredicted;
  r.num_residuals = 57;  // too few to be taken
  r.degeneracy.degenerate = true;
  const odometry_t predicted = toOdometry(r, OdometryFrame{});
  EXPECT_EQ(predicted.num_residuals, 0);
  EXPECT_EQ(predicted.degenerate, 1);
  r.status = ScanResult::Status::kTracked;
  EXPECT_EQ(toOdometry(r, OdometryFrame{}).num_residuals, 57);
}

// REGISTERED_SCAN keeps each point's capture time (cloud.utime = sweep start, the input offsets)
// for the colouring process; KEYFRAME clouds carry the input intensities.
TEST(LioNode, RegisteredScansKeepPointTimesAndKeyframesIntensity) {
  const std::vector<Message> in = syntheticRun();
  std::vector<int64_t> sweep_starts;
  for (const auto& m : in)
    if (m.channel == "LIDAR") {
      point_cloud_t c;
      c.decode(m.bytes.data(), 0, static_cast<int>(m.bytes.size()));
      sweep_starts.push_back(c.utime);
    }
  const Outputs out = runNode(in);
  ASSERT_FALSE(out.scans.empty());
  for (const auto& s : out.scans) {
    const point_cloud_t& c = s.cloud;
    ASSERT_EQ(c.time_offset.size(), static_cast<size_t>(c.num_points));
    EXPECT_NE(std::find(sweep_starts.begin(), sweep_starts.end(), c.utime), sweep_starts.end());
    EXPECT_GT(s.utime, c.utime);
    EXPECT_GT(c.sweep_duration, 0.0f);
    float lo = 1e9f, hi = -1e9f;
    for (float t : c.time_offset) {
      lo = std::min(lo, t);
      hi = std::max(hi, t);
    }
    EXPECT_GE(lo, 0.0f);
    EXPECT_LE(hi, c.sweep_duration + 1e-6f);
    EXPECT_GT(hi, 0.5f * c.sweep_duration);  // the offsets are not all zero
    // the state time is the sweep end: start + sweep duration
    EXPECT_NEAR(static_cast<double>(s.utime - c.utime), 1e6 * static_cast<double>(c.sweep_duration), 2.0);
  }
  ASSERT_FALSE(out.keyframes.empty());
  for (const auto& k : out.keyframes) {
    const point_cloud_t& c = k.cloud;
    ASSERT_EQ(c.intensity.size(), static_cast<size_t>(c.num_points));
    float hi = 0.0f;
    for (float v : c.intensity) {
      EXPECT_GE(v, 0.0f);
      EXPECT_LE(v, 15.0f);  // the synthetic intensity is the ring index
      hi = std::max(hi, v);
    }
    EXPECT_GT(hi, 0.0f);
  }
}

TEST(LioNode, OutputDoesNotDependOnChannelInterleaving) {
  const std::vector<Message> in_order = syntheticRun();
  // Same per-channel order, channels interleaved differently: every sweep published 0.35 s
  // early (before the IMU covering it), and separately all IMU of each second ahead of its sweeps.
  std::vector<Message> lidar_early = in_order, imu_early = in_order;
  for (auto& m : lidar_early)
    if (m.channel == "LIDAR") m.order_key -= 350'000;
  for (auto& m : imu_early)
    if (m.channel == "IMU") m.order_key = (m.order_key / 1'000'000) * 1'000'000;
  livo_test::sortByArrival(&lidar_early);
  livo_test::sortByArrival(&imu_early);
  const Outputs a = runNode(in_order), b = runNode(lidar_early), c = runNode(imu_early);
  ASSERT_GE(a.odometry_bytes.size(), 24u);
  EXPECT_EQ(a.odometry_bytes, b.odometry_bytes);
  EXPECT_EQ(a.odometry_bytes, c.odometry_bytes);
}

TEST(LioNode, RefusesBadInputAndKeepsGoing) {
  std::vector<Message> msgs = syntheticRun();
  std::vector<Message> bad;
  imu_t nan_imu;
  nan_imu.utime = 1'000'000'000 + 1'502'500;
  nan_imu.angular_velocity[0] = std::nan("");
  bad.push_back(encode(1'000'000'000 + 1'502'500, "IMU", nan_imu));
  point_cloud_t broken;
  broken.utime = 1'000'000'000 + 2'000'000;
  broken.frame = "C";  // a cloud in the camera frame is not a LiDAR sweep
  broken.num_points = 3;
  broken.x = broken.y = broken.z = broken.intensity = broken.time_offset = {1.0f, 2.0f, 3.0f};
  broken.ring = {0, 0, 0};
  bad.push_back(encode(1'000'000'000 + 2'000'000, "LIDAR", broken));
  Message junk{1'000'000'000 + 2'200'000, "LIDAR", {1, 2, 3, 4, 5}};
  bad.push_back(junk);
  msgs.insert(msgs.end(), bad.begin(), bad.end());
  livo_test::sortByArrival(&msgs);
  int64_t rejected = 0;
  const Outputs out = runNode(msgs, &rejected);
  EXPECT_EQ(rejected, 3);
  EXPECT_GE(out.odometry.size(), 24u);
  for (const auto& o : out.odometry) EXPECT_TRUE(allFinite(o.position, 3));
}

// Corrupted IMU messages that still decode: a stamp 1000 s ahead, one 5 s back (each would have
// bridged or reset the filter), and an acceleration no IMU measures. Each is refused, and the
// odometry is byte for byte that of the clean run.
TEST(LioNode, CorruptedImuSamplesChangeNothing) {
  const std::vector<Message> clean = syntheticRun();
  std::vector<Message> msgs = clean;
  auto sampleNear = [&](int64_t utime) {
    imu_t m;
    for (const auto& c : clean)
      if (c.channel == "IMU" && c.order_key >= utime) {
        m.decode(c.bytes.data(), 0, static_cast<int>(c.bytes.size()));
        break;
      }
    return m;
  };
  imu_t ahead = sampleNear(kBaseTime + 1'200'000);
  ahead.utime += 1'000'000'000;
  imu_t behind = sampleNear(kBaseTime + 1'700'000);
  behind.utime -= 5'000'000;
  imu_t wild = sampleNear(kBaseTime + 2'100'000);
  wild.utime += 1'000;  // between two samples
  wild.linear_acceleration[2] = 3.0e5;
  msgs.push_back(encode(kBaseTime + 1'200'001, "IMU", ahead));
  msgs.push_back(encode(kBaseTime + 1'700'001, "IMU", behind));
  msgs.push_back(encode(kBaseTime + 2'100'001, "IMU", wild));
  livo_test::sortByArrival(&msgs);
  int64_t rejected = 0;
  const Outputs out = runNode(msgs, &rejected);
  const Outputs ref = runNode(clean);
  EXPECT_EQ(rejected, 5);  // two jumps held then found unconfirmed, one out of range
  ASSERT_GE(ref.odometry_bytes.size(), 24u);
  EXPECT_EQ(out.odometry_bytes, ref.odometry_bytes);
}

namespace {
// The synthetic run with 20 Hz image times on CAMERA (tiny grey images: lio reads only the time).
constexpr int64_t kBase = 1'000'000'000;
/// A 2x2 grey image: lio reads only its stamp.
Message tinyImage(int64_t utime) {
  image_t img;
  img.utime = utime;
  img.frame = "C";
  img.width = img.height = img.row_stride = 2;
  img.encoding = image_t::ENCODING_GRAY8;
  img.data = {10, 20, 30, 40};
  img.size = 4;
  return encode(utime, "CAMERA", img);
}

std::vector<Message> withImages(std::vector<Message> msgs, int64_t* first_image, int64_t* last_image) {
  *first_image = kBase + 25'000;
  for (int64_t t = *first_image; t < kBase + 2'950'000; t += 50'000) {
    msgs.push_back(tinyImage(t));
    *last_image = t;
  }
  livo_test::sortByArrival(&msgs);
  return msgs;
}

std::string handoffConfig() {
  std::string c = kConfig;
  c += "  camera_handoff: true\n";
  return c;
}

Pose3 poseOf(const double* position, const double* orientation) {
  Pose3 T = Pose3::Identity();
  T.linear() = Eigen::Quaterniond(orientation[0], orientation[1], orientation[2], orientation[3]).toRotationMatrix();
  T.translation() = Vec3(position[0], position[1], position[2]);
  return T;
}

/// Position RMSE of the odometry against the truth after the best rigid alignment.
double alignedError(const Outputs& out, const synth::SyntheticSequence& seq) {
  std::vector<Vec3> est, gt;
  for (const auto& o : out.odometry) {
    est.emplace_back(o.position[0], o.position[1], o.position[2]);
    gt.push_back(seq.truth(o.utime).translation());
  }
  return synth::alignedRmse(est, gt);
}

/// A fake VIO's answer: a pose measurement of the truth `T` (1 mm, 1 mrad) through the same
/// iterated ESIKF update.
filter_state_t posteriorFromTruth(const filter_state_t& prior, const Pose3& T) {
  FilterState x, x_post;
  StateCovariance P, P_post;
  EXPECT_TRUE(fromFilterState(prior, &x, &P));
  const Measurement measure = [&](const FilterState& xi, int, MeasurementInformation* info) {
    Vec6 z;
    z.head<3>() = so3::Log(Mat3(T.linear().transpose() * xi.rot));
    z.tail<3>() = xi.pos - T.translation();
    Mat6 H = Mat6::Identity();
    H.topLeftCorner<3, 3>() = so3::rightJacobianInverse(z.head<3>());
    info->HtRinvH.topLeftCorner<6, 6>() = H.transpose() * H / 1e-6;
    info->HtRinvz.head<6>() = H.transpose() * z / 1e-6;
    info->count = 6;
    return true;
  };
  const EsikfResult r = iteratedUpdate(x, P, measure, EsikfOptions{}, &x_post, &P_post);
  EXPECT_TRUE(r.valid);
  filter_state_t post = toFilterState(prior.utime, x_post, P_post, prior.request_id, "fake_vio");
  post.valid = 1;
  post.iterations = r.iterations;
  post.num_measurements = r.info.count;
  return post;
}

}  // namespace

// At every image time after the map is seeded lio publishes the propagated filter on STATE_PRIOR
// and waits for the answer; a VIO that answers with the true pose and a tight covariance pulls the
// state onto the truth, and every sweep still gets its ODOMETRY.
TEST(LioNode, CameraHandOffPublishesPriorsAndAdoptsPosteriors) {
  const synth::SyntheticSequence seq = syntheticSequence();
  int64_t first_image = 0, last_image = 0;
  const std::vector<Message> in = withImages(syntheticRun(), &first_image, &last_image);
  std::vector<filter_state_t> priors;
  // lio's world frame is its own (gravity-aligned, started at the origin): the fake VIO maps the
  // truth into it with the transform the first prior defines (that prior is a few mm off)
  Pose3 T_lio_truth = Pose3::Identity();
  RunSetup setup;
  setup.config = handoffConfig();
  LioNode::HandoffCounts counts;
  setup.handoff = &counts;
  setup.attach = [&](Node& vio) {
    vio.subscribe<filter_state_t>("STATE_PRIOR", [&](const filter_state_t& prior) {
      if (priors.empty()) T_lio_truth = poseOf(prior.position, prior.orientation) * seq.truth(prior.utime).inverse();
      priors.push_back(prior);
      vio.publish("STATE_POSTERIOR", posteriorFromTruth(prior, T_lio_truth * seq.truth(prior.utime)));
    });
    vio.declareOutput("STATE_POSTERIOR");  // lio counts a node that answers, not any subscriber
    vio.announce();  // lio hands off only while a STATE_PRIOR subscriber is alive
  };
  const Outputs out = runNode(in, nullptr, setup);
  const Outputs lidar_only = runNode(syntheticRun());

  ASSERT_GE(priors.size(), 40u);  // 58 images, the first ~0.5 s before the map exists
  EXPECT_EQ(counts.priors, static_cast<int64_t>(priors.size()));
  EXPECT_EQ(counts.adopted, counts.priors);
  EXPECT_EQ(counts.missing, 0);
  EXPECT_EQ(counts.kept_prior, 0);
  EXPECT_EQ(counts.priors + counts.images_skipped, (last_image - first_image) / 50'000 + 1);
  for (size_t i = 0; i < priors.size(); ++i) {
    EXPECT_EQ(priors[i].request_id, static_cast<int64_t>(i + 1));
    EXPECT_EQ((priors[i].utime - first_image) % 50'000, 0);  // exactly the image times
    EXPECT_EQ(priors[i].source, "lio");
    EXPECT_TRUE(allFinite(priors[i].covariance, FilterState::kDim * FilterState::kDim));
    // the prior is the tracked state propagated by the IMU: close to the truth already
    const Vec3 p(priors[i].position[0], priors[i].position[1], priors[i].position[2]);
    EXPECT_LT((p - (T_lio_truth * seq.truth(priors[i].utime)).translation()).norm(), 0.02) << "prior " << i;
  }
  // every sweep still produces its odometry, and exact posteriors keep it on the truth
  ASSERT_EQ(out.odometry.size(), lidar_only.odometry.size());
  for (size_t i = 0; i < out.odometry.size(); ++i) {
    EXPECT_EQ(out.odometry[i].utime, lidar_only.odometry[i].utime);
    const Pose3 truth = T_lio_truth * seq.truth(out.odometry[i].utime);
    if (out.odometry[i].utime > priors.front().utime) {
      EXPECT_LT(
          (poseOf(out.odometry[i].position, out.odometry[i].orientation).translation() - truth.translation()).norm(),
          0.01)
          << "sweep " << i;
    }
  }
  std::printf("aligned position RMSE: with exact posteriors %.4f m, LiDAR-only %.4f m\n", alignedError(out, seq),
              alignedError(lidar_only, seq));
  EXPECT_LT(alignedError(out, seq), 0.002);
  EXPECT_LT(alignedError(out, seq), alignedError(lidar_only, seq));
}

// Without a VIO on the bus nothing is handed off and the odometry is byte for byte LiDAR-only; a
// VIO that never answers costs posterior_max_wait_s of IMU time per image and is counted; a "kept
// the prior" answer and a foreign posterior are handled too.
TEST(LioNode, CameraHandOffGoesOnWithoutVio) {
  int64_t first_image = 0, last_image = 0;
  const std::vector<Message> in = withImages(syntheticRun(), &first_image, &last_image);
  const synth::SyntheticSequence seq = syntheticSequence();
  const Outputs lidar_only = runNode(syntheticRun());
  {
    RunSetup setup;
    setup.config = handoffConfig();
    LioNode::HandoffCounts counts;
    setup.handoff = &counts;
    const Outputs out = runNode(in, nullptr, setup);
    EXPECT_EQ(counts.priors, 0);
    EXPECT_GE(counts.no_vio, 40);
    EXPECT_EQ(out.odometry_bytes, lidar_only.odometry_bytes);
  }
  {
    // subscribed (announced) but silent: every prior times out
    RunSetup setup;
    setup.config = handoffConfig();
    LioNode::HandoffCounts counts;
    setup.handoff = &counts;
    setup.attach = [](Node& vio) {
      vio.subscribe<filter_state_t>("STATE_PRIOR", [](const filter_state_t&) {});
      vio.declareOutput("STATE_POSTERIOR");
      vio.announce();
    };
    const Outputs out = runNode(in, nullptr, setup);
    EXPECT_GE(counts.priors, 40);
    EXPECT_EQ(counts.missing, counts.priors);
    EXPECT_EQ(counts.adopted, 0);
    ASSERT_EQ(out.odometry.size(), lidar_only.odometry.size());
    EXPECT_LT(alignedError(out, seq), 0.002);
  }
  {
    // a VIO that keeps every prior (valid = 0) and also sends a posterior nobody asked for
    RunSetup setup;
    setup.config = handoffConfig();
    LioNode::HandoffCounts counts;
    setup.handoff = &counts;
    int64_t rejected_posteriors = 0;
    setup.rejected_posteriors = &rejected_posteriors;
    setup.attach = [&](Node& vio) {
      vio.subscribe<filter_state_t>("STATE_PRIOR", [&vio](const filter_state_t& prior) {
        filter_state_t post = prior;
        post.valid = 0;
        vio.publish("STATE_POSTERIOR", post);
        if (prior.request_id == 3) {
          filter_state_t foreign = prior;
          foreign.request_id = 999;
          foreign.valid = 1;
          vio.publish("STATE_POSTERIOR", foreign);
        }
      });
      vio.declareOutput("STATE_POSTERIOR");
      vio.announce();
    };
    const Outputs out = runNode(in, nullptr, setup);
    EXPECT_GE(counts.priors, 40);
    EXPECT_EQ(counts.kept_prior, counts.priors);
    EXPECT_EQ(counts.missing, 0);
    EXPECT_EQ(rejected_posteriors, 1);
    ASSERT_EQ(out.odometry.size(), lidar_only.odometry.size());
    EXPECT_LT(alignedError(out, seq), 0.002);
  }
}

// A recorder of STATE_PRIOR (livo-record in run_pipeline.sh) subscribes to it but publishes no
// STATE_POSTERIOR: lio does not take it for a VIO, hands nothing off, never waits, and its odometry is
// byte for byte LiDAR-only.
TEST(LioNode, ARecorderOfStatePriorIsNoVio) {
  int64_t first_image = 0, last_image = 0;
  const std::vector<Message> in = withImages(syntheticRun(), &first_image, &last_image);
  const Outputs lidar_only = runNode(syntheticRun());
  RunSetup setup;
  setup.config = handoffConfig();
  LioNode::HandoffCounts counts;
  setup.handoff = &counts;
  int64_t recorded_priors = 0;
  setup.attach = [&](Node& recorder) {
    recorder.subscribeRaw("STATE_PRIOR", [&](const void*, int) { ++recorded_priors; });
    recorder.subscribeRaw("ODOMETRY", [](const void*, int) {});
    recorder.declareOutput("HEALTH");
    recorder.announce();
  };
  const Outputs out = runNode(in, nullptr, setup);
  EXPECT_EQ(counts.priors, 0);
  EXPECT_EQ(recorded_priors, 0);
  EXPECT_EQ(counts.missing, 0);
  EXPECT_GE(counts.no_vio, 40);
  EXPECT_EQ(out.odometry_bytes, lidar_only.odometry_bytes);
}

// A camera triggered by the LiDAR: every image stamped exactly at a sweep end (the next sweep's
// start) and delivered before that sweep's message, as a driver publishing the image first does.
// The sweep ending there is registered first and the image handed off at the same time: no sweep
// is refused, every sweep gives its odometry, and every image after the map exists gets a prior.
// The old order (the image first, as soon as the IMU passed it) refused the sweep at the same time.
TEST(LioNode, ImagesAtTheSweepEndsCostNoSweep) {
  const synth::SyntheticSequence seq = syntheticSequence();
  std::vector<Message> in;
  for (int k = 0; k < seq.numScans(); ++k)
    in.push_back(tinyImage(seq.scanEndUtime(k)));  // before the sweep on equal keys (stable sort)
  const std::vector<Message> run = syntheticRun();
  in.insert(in.end(), run.begin(), run.end());
  livo_test::sortByArrival(&in);

  std::vector<int64_t> prior_times;
  RunSetup setup;
  setup.config = handoffConfig();
  LioNode::HandoffCounts counts;
  setup.handoff = &counts;
  setup.attach = [&](Node& vio) {
    vio.subscribe<filter_state_t>("STATE_PRIOR", [&vio, &prior_times](const filter_state_t& prior) {
      prior_times.push_back(prior.utime);
      filter_state_t post = prior;  // an answer that keeps the prior: the odometry stays LiDAR-only
      post.valid = 0;
      vio.publish("STATE_POSTERIOR", post);
    });
    vio.declareOutput("STATE_POSTERIOR");
    vio.announce();
  };
  int64_t rejected = 0;
  const Outputs out = runNode(in, &rejected, setup);
  const Outputs lidar_only = runNode(syntheticRun());
  EXPECT_EQ(rejected, 0);
  ASSERT_EQ(out.odometry.size(), lidar_only.odometry.size());
  EXPECT_EQ(out.odometry_bytes, lidar_only.odometry_bytes);
  // every image from the first tracked sweep on, at its own time
  ASSERT_GE(prior_times.size(), 20u);
  EXPECT_EQ(counts.kept_prior, counts.priors);
  EXPECT_EQ(counts.missing, 0);
  EXPECT_EQ(counts.priors + counts.images_skipped, seq.numScans());
  EXPECT_EQ(prior_times.back(), seq.scanEndUtime(seq.numScans() - 1));
  for (size_t i = 1; i < prior_times.size(); ++i) EXPECT_GT(prior_times[i], prior_times[i - 1]);
}

namespace {
// Real-time orders around a reset: a loop correction of the current epoch is adopted (later
// output says so in correction_id); an IMU clock jump back re-initialises lio in epoch 1; then a
// correction and a posterior made for epoch 0 arrive late and are both ignored.
TEST(LioNode, ResetStartsANewEpochAndRefusesOldCorrectionsAndPosteriors) {
  std::vector<Message> msgs = syntheticRun();
  loop_correction_t lc{};
  lc.utime = kBase + 1'000'000;
  lc.correction_id = 1;
  lc.epoch = 0;
  const Pose3 T = se3::fromRotationTranslation(so3::Exp(Vec3(0.0, 0.0, 0.01)), Vec3(0.2, 0.0, 0.0));
  poseTo(T, lc.correction_position, lc.correction_orientation);
  poseTo(T, lc.odometry_to_corrected_position, lc.odometry_to_corrected_orientation);
  msgs.push_back(encode(kBase + 1'000'001, "LOOP_CORRECTION", lc));
  imu_t jumped = synth::imuMessage(syntheticSequence().imu().front());
  jumped.utime = kBase - 2'000'000;  // 3.5 s back from 1.5 s: more than clock_reset_s
  msgs.push_back(encode(kBase + 1'500'001, "IMU", jumped));
  jumped.utime += 5'000;  // the next sample confirms the new clock (a lone one would be dropped)
  msgs.push_back(encode(kBase + 1'500'001, "IMU", jumped));
  loop_correction_t old = lc;
  old.correction_id = 2;
  old.previous_correction_id = 1;
  msgs.push_back(encode(kBase + 1'500'002, "LOOP_CORRECTION", old));
  // a posterior lio would adopt but for its epoch (the calibration held fixed, as lio holds it)
  StateCovariance P_posterior = StateCovariance::Zero();
  P_posterior.topLeftCorner<FilterState::kNavDim, FilterState::kNavDim>().setIdentity();
  filter_state_t posterior = toFilterState(kBase + 1'400'000, FilterState(), P_posterior, 1, "vio");
  posterior.epoch = 0;
  msgs.push_back(encode(kBase + 1'500'003, "STATE_POSTERIOR", posterior));
  livo_test::sortByArrival(&msgs);
  int64_t rejected = 0, rejected_posteriors = 0;
  RunSetup setup;
  setup.rejected_posteriors = &rejected_posteriors;
  const Outputs out = runNode(msgs, &rejected, setup);
  EXPECT_EQ(rejected_posteriors, 1);
  EXPECT_GE(rejected, 2);  // the posterior and the old epoch's correction (and late sweeps, if any)
  ASSERT_FALSE(out.odometry.empty());
  // lio publishes a sweep's odometry once the IMU passed its end, so a sweep ending at or just
  // before the correction's arrival may already be in correction 1: every later sweep is, none
  // goes back to 0, and the early ones are raw.
  int adopted = 0, raw = 0;
  int64_t previous_id = 0;
  for (const odometry_t& o : out.odometry) {
    EXPECT_TRUE(allFinite(o.position, 3));
    if (o.epoch == 0) {
      if (o.utime > kBase + 1'000'000) {
        EXPECT_EQ(o.correction_id, 1) << o.utime;
      }
      EXPECT_GE(o.correction_id, previous_id) << o.utime;
      EXPECT_LE(o.correction_id, 1) << o.utime;
      previous_id = o.correction_id;
      adopted += o.correction_id == 1;
      raw += o.correction_id == 0;
    } else {
      EXPECT_EQ(o.epoch, 1);
      EXPECT_EQ(o.correction_id, 0);  // correction 2 was for epoch 0
    }
  }
  EXPECT_GT(adopted, 0);
  EXPECT_GT(raw, 0);
  for (const keyframe_t& k : out.keyframes) EXPECT_LE(k.epoch, 1);
  for (size_t i = 0; i < out.scans.size(); ++i) EXPECT_EQ(out.scans[i].epoch, out.odometry[i].epoch);
}
}  // namespace

// The promises lio sends with every PROGRESS (progress_t.quiet_*), which let lockstep playback send
// IMU samples and wheel readings on without waiting for it, hold: nothing they cover makes lio
// publish anything. And they are worth having: they cover most samples (not those that carry the
// filter past a sweep end or an image time, nor those while a posterior is awaited) and most wheel
// readings (not the first past the end of a sweep waiting for one).
TEST(LioNode, QuietPromisesHoldAndCoverMostImuSamplesImagesAndWheelReadings) {
  struct Watcher {
    progress_t last{};
    bool have = false;
    int64_t outputs = 0;
    void onProgress(const lcm::ReceiveBuffer* rbuf, const std::string&) {
      progress_t p;
      if (p.decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) <= 0 || p.node == "fake_vio") return;
      last = p;
      have = true;
    }
    void onOutput(const lcm::ReceiveBuffer*, const std::string&) { ++outputs; }
    // Playback may send on while every message since a PROGRESS is inside its promises, however
    // many states later: every such promise must hold for the whole run of messages it covers.
    std::vector<progress_t> active;
    static bool covers(const progress_t& p, const std::string& channel, int64_t utime) {
      for (int i = 0; i < p.num_quiet; ++i)
        if (p.quiet_channel[i] == channel && utime >= p.quiet_from[i] && utime < p.quiet_before[i]) return true;
      return false;
    }
    /// Drops the promises that do not cover this message; true if one still does.
    bool keepCovering(const std::string& channel, int64_t utime) {
      active.erase(
          std::remove_if(active.begin(), active.end(), [&](const progress_t& p) { return !covers(p, channel, utime); }),
          active.end());
      return !active.empty();
    }
  };
  const synth::SyntheticSequence seq = syntheticSequence();
  // the plain run, with the camera hand-off, with IMU samples swapped and duplicated, with wheels,
  // with the hand-off from a camera whose stamps jitter by up to 24 ms and which misses images,
  // from a camera whose images arrive 30 ms late (after the sweep that ends after them), and with
  // each sweep arriving at its start (as livo-sim writes them), so that it waits for the images
  // and all of it at once: camera, wheels, sweeps arriving at their start
  for (const int variant : {0, 1, 2, 3, 4, 5, 6, 7}) {
    const bool handoff = variant == 1 || variant >= 4, wheels = variant == 3 || variant == 7;
    Watcher w;
    std::map<std::string, int64_t> seen, covered;
    int64_t broken = 0, outputs_before = 0;
    bool in_promise = false;
    RunSetup setup;
    if (handoff) setup.config = handoffConfig();
    if (wheels) {
      setup.config.insert(setup.config.find("  camera:"),
                          "  wheel: {rate_hz: 50, track_width: 0.5, speed_noise_std: 0.05, "
                          "T_I_B: {translation: [0, 0, 0], rpy_deg: [0, 0, 0]}}\n");
    }
    LioNode::HandoffCounts counts;
    setup.handoff = &counts;
    setup.attach = [&](Node& vio) {
      vio.lcm().subscribe("PROGRESS", &Watcher::onProgress, &w);
      for (const char* ch : {"ODOMETRY", "REGISTERED_SCAN", "KEYFRAME", "STATE_PRIOR"})
        vio.lcm().subscribe(ch, &Watcher::onOutput, &w);
      if (!handoff) return;
      vio.subscribe<filter_state_t>("STATE_PRIOR", [&vio](const filter_state_t& prior) {
        filter_state_t keep = prior;  // "kept the prior": the answer that changes nothing
        keep.valid = 0;
        keep.source = "fake_vio";
        vio.publish("STATE_POSTERIOR", keep);
      });
      vio.declareOutput("STATE_POSTERIOR");
      vio.announce();
    };
    setup.before_each = [&](const Message& m) {
      in_promise = false;
      int64_t utime = 0;
      if (m.channel == "IMU") {
        imu_t s;
        ASSERT_GT(s.decode(m.bytes.data(), 0, static_cast<int>(m.bytes.size())), 0);
        utime = s.utime;
      } else if (m.channel == "WHEEL") {
        wheel_odometry_t s;
        ASSERT_GT(s.decode(m.bytes.data(), 0, static_cast<int>(m.bytes.size())), 0);
        utime = s.utime;
      } else if (m.channel == "CAMERA") {
        image_t s;
        ASSERT_GT(s.decode(m.bytes.data(), 0, static_cast<int>(m.bytes.size())), 0);
        utime = s.utime;
      } else if (m.channel == "LIDAR") {
        point_cloud_t s;
        ASSERT_GT(s.decode(m.bytes.data(), 0, static_cast<int>(m.bytes.size())), 0);
        utime = s.utime;
      } else {
        w.active.clear();  // never promised: playback waits for lio here
        return;
      }
      ++seen[m.channel];
      in_promise = w.keepCovering(m.channel, utime);
      covered[m.channel] += in_promise;
      outputs_before = w.outputs;
    };
    setup.after_each = [&](const Message&) {
      broken += in_promise && w.outputs != outputs_before;
      if (w.have) w.active.push_back(w.last);
    };
    int64_t first_image = 0, last_image = 0;
    std::vector<Message> in = handoff ? withImages(syntheticRun(), &first_image, &last_image) : syntheticRun();
    if (variant >= 5) {
      for (Message& m : in) {
        if (variant == 5 && m.channel == "CAMERA") m.order_key += 30'000;
        if (variant >= 6 && m.channel == "LIDAR") m.order_key -= 100'000;
      }
      livo_test::sortByArrival(&in);
    }
    if (variant == 4) {
      std::vector<Message> jittery;
      int64_t k = 0;
      for (const Message& m : in) {
        if (m.channel != "CAMERA") {
          jittery.push_back(m);
          continue;
        }
        if (++k % 9 == 0) continue;  // missed
        const int64_t jitter_ms = static_cast<int64_t>((static_cast<uint32_t>(k) * 2654435761u >> 8) % 49) - 24;
        const int64_t t = m.order_key + jitter_ms * 1000;
        jittery.push_back(tinyImage(t));
      }
      livo_test::sortByArrival(&jittery);
      in.swap(jittery);
    }
    if (variant == 2) {
      std::vector<Message> disordered;
      int64_t k = 0;
      for (const Message& m : in) {
        disordered.push_back(m);
        if (m.channel != "IMU") continue;
        if (++k % 11 == 0) disordered.push_back(m);
        const size_t n = disordered.size();
        if (k % 7 == 0 && n >= 2 && disordered[n - 2].channel == "IMU") std::swap(disordered[n - 2], disordered[n - 1]);
      }
      in.swap(disordered);
    }
    if (wheels) {
      // 50 Hz, the body's forward speed on both wheels (the content does not matter here)
      for (int64_t t = kBaseTime; t <= kBaseTime + 3'000'000; t += 20'000) {
        const Pose3 a = seq.truth(t), b = seq.truth(t + 10'000);
        const double v = (a.linear().transpose() * (b.translation() - a.translation())).x() / 0.01;
        wheel_odometry_t m{};
        m.utime = t;
        m.left_speed = m.right_speed = v;
        in.push_back(encode(t, "WHEEL", m));
      }
      livo_test::sortByArrival(&in);
    }
    const Outputs out = runNode(in, nullptr, setup);
    EXPECT_GE(out.odometry.size(), 20u) << "variant " << variant;  // the run goes on (24-29 of 30 sweeps)
    if (handoff) {
      EXPECT_GE(counts.kept_prior, 40);
    }
    EXPECT_EQ(broken, 0) << "variant " << variant;
    // per 0.1 s sweep, 20 samples: the one past the sweep end (and with images, those past each image)
    EXPECT_GT(covered["IMU"], seen["IMU"] * (handoff ? 8 : 9) / 10) << covered["IMU"] << " of " << seen["IMU"];
    if (wheels) {
      EXPECT_GT(covered["WHEEL"], seen["WHEEL"] * 7 / 10) << covered["WHEEL"] << " of " << seen["WHEEL"];
    }
    if (variant == 1 || variant == 6) {  // a regular camera: every image but the first (none due yet)
      EXPECT_GT(covered["CAMERA"], seen["CAMERA"] * 9 / 10) << covered["CAMERA"] << " of " << seen["CAMERA"];
    }
    if (variant >= 6) {  // sweeps that arrive before the IMU passes the previous one's end
      EXPECT_GT(covered["LIDAR"], seen["LIDAR"] * 9 / 10) << covered["LIDAR"] << " of " << seen["LIDAR"];
    }
    std::printf(
        "%s: %lld of %lld IMU samples, %lld of %lld images, %lld of %lld sweeps, %lld of %lld wheel readings "
        "inside the quiet promises\n",
        variant == 0   ? "LiDAR-only"
        : variant == 1 ? "camera hand-off"
        : variant == 2 ? "swapped and duplicated IMU"
        : variant == 3 ? "wheels"
        : variant == 4 ? "hand-off, jittery camera"
        : variant == 5 ? "hand-off, images 30 ms late"
        : variant == 6 ? "hand-off, sweeps at their start"
                       : "hand-off, wheels, sweeps at their start",
        static_cast<long long>(covered["IMU"]), static_cast<long long>(seen["IMU"]),
        static_cast<long long>(covered["CAMERA"]), static_cast<long long>(seen["CAMERA"]),
        static_cast<long long>(covered["LIDAR"]), static_cast<long long>(seen["LIDAR"]),
        static_cast<long long>(covered["WHEEL"]), static_cast<long long>(seen["WHEEL"]));
  }
}

namespace {
struct LioProgress {
  progress_t last{};
  void onProgress(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    progress_t p;
    if (p.decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) > 0 && p.node == "lio") last = p;
  }
};
}  // namespace

// While lio waits for a posterior it promises STATE_POSTERIOR quiet, and the IMU samples up to the
// next event: lockstep playback then sends those on while vio is still working on the image (an
// answer in flight, LockstepGate::mayPublish). The answer may arrive anywhere among them: the
// odometry, scans and keyframes are byte for byte those of an answer that came at once.
TEST(LioNode, AnAnswerArrivingAmongTheQuietSamplesChangesNothing) {
  const synth::SyntheticSequence seq = syntheticSequence();
  int64_t first_image = 0, last_image = 0;
  std::vector<Message> in;
  struct Run {
    Outputs out;
    LioNode::HandoffCounts counts;
    int64_t sent_while_held = 0;  // messages lio took while an answer was held back
  };
  // held_for(request id): how many covered messages an answer is held for (at most: it goes out
  // before the first message lio's promises do not cover, where playback would wait for vio)
  std::string config;
  auto run = [&](const std::function<int(int64_t)>& held_for) {
    Run r;
    Pose3 T_lio_truth = Pose3::Identity();
    bool have_frame = false;
    Node* fake_vio = nullptr;
    std::optional<filter_state_t> held;
    int held_left = 0;
    LioProgress lio_progress;
    RunSetup setup;
    setup.config = config;
    setup.handoff = &r.counts;
    setup.attach = [&](Node& vio) {
      fake_vio = &vio;
      vio.subscribe<filter_state_t>("STATE_PRIOR", [&](const filter_state_t& prior) {
        if (!have_frame) T_lio_truth = poseOf(prior.position, prior.orientation) * seq.truth(prior.utime).inverse();
        have_frame = true;
        held = posteriorFromTruth(prior, T_lio_truth * seq.truth(prior.utime));
        held_left = held_for(prior.request_id);
        if (held_left == 0) {
          vio.publish("STATE_POSTERIOR", *held);
          held.reset();
        }
      });
      // on the bus itself: a node's input would make the fake VIO report progress on each PROGRESS
      vio.lcm().subscribe("PROGRESS", &LioProgress::onProgress, &lio_progress);
      vio.declareOutput("STATE_POSTERIOR");
      vio.announce();
    };
    setup.before_each = [&](const Message& m) {
      if (!held) return;
      int64_t utime = 0;
      ASSERT_TRUE(messageUtime(m.bytes.data(), static_cast<int>(m.bytes.size()), &utime));
      bool posterior_quiet = false, covered = false;
      const progress_t& p = lio_progress.last;
      for (int i = 0; i < p.num_quiet; ++i) {
        const std::string& ch = p.quiet_channel[i];
        posterior_quiet |= ch == "STATE_POSTERIOR" && p.quiet_from[i] == INT64_MIN && p.quiet_before[i] == INT64_MAX;
        covered |= ch == m.channel && utime >= p.quiet_from[i] && utime < p.quiet_before[i];
      }
      // playback sends m before the answer only if lio promised both quiet (LockstepGate::mayPublish)
      if (posterior_quiet && covered && held_left-- > 0) {
        ++r.sent_while_held;
        return;
      }
      fake_vio->publish("STATE_POSTERIOR", *held);  // handled before m
      held.reset();
    };
    r.out = runNode(in, nullptr, setup);
    return r;
  };
  // sweeps arriving at their end (an image then waits for the sweep past it: two go out at once)
  // and at their start (as livo-sim writes them); and with lio giving up on an answer 30 ms past
  // the image, before the next event (the promises then end there)
  for (const int variant : {0, 1, 2}) {
    const bool at_start = variant >= 1;
    config = handoffConfig() + (variant == 2 ? "  posterior_max_wait_s: 0.03\n" : "");
    in = withImages(syntheticRun(), &first_image, &last_image);
    if (at_start) {
      for (Message& m : in)
        if (m.channel == "LIDAR") m.order_key -= 100'000;
      livo_test::sortByArrival(&in);
    }
    const Run at_once = run([](int64_t) { return 0; });
    const Run latest = run([](int64_t) { return 1000; });  // until playback would have to wait for vio
    const Run mixed = run([](int64_t id) { return static_cast<int>(id % 4); });
    ASSERT_GE(at_once.counts.adopted, 40);
    // the samples between the image time (and its 20 ms reorder window) and the next event go while
    // vio works: at least 2 an image (sweeps at their end: none for the first of each pair)
    EXPECT_GT(latest.sent_while_held, (variant == 1 ? 4 : 1) * at_once.counts.adopted) << latest.sent_while_held;
    EXPECT_GT(mixed.sent_while_held, at_once.counts.adopted / 2) << mixed.sent_while_held;
    for (const Run* r : {&latest, &mixed}) {
      EXPECT_EQ(r->counts.adopted, at_once.counts.adopted);
      EXPECT_EQ(r->counts.missing, 0);
      EXPECT_EQ(r->out.odometry_bytes, at_once.out.odometry_bytes);
      ASSERT_EQ(r->out.scans.size(), at_once.out.scans.size());
      for (size_t i = 0; i < r->out.scans.size(); ++i) {
        EXPECT_EQ(r->out.scans[i].cloud.x, at_once.out.scans[i].cloud.x) << "scan " << i;
        EXPECT_EQ(r->out.scans[i].cloud.y, at_once.out.scans[i].cloud.y) << "scan " << i;
        EXPECT_EQ(r->out.scans[i].cloud.z, at_once.out.scans[i].cloud.z) << "scan " << i;
      }
      EXPECT_EQ(r->out.keyframes.size(), at_once.out.keyframes.size());
    }
    std::printf(
        "sweeps arriving at their %s%s: messages lio took while an answer was in flight: %lld (held to the "
        "last), %lld (mixed), %lld images\n",
        at_start ? "start" : "end", variant == 2 ? ", posterior_max_wait_s 0.03" : "",
        static_cast<long long>(latest.sent_while_held), static_cast<long long>(mixed.sent_while_held),
        static_cast<long long>(at_once.counts.adopted));
  }
}

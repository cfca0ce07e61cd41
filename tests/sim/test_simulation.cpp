// The whole simulator: shipped configs make logs with the configured channels and rates, the log
// is ordered and reproducible byte for byte, the EuRoC re-simulation keeps the real IMU stream,
// and configuration mistakes are reported with the file and key.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>

#include <lcm/lcm-cpp.hpp>

#include "livo/asl_dataset.hpp"
#include "livo/image_t.hpp"
#include "livo/imu_t.hpp"
#include "livo/point_cloud_t.hpp"
#include "livo/pose_t.hpp"
#include "livo/sim/log_writer.hpp"
#include "livo/sim/simulation_setup.hpp"
#include "livo/sim/simulator.hpp"
#include "livo/trajectory_io.hpp"
#include "livo/wheel_odometry_t.hpp"
#include "sim_test_support.hpp"
#include "temp_path.hpp"

using namespace livo;
using namespace livo::sim;

namespace {

std::string configPath(const std::string& name) {
  return std::string(LIVO_SOURCE_DIR) + "/config/sim/" + name + ".yaml";
}

std::string simulateToLog(const std::string& config, double duration, uint64_t seed, int threads,
                          const std::string& tag) {
  SimOverrides o;
  o.duration_s = duration;
  o.seed = seed;
  o.threads = threads;
  const SimulationSetup setup = loadSimulation(configPath(config), o);
  const std::string path = livo_test::tempPath("sim_") + config + "_" + tag + ".lcmlog";
  {
    LogWriter writer(path, setup.rig.channels);
    Simulator(setup).run(writer);
  }
  return path;
}

std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

template <class Msg>
int64_t utimeOf(const lcm::LogEvent* ev) {
  Msg m;
  EXPECT_EQ(m.decode(ev->data, 0, ev->datalen), ev->datalen) << ev->channel;
  return m.utime;
}

struct ChannelCount {
  int64_t count = 0, first = 0, last = 0;
};

/// Reads a log, checks order, tie order and that each event's stamp is its message's utime.
std::map<std::string, ChannelCount> checkLog(const std::string& path, const RigChannels& ch) {
  const std::map<std::string, int> rank = {{ch.imu, 0},   {ch.wheel, 1},  {ch.ground_truth, 2},
                                           {ch.lidar, 3}, {ch.camera, 4}, {ch.depth, 5}};
  lcm::LogFile log(path, "r");
  EXPECT_TRUE(log.good());
  std::map<std::string, ChannelCount> out;
  int64_t prev_t = -1;
  int prev_rank = -1;
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    int64_t u = -1;
    if (ev->channel == ch.imu)
      u = utimeOf<imu_t>(ev);
    else if (ev->channel == ch.ground_truth)
      u = utimeOf<pose_t>(ev);
    else if (ev->channel == ch.wheel)
      u = utimeOf<wheel_odometry_t>(ev);
    else if (ev->channel == ch.lidar)
      u = utimeOf<point_cloud_t>(ev);
    else if (ev->channel == ch.camera || ev->channel == ch.depth)
      u = utimeOf<image_t>(ev);
    else
      ADD_FAILURE() << "unexpected channel " << ev->channel;
    EXPECT_EQ(u, ev->timestamp) << ev->channel;
    EXPECT_GE(ev->timestamp, prev_t);
    if (ev->timestamp == prev_t) {
      EXPECT_GE(rank.at(ev->channel), prev_rank) << "tie order at " << ev->timestamp;
    }
    prev_t = ev->timestamp;
    prev_rank = rank.at(ev->channel);
    ChannelCount& c = out[ev->channel];
    if (c.count++ == 0) c.first = ev->timestamp;
    c.last = ev->timestamp;
  }
  return out;
}

void expectRate(const std::map<std::string, ChannelCount>& counts, const std::string& channel, double rate_hz,
                double duration, double phase = 0.0) {
  ASSERT_TRUE(counts.count(channel)) << channel;
  const ChannelCount& c = counts.at(channel);
  EXPECT_NEAR(static_cast<double>(c.count), std::floor(duration * rate_hz - phase + 1e-9) + 1.0, 1.0) << channel;
  if (c.count > 1) {
    EXPECT_NEAR((c.count - 1) / ((c.last - c.first) * 1e-6), rate_hz, 0.01 * rate_hz) << channel;
  }
}

std::string configError(const std::string& yaml) {
  try {
    loadSimulation(Config::fromString(yaml, "bad.yaml"), "");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Simulation, SameSeedGivesAByteIdenticalLogWhateverTheThreads) {
  const std::string a = readBytes(simulateToLog("room", 0.6, 7, 2, "a"));
  const std::string b = readBytes(simulateToLog("room", 0.6, 7, 2, "b"));
  const std::string c = readBytes(simulateToLog("room", 0.6, 7, 1, "c"));
  const std::string d = readBytes(simulateToLog("room", 0.6, 8, 2, "d"));
  ASSERT_GT(a.size(), 1000000u);
  EXPECT_TRUE(a == b);
  EXPECT_TRUE(a == c);
  EXPECT_FALSE(a == d);  // other noise (and other LiDAR dropouts)
}

// livo-sim --no-images: the camera's and depth images left out, every other channel byte for byte
// as with them (each sensor draws its noise from a stream of its own), on a config with auto
// exposure and drawn calibration errors and on one with an RGB-D camera and wheels.
TEST(Simulation, NoImagesLeavesEveryOtherChannelAsItIs) {
  const auto channelBytes = [](const std::string& path) {
    std::map<std::string, std::string> bytes;
    lcm::LogFile log(path, "r");
    while (const lcm::LogEvent* ev = log.readNextEvent())
      bytes[ev->channel] += std::to_string(ev->timestamp) + ":" +
                            std::string(static_cast<const char*>(ev->data), static_cast<size_t>(ev->datalen));
    return bytes;
  };
  for (const std::string config : {"room_hard", "tree_campus"}) {
    SCOPED_TRACE(config);
    SimOverrides o;
    o.duration_s = 0.6;
    o.seed = 5;
    const SimulationSetup with = loadSimulation(configPath(config), o);
    o.no_images = true;
    const SimulationSetup without = loadSimulation(configPath(config), o);
    const std::string a = livo_test::tempPath("sim_") + config + "_images.lcmlog";
    const std::string b = livo_test::tempPath("sim_") + config + "_no_images.lcmlog";
    {
      LogWriter wa(a, with.rig.channels), wb(b, without.rig.channels);
      Simulator(with).run(wa);
      Simulator(without).run(wb);
    }
    std::map<std::string, std::string> all = channelBytes(a);
    const std::map<std::string, std::string> rest = channelBytes(b);
    ASSERT_EQ(all.count(with.rig.channels.camera), 1u);
    EXPECT_EQ(all.count(with.rig.channels.depth), config == "tree_campus" ? 1u : 0u);
    all.erase(with.rig.channels.camera);
    all.erase(with.rig.channels.depth);
    EXPECT_GE(all.size(), 3u);  // IMU, LiDAR, ground truth (and wheels)
    EXPECT_TRUE(all == rest);
  }
}

// rig.camera.time_offset_s: images carry the camera's clock (IMU time - offset), are rendered at
// the IMU time and logged there, so the log stays in time order.
TEST(Simulation, CameraTimeOffsetStampsImagesOnTheCameraClock) {
  std::ifstream in(configPath("room"));
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  const std::string key = "    T_I_C:";
  const size_t at = yaml.find(key);
  ASSERT_NE(at, std::string::npos);
  yaml.insert(at, "    time_offset_s: 0.0042\n");
  SimOverrides o;
  o.duration_s = 0.3;
  const SimulationSetup shifted =
      loadSimulation(Config::fromString(yaml, "room_offset.yaml"), std::string(LIVO_SOURCE_DIR) + "/config/sim", o);
  const SimulationSetup plain = loadSimulation(configPath("room"), o);
  ASSERT_TRUE(shifted.rig.camera);
  EXPECT_DOUBLE_EQ(shifted.rig.camera->time_offset_s, 0.0042);
  struct Images : SensorDataSink {
    std::vector<CameraImage> images;
    void write(const ImuReading&) override {}
    void write(const PoseReading&) override {}
    void write(const WheelReading&) override {}
    void write(const LidarSweep&) override {}
    void write(const CameraImage& m) override { images.push_back(m); }
  } a, b;
  Simulator(shifted).run(a);
  Simulator(plain).run(b);
  ASSERT_EQ(a.images.size(), b.images.size());
  ASSERT_GE(a.images.size(), 5u);
  for (size_t i = 0; i < a.images.size(); ++i) {
    EXPECT_EQ(a.images[i].log_utime, b.images[i].utime);     // logged at the IMU time
    EXPECT_EQ(a.images[i].utime, b.images[i].utime - 4200);  // stamped on the camera clock
    EXPECT_EQ(a.images[i].data, b.images[i].data);           // the same view
  }
}

namespace {
/// The room config with every world and camera effect of this file switched on: an inline scene
/// with a glass pane, a vegetation crown, a walker and a car; rolling shutter and auto exposure.
std::string roomWithEveryEffect() {
  std::ifstream in(configPath("room"));
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  const std::string scene_key = "  scene_file: scenes/room.yaml\n";
  const size_t at = yaml.find(scene_key);
  EXPECT_NE(at, std::string::npos);
  yaml.replace(at, scene_key.size(), R"(  scene:
    textures:
      grey: {pattern: noise, scale: 0.5, color: [0.8, 0.8, 0.8]}
      leaves: {pattern: noise, scale: 0.1, color: [0.2, 0.5, 0.15], color2: [0.1, 0.3, 0.05]}
    objects:
      room: {type: box, center: [0, 0, 2], size: [14, 14, 4], texture: grey}
      pane: {type: box, center: [3.5, 0, 1.5], size: [0.01, 3, 2], texture: grey, material: glass, return_probability: 0.2, transmission: 0.7}
      bush: {type: vegetation, shape: cylinder, center: [-4, 4, 1], radius: 1.2, height: 2, texture: leaves, leaf_density: 1.5}
    movers:
      walker: {type: pedestrian, path: [-5, -5, 0, 5, -5, 0], speed: 1.4, phase: 0.3, texture: grey, reflectivity: 0.3}
      car: {type: car, path: [-5, 5.5, 0, 5, 5.5, 0, 5, -5.5, 0], speed: 5, texture: leaves}
)");
  const std::string noise_key = "    noise_std: 1.5\n";
  const size_t cam = yaml.find(noise_key);
  EXPECT_NE(cam, std::string::npos);
  yaml.insert(cam + noise_key.size(), "    rolling_shutter_s: 0.02\n    auto_exposure: {target_mean: 90, rate: 0.6}\n");
  return yaml;
}
}  // namespace

TEST(Simulation, EveryWorldAndCameraEffectStaysByteIdenticalWhateverTheThreads) {
  const std::string yaml = roomWithEveryEffect();
  std::vector<std::string> logs;
  for (int threads : {1, 2}) {
    SimOverrides o;
    o.duration_s = 0.6;
    o.threads = threads;
    const SimulationSetup setup = loadSimulation(Config::fromString(yaml, "room_effects.yaml"), "", o);
    EXPECT_EQ(setup.scene->moverCount(), 2u);
    EXPECT_TRUE(setup.options.camera.auto_exposure.enabled);
    const std::string path = livo_test::tempPath("sim_") + "room_effects_" + std::to_string(threads) + ".lcmlog";
    {
      LogWriter writer(path, setup.rig.channels);
      Simulator(setup).run(writer);
    }
    logs.push_back(readBytes(path));
  }
  ASSERT_GT(logs[0].size(), 1000000u);
  EXPECT_TRUE(logs[0] == logs[1]);
  // the controller moves the exposure away from the configured start
  SimOverrides o;
  o.duration_s = 0.6;
  const SimulationSetup setup = loadSimulation(Config::fromString(yaml, "room_effects.yaml"), "", o);
  test::CollectingSink sink;
  Simulator(setup).run(sink);
  ASSERT_GE(sink.images.size(), 10u);
  EXPECT_FLOAT_EQ(sink.images.front().exposure_time, 0.006f);
  EXPECT_NE(sink.images.back().exposure_time, sink.images.front().exposure_time);
}

// sim.camera.trigger: one image per sweep at its start or end stamp (room_triggered: 10 Hz camera
// triggered at the sweep end); free-running images sit halfway between the camera clock's ticks.
TEST(Simulation, TriggeredCameraFiresAtTheSweepStartsOrEnds) {
  std::ifstream in(configPath("room_triggered"));
  std::stringstream text;
  text << in.rdbuf();
  const std::string yaml = text.str();
  ASSERT_NE(yaml.find("    trigger: sweep_end\n"), std::string::npos);
  struct Stamps : SensorDataSink {
    std::vector<int64_t> sweep_starts, sweep_ends, images;
    void write(const ImuReading&) override {}
    void write(const PoseReading&) override {}
    void write(const WheelReading&) override {}
    void write(const LidarSweep& m) override {
      sweep_starts.push_back(m.utime);
      sweep_ends.push_back(m.utime + std::llround(m.duration * 1e6));
    }
    void write(const CameraImage& m) override { images.push_back(m.utime); }
  };
  SimOverrides o;
  o.duration_s = 0.65;
  for (const std::string trigger : {"sweep_end", "sweep_start", "free"}) {
    SCOPED_TRACE(trigger);
    std::string y = yaml;
    y.replace(y.find("trigger: sweep_end"), 18, "trigger: " + trigger);
    const SimulationSetup setup =
        loadSimulation(Config::fromString(y, "room_trigger.yaml"), std::string(LIVO_SOURCE_DIR) + "/config/sim", o);
    Stamps s;
    Simulator(setup).run(s);
    ASSERT_EQ(s.sweep_starts.size(), 6u);
    ASSERT_GE(s.images.size(), 6u);
    if (trigger == "free") {
      for (int64_t t : s.images) EXPECT_EQ((t - setup.start_utime) % 100'000, 50'000) << t;
      continue;
    }
    // every image on a sweep's start (end), and every sweep's start (end) within the run imaged
    const std::vector<int64_t>& at = trigger == "sweep_start" ? s.sweep_starts : s.sweep_ends;
    for (int64_t t : s.images) {
      if (t <= at.back()) {
        EXPECT_NE(std::find(at.begin(), at.end(), t), at.end()) << t;
      }
    }
    for (int64_t t : at) EXPECT_NE(std::find(s.images.begin(), s.images.end(), t), s.images.end()) << t;
  }
  // a trigger needs a LiDAR at the camera's rate, and a known name
  std::string mismatched = yaml;
  mismatched.replace(mismatched.find("rate_hz: 10   # one image per sweep"), 10, "rate_hz: 20");
  try {
    loadSimulation(Config::fromString(mismatched, "rates.yaml"), std::string(LIVO_SOURCE_DIR) + "/config/sim", o);
    ADD_FAILURE() << "a 20 Hz camera triggered by a 10 Hz LiDAR was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("sim.camera.trigger: sweep_end fires once per sweep"), std::string::npos)
        << e.what();
  }
  std::string unknown = yaml;
  unknown.replace(unknown.find("trigger: sweep_end"), 18, "trigger: strobe");
  try {
    loadSimulation(Config::fromString(unknown, "strobe.yaml"), std::string(LIVO_SOURCE_DIR) + "/config/sim", o);
    ADD_FAILURE() << "an unknown trigger was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("'strobe' is not free, sweep_start or sweep_end"), std::string::npos)
        << e.what();
  }
}

TEST(Simulation, ShippedConfigsLogTheirChannelsAtTheirRates) {
  for (const std::string name : {"room", "corridor", "campus_loop", "campus_loop_long", "parking", "hall_noisy",
                                 "room_hard", "corridor_hard", "campus_loop_hard", "campus_loop_long_hard",
                                 "parking_hard", "room_fr2_desk", "room_fr2_desk_hard", "bridge_deck", "tree_campus"}) {
    SCOPED_TRACE(name);
    const double duration = 0.5;
    const SimulationSetup setup = loadSimulation(configPath(name));
    const std::string log = simulateToLog(name, duration, 1, 2, "rates");
    const auto counts = checkLog(log, setup.rig.channels);
    const RigChannels& ch = setup.rig.channels;
    expectRate(counts, ch.imu, setup.rig.imu.rate_hz, duration);
    expectRate(counts, ch.ground_truth, setup.options.ground_truth_rate_hz, duration);
    if (setup.rig.wheel) expectRate(counts, ch.wheel, setup.rig.wheel->rate_hz, duration);
    if (setup.rig.camera) expectRate(counts, ch.camera, setup.rig.camera->rate_hz, duration, 0.5);
    if (setup.rig.camera && setup.rig.camera->depth) {
      expectRate(counts, ch.depth, setup.rig.camera->rate_hz, duration, 0.5);
    } else {
      EXPECT_EQ(counts.count(ch.depth), 0u);
    }
    if (setup.rig.lidar) {
      ASSERT_TRUE(counts.count(ch.lidar));
      EXPECT_EQ(counts.at(ch.lidar).count, static_cast<int64_t>(std::floor(duration * setup.rig.lidar->rate_hz)));
    }
    EXPECT_EQ(counts.begin()->second.first >= setup.start_utime, true);
  }
}

TEST(Simulation, EurocResimulationKeepsTheRealImuStream) {
  SimOverrides o;
  o.duration_s = 0.6;
  const SimulationSetup setup = loadSimulation(configPath("euroc_v1_01"), o);
  ASSERT_TRUE(setup.recorded);
  test::CollectingSink sink;
  Simulator(setup).run(sink);
  const auto real = readAslImuCsv(std::string(LIVO_SHARED_DATA) + "/euroc_v1_01/mav0/imu0/data.csv");
  ASSERT_GE(sink.imu.size(), 110u);  // 200 Hz
  size_t k = 0;
  while (real[k].stamp_ns < setup.start_utime * 1000) ++k;
  for (size_t i = 0; i < sink.imu.size(); ++i, ++k) {
    EXPECT_EQ(sink.imu[i].utime, (real[k].stamp_ns + 500) / 1000);
    EXPECT_EQ(sink.imu[i].angular_velocity, real[k].gyro);  // bit for bit
    EXPECT_EQ(sink.imu[i].linear_acceleration, real[k].accel);
  }
  // the ray-cast sensors and the ground truth follow the recorded motion
  ASSERT_FALSE(sink.sweeps.empty());
  ASSERT_FALSE(sink.images.empty());
  EXPECT_EQ(sink.images.front().width, 752);
  const livo::Trajectory gt = readTrajectory(std::string(LIVO_SHARED_DATA) + "/euroc_v1_01/groundtruth.tum");
  EXPECT_NEAR(sink.poses.front().utime * 1e-6, gt.front().stamp, 1e-5);
  EXPECT_LT((sink.poses.front().T_W_I.translation() - gt.front().pose.translation()).norm(), 1e-4);
  // the drone stays inside the modelled room: every LiDAR sweep is nearly complete
  for (const auto& s : sink.sweeps) EXPECT_GT(s.size(), 0.9 * 16 * 1024);
}

TEST(SimulationConfig, ErrorsNameTheFileAndKey) {
  const std::string rig = test::noiseFreeImuRig();
  const std::string good_traj = "  trajectory: {type: handheld, waypoints: [0,0,1, 2,0,1, 2,2,1]}\n";
  // the valid baseline
  EXPECT_EQ(configError(rig + "sim:\n" + test::boxRoomScene() + good_traj), "");

  EXPECT_NE(configError("rig:\n  imu: {gyro_noise_density: 0, gyro_random_walk: 0, accel_noise_density: 0, "
                        "accel_random_walk: 0}\nsim:\n" +
                        test::boxRoomScene() + good_traj)
                .find("bad.yaml: rig.imu.rate_hz: missing required key"),
            std::string::npos);
  EXPECT_NE(configError(rig + "sim:\n  duraton_s: 3\n" + test::boxRoomScene() + good_traj)
                .find("sim.duraton_s (did you mean sim.duration_s?)"),
            std::string::npos);
  EXPECT_NE(configError(rig +
                        "  lidar: {model: VLP-32, rate_hz: 10, min_range: 1, max_range: 50, range_noise_std: 0, "
                        "T_I_L: {translation: [0,0,0], rpy_deg: [0,0,0]}}\nsim:\n" +
                        test::boxRoomScene() + good_traj)
                .find("rig.lidar.model: unknown LiDAR model 'VLP-32'"),
            std::string::npos);
  // a real LiDAR the rig may name (config/rigs/) but that has no beam table in the simulator
  EXPECT_NE(configError(rig +
                        "  lidar: {model: VLP-32C, rate_hz: 10, min_range: 1, max_range: 50, range_noise_std: 0, "
                        "T_I_L: {translation: [0,0,0], rpy_deg: [0,0,0]}}\nsim:\n" +
                        test::boxRoomScene() + good_traj)
                .find("rig.lidar.model: livo-sim cannot simulate a 'VLP-32C'"),
            std::string::npos);
  std::string bad_texture = test::boxRoomScene();
  bad_texture.replace(bad_texture.find("texture: grey"), 13, "texture: gray");
  EXPECT_NE(configError(rig + "sim:\n" + bad_texture + good_traj)
                .find("sim.scene.objects.room.texture: unknown texture 'gray'"),
            std::string::npos);
  EXPECT_NE(configError(rig + "sim:\n" + test::boxRoomScene() + "  trajectory: {type: bicycle}\n")
                .find("sim.trajectory.type: unknown trajectory type 'bicycle'"),
            std::string::npos);
  EXPECT_NE(configError(rig + "sim:\n  scene_file: /nonexistent/scene.yaml\n" + good_traj)
                .find("sim.scene_file: /nonexistent/scene.yaml: cannot open"),
            std::string::npos);
  EXPECT_NE(
      configError(rig + "sim:\n" + test::boxRoomScene() +
                  "  trajectory: {type: recorded, ground_truth: /nonexistent/gt.tum, imu: /nonexistent/imu.csv}\n")
          .find("sim.trajectory.ground_truth: /nonexistent/gt.tum"),
      std::string::npos);
  EXPECT_NE(configError(rig + "sim:\n  camera: {noise_std: 1}\n" + test::boxRoomScene() + good_traj)
                .find("sim.camera: the rig has no camera"),
            std::string::npos);
  EXPECT_NE(configError(rig + "vio: {}\nsimulation: {}\n").find("simulation: unknown section"), std::string::npos);
  EXPECT_NE(configError(rig + "sim:\n  duration_s: -1\n" + test::boxRoomScene() + good_traj)
                .find("sim.duration_s: must be > 0"),
            std::string::npos);
  // world and camera effects
  std::string scene_with = test::boxRoomScene();
  scene_with += "    movers:\n      bus: {type: bus, path: [0,0,0, 1,0,0], speed: 1, texture: grey}\n";
  EXPECT_NE(
      configError(rig + "sim:\n" + scene_with + good_traj).find("sim.scene.movers.bus.type: unknown mover type 'bus'"),
      std::string::npos);
  std::string glass = test::boxRoomScene();
  glass.replace(glass.find("reflectivity: 0.5}"), 18, "reflectivity: 0.5, material: glass, transmission: 1.5}");
  EXPECT_NE(
      configError(rig + "sim:\n" + glass + good_traj).find("sim.scene.objects.room.transmission: must be in [0, 1]"),
      std::string::npos);
  std::string bush = test::boxRoomScene();
  bush +=
      "      bush: {type: vegetation, shape: cone, center: [0,0,1], radius: 1, height: 2, texture: grey, leaf_density: "
      "1}\n";
  EXPECT_NE(configError(rig + "sim:\n" + bush + good_traj)
                .find("sim.scene.objects.bush.shape: unknown vegetation shape 'cone'"),
            std::string::npos);
  const std::string cam_rig =
      rig +
      "  camera: {width: 64, height: 48, fx: 40, fy: 40, cx: 31.5, cy: 23.5, distortion: [0,0,0,0], "
      "rate_hz: 20, T_I_C: {translation: [0,0,0], rpy_deg: [-90,0,-90]}}\n";
  EXPECT_NE(configError(cam_rig + "sim:\n  camera: {rolling_shutter_s: 0.06}\n" + test::boxRoomScene() + good_traj)
                .find("sim.camera.rolling_shutter_s: must be in [0, 1 / rate_hz]"),
            std::string::npos);
  EXPECT_NE(configError(cam_rig + "sim:\n  camera: {auto_exposure: {rate: 0}}\n" + test::boxRoomScene() + good_traj)
                .find("sim.camera.auto_exposure.rate: must be in (0, 1]"),
            std::string::npos);
  EXPECT_NE(configError(cam_rig + "sim:\n  camera: {auto_exposure: {target: 90}}\n" + test::boxRoomScene() + good_traj)
                .find("sim.camera.auto_exposure.target"),
            std::string::npos);
  EXPECT_THROW(loadSimulation("/nonexistent/config.yaml"), ConfigError);
}

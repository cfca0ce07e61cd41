// ROS 1 bags written by the real ROS library (make_test_bags.py, a ctest fixture), one per chunk
// compression, imported and compared value by value with what was written.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "livo/image_t.hpp"
#include "livo/import/file_utils.hpp"
#include "livo/import/import_job.hpp"
#include "livo/imu_t.hpp"
#include "livo/point_cloud_t.hpp"
#include "livo/pose_t.hpp"
#include "log_reading.hpp"

namespace livo::import {
namespace {

using nlohmann::json;
const std::string kBags = LIVO_IMPORT_TEST_BAGS;

json expectedFor(const std::string& bag) {
  std::ifstream in(bag + ".expected.json");
  EXPECT_TRUE(in.good()) << bag << ".expected.json (written by the import_make_test_bags fixture)";
  return in ? json::parse(in) : json();
}

ImportJob bagJob(const std::string& bag, const std::string& out) {
  ImportJob job;
  job.format = "rosbag";
  job.input = bag;
  job.out = out;
  job.quiet = true;
  return job;
}

void expectCloud(const point_cloud_t& c, const json& e, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(c.utime, e["utime"].get<int64_t>());
  EXPECT_EQ(c.pattern, e["pattern"].get<int>());
  EXPECT_EQ(c.frame, "L");
  const json& pts = e["points"];
  ASSERT_EQ(c.num_points, static_cast<int>(pts.size()));
  for (int j = 0; j < c.num_points; ++j) {
    const json& p = pts[j];
    EXPECT_EQ(c.x[j], p[0].get<float>()) << "point " << j;
    EXPECT_EQ(c.y[j], p[1].get<float>()) << "point " << j;
    EXPECT_EQ(c.z[j], p[2].get<float>()) << "point " << j;
    EXPECT_EQ(c.intensity[j], p[3].get<float>()) << "point " << j;
    EXPECT_EQ(c.time_offset[j], p[4].get<float>()) << "point " << j;
    EXPECT_GE(c.time_offset[j], 0.0f);
    EXPECT_LT(c.time_offset[j], c.sweep_duration);
    EXPECT_EQ(c.ring[j], p[5].get<int>()) << "point " << j;
  }
}

class RosbagLayouts : public ::testing::TestWithParam<std::string> {};

TEST_P(RosbagLayouts, EveryTypeAndPointCloudLayoutMatchesTheBag) {
  const std::string compression = GetParam();
  const std::string bag = kBags + "/layouts_" + compression + ".bag";
  const json exp = expectedFor(bag);
  const std::string dir = test::freshTempDir("rosbag_" + compression);
  for (const std::string lidar :
       {"/velodyne_points", "/velodyne_end", "/ouster/points", "/hesai/pandar", "/livox/lidar"}) {
    SCOPED_TRACE(compression + " " + lidar);
    ImportJob job = bagJob(bag, dir + "/out.lcmlog");
    job.rosbag.imu_topic = "/imu";
    job.rosbag.lidar_topic = lidar;
    job.rosbag.camera_topic = "/camera/image_raw";
    job.rosbag.camera_right_topic = "/camera/compressed";
    job.rosbag.ground_truth_topic = lidar == "/livox/lidar" ? "/gt/pose" : "/gt/odom";
    const ImportOutcome r = runImport(job, nullptr);
    EXPECT_TRUE(r.ok());
    EXPECT_EQ(r.report.metadataValue("bag_chunks").find(compression), 1u) << r.report.metadataValue("bag_chunks");
    const auto events = test::readLog(job.out);
    EXPECT_TRUE(test::inTimeOrder(events));

    const auto imu = test::messagesOn<imu_t>(events, "IMU");
    ASSERT_EQ(imu.size(), exp["imu"].size());
    for (size_t i = 0; i < imu.size(); ++i) {
      EXPECT_EQ(imu[i].utime, exp["imu"][i]["utime"].get<int64_t>());
      for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(imu[i].angular_velocity[k], exp["imu"][i]["gyro"][k].get<double>());
        EXPECT_EQ(imu[i].linear_acceleration[k], exp["imu"][i]["accel"][k].get<double>());
      }
    }
    const auto clouds = test::messagesOn<point_cloud_t>(events, "LIDAR");
    const json& ec = exp["clouds"][lidar];
    ASSERT_EQ(clouds.size(), ec.size());
    for (size_t k = 0; k < clouds.size(); ++k) expectCloud(clouds[k], ec[k], "cloud " + std::to_string(k));
    if (lidar == "/ouster/points") {
      EXPECT_EQ(clouds[0].num_rings, 4) << "organised cloud: height rings";
    }
    if (lidar == "/velodyne_points") {
      EXPECT_EQ(r.report.skipped().at("LiDAR points with a NaN/inf coordinate").count, 3);
    }

    const auto raw = test::messagesOn<image_t>(events, "CAMERA");
    ASSERT_EQ(raw.size(), exp["image"].size());
    for (size_t k = 0; k < raw.size(); ++k) {
      const json& e = exp["image"][k];
      EXPECT_EQ(raw[k].utime, e["utime"].get<int64_t>());
      EXPECT_EQ(raw[k].encoding, e["encoding"].get<int>());
      EXPECT_EQ(raw[k].width, e["width"].get<int>());
      EXPECT_EQ(raw[k].height, e["height"].get<int>());
      EXPECT_EQ(raw[k].row_stride, e["stride"].get<int>());
      EXPECT_EQ(raw[k].data, e["data"].get<std::vector<uint8_t>>());
    }
    const auto comp = test::messagesOn<image_t>(events, "CAMERA_RIGHT");
    ASSERT_EQ(comp.size(), exp["compressed"].size());
    for (size_t k = 0; k < comp.size(); ++k) {
      EXPECT_EQ(comp[k].utime, exp["compressed"][k]["utime"].get<int64_t>());
      EXPECT_EQ(comp[k].encoding, exp["compressed"][k]["encoding"].get<int>());
      EXPECT_EQ(comp[k].size, exp["compressed"][k]["size"].get<int>());
    }
    EXPECT_EQ(comp[0].width, 40);  // the JPEG's SOF header
    EXPECT_EQ(comp[0].height, 24);
    EXPECT_EQ(comp[1].width, 752);  // the PNG's IHDR (a EuRoC frame)
    EXPECT_EQ(comp[1].height, 480);

    const auto gt = test::messagesOn<pose_t>(events, "GROUND_TRUTH");
    const json& eg = exp[lidar == "/livox/lidar" ? "pose" : "odom"];
    ASSERT_EQ(gt.size(), eg.size());
    for (size_t k = 0; k < gt.size(); ++k) {
      EXPECT_EQ(gt[k].utime, eg[k]["utime"].get<int64_t>());
      EXPECT_EQ(gt[k].parent_frame, "W");
      EXPECT_EQ(gt[k].child_frame, "I");
      for (int i = 0; i < 3; ++i) EXPECT_EQ(gt[k].position[i], eg[k]["position"][i].get<double>());
      for (int i = 0; i < 4; ++i) EXPECT_NEAR(gt[k].orientation[i], eg[k]["wxyz"][i].get<double>(), 1e-15);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Compressions, RosbagLayouts, ::testing::Values("none", "bz2", "lz4"));

TEST(RosbagImport, UnknownTypeOnAMappedTopicIsCountedWithAReason) {
  const std::string dir = test::freshTempDir("rosbag_unknown");
  ImportJob job = bagJob(kBags + "/layouts_none.bag", dir + "/out.lcmlog");
  job.rosbag.imu_topic = "/imu";
  job.rosbag.ground_truth_topic = "/chatter";
  job.rosbag.auto_map = false;
  const ImportOutcome r = runImport(job, nullptr);
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(r.report.skipped().at("unsupported message type std_msgs/String on /chatter").count, 1);
  EXPECT_EQ(r.channel_counts.at("IMU"), 40);
  EXPECT_EQ(r.channel_counts.count("GROUND_TRUTH"), 0u);
}

TEST(RosbagImport, AutoMapsTheOnlyTopicOfAType) {
  const std::string dir = test::freshTempDir("rosbag_auto");
  ImportJob job = bagJob(kBags + "/layouts_lz4.bag", dir + "/out.lcmlog");
  const ImportOutcome r = runImport(job, nullptr);
  EXPECT_EQ(r.channel_counts.at("IMU"), 40) << "the bag's only sensor_msgs/Imu topic";
  EXPECT_EQ(r.channel_counts.count("LIDAR"), 0u) << "five PointCloud2 topics: none chosen";
}

// An RGB-D camera's bag: the colour camera and its aligned depth (16UC1, mm) side by side.
bool anyNoteHas(const ImportReport& report, const std::string& text) {
  for (const std::string& n : report.notes())
    if (n.find(text) != std::string::npos) return true;
  return false;
}

TEST(RosbagImport, DepthImagesGoToTheDepthChannelNotTheCamera) {
  const std::string bag = kBags + "/rgbd.bag";
  const json exp = expectedFor(bag);
  const std::string dir = test::freshTempDir("rosbag_rgbd");
  const ImportOutcome r = runImport(bagJob(bag, dir + "/out.lcmlog"), nullptr);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.channel_counts.at("CAMERA"), 3) << "the only colour Image topic; the depth topic is no camera";
  EXPECT_EQ(r.report.metadataValue("topic_camera"), "\"/camera/color/image_raw\"");
  EXPECT_EQ(r.report.metadataValue("topic_depth"), "\"/camera/aligned_depth_to_color/image_raw\"");
  EXPECT_TRUE(anyNoteHas(r.report, "--depth not given: using the bag's only fitting topic"));
  const auto depth = test::messagesOn<image_t>(test::readLog(dir + "/out.lcmlog"), "DEPTH");
  ASSERT_EQ(depth.size(), 3u);
  for (size_t k = 0; k < depth.size(); ++k) {
    const image_t& d = depth[k];
    const json& e = exp["depth"][k];
    EXPECT_EQ(d.utime, e["utime"].get<int64_t>());
    EXPECT_EQ(d.encoding, int8_t{image_t::ENCODING_DEPTH16});
    EXPECT_EQ(d.frame, "C");
    EXPECT_EQ(d.width, 3);
    EXPECT_EQ(d.height, 2);
    ASSERT_EQ(d.row_stride, 8) << "the padded rows are kept";
    ASSERT_EQ(d.size, 16);
    for (int i = 0; i < 6; ++i) {
      const uint8_t* p = &d.data[(i / 3) * 8 + (i % 3) * 2];
      EXPECT_EQ(p[0] | (p[1] << 8), e["millimetres"][i].get<int>()) << "frame " << k << " pixel " << i;
    }
  }
}

TEST(RosbagImport, SeveralDepthTopicsAreNotGuessedAndEachCanBeNamed) {
  const std::string bag = kBags + "/rgbd_two_depths.bag";
  const json exp = expectedFor(bag);
  {
    const std::string dir = test::freshTempDir("rosbag_two_depths_auto");
    const ImportOutcome r = runImport(bagJob(bag, dir + "/out.lcmlog"), nullptr);
    EXPECT_EQ(r.channel_counts.at("CAMERA"), 3);
    EXPECT_EQ(r.channel_counts.count("DEPTH"), 0u);
    EXPECT_TRUE(anyNoteHas(r.report, "--depth not given and several topics fit"));
  }
  {
    // 32FC1, big-endian in the bag: little-endian floats in the log, NaN as sent
    const std::string dir = test::freshTempDir("rosbag_two_depths_float");
    ImportJob job = bagJob(bag, dir + "/out.lcmlog");
    job.rosbag.depth_topic = "/camera/depth/image_float";
    const ImportOutcome r = runImport(job, nullptr);
    ASSERT_TRUE(r.ok());
    const auto depth = test::messagesOn<image_t>(test::readLog(dir + "/out.lcmlog"), "DEPTH");
    ASSERT_EQ(depth.size(), 3u);
    for (size_t k = 0; k < depth.size(); ++k) {
      EXPECT_EQ(depth[k].encoding, int8_t{image_t::ENCODING_DEPTH32F});
      ASSERT_EQ(depth[k].size, 24);
      for (int i = 0; i < 6; ++i) {
        float v;
        std::memcpy(&v, &depth[k].data[4 * i], 4);
        const json& e = exp["depth"][k]["metres"][i];
        if (e.is_null())
          EXPECT_TRUE(std::isnan(v)) << "pixel " << i;
        else
          EXPECT_FLOAT_EQ(v, e.get<float>()) << "frame " << k << " pixel " << i;
      }
    }
  }
  {
    // a depth topic named as the camera is refused with the reason
    const std::string dir = test::freshTempDir("rosbag_depth_as_camera");
    ImportJob job = bagJob(bag, dir + "/out.lcmlog");
    job.rosbag.camera_topic = "/camera/aligned_depth_to_color/image_raw";
    const ImportOutcome r = runImport(job, nullptr);
    EXPECT_EQ(r.channel_counts.count("CAMERA"), 0u);
    bool refused = false;
    for (const auto& [reason, s] : r.report.skipped())
      refused |= reason.find("'16UC1' is depth, not a camera image") != std::string::npos && s.count == 3;
    EXPECT_TRUE(refused);
  }
}

TEST(RosbagImport, NtuViralPresetConvertsEndOfSweepStampsAndKeepsThePrismOffset) {
  const std::string bag = kBags + "/ntu_viral.bag";
  const json exp = expectedFor(bag);
  const std::string dir = test::freshTempDir("rosbag_ntu");
  ImportJob job = bagJob(bag, dir + "/ntu.lcmlog");
  job.preset = "ntu_viral";
  applyPreset(job);
  const ImportOutcome r = runImport(job, nullptr);
  ASSERT_TRUE(r.ok());
  const auto events = test::readLog(job.out);
  EXPECT_TRUE(test::inTimeOrder(events));
  EXPECT_EQ(test::messagesOn<imu_t>(events, "IMU").size(), exp["imu"].size());
  const auto clouds = test::messagesOn<point_cloud_t>(events, "LIDAR");
  ASSERT_EQ(clouds.size(), 3u) << "only /os1_cloud_node1 (horizontal)";
  for (size_t k = 0; k < clouds.size(); ++k) {
    expectCloud(clouds[k], exp["clouds"][k], "cloud " + std::to_string(k));
    EXPECT_EQ(clouds[k].num_rings, 16);
    EXPECT_FLOAT_EQ(clouds[k].sweep_duration, 0.1f);
  }
  const auto left = test::messagesOn<image_t>(events, "CAMERA");
  const auto right = test::messagesOn<image_t>(events, "CAMERA_RIGHT");
  ASSERT_EQ(left.size(), 3u);
  ASSERT_EQ(right.size(), 3u);
  EXPECT_EQ(left[1].encoding, +image_t::ENCODING_GRAY8);
  EXPECT_EQ(left[1].data, exp["left"][1]["data"].get<std::vector<uint8_t>>());
  EXPECT_EQ(right[2].data, exp["right"][2]["data"].get<std::vector<uint8_t>>());
  const auto prism = test::messagesOn<pose_t>(events, "GROUND_TRUTH");
  ASSERT_EQ(prism.size(), 3u);
  for (size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(prism[k].utime, exp["prism"][k]["utime"].get<int64_t>());
    for (int i = 0; i < 3; ++i) EXPECT_EQ(prism[k].position[i], exp["prism"][k]["position"][i].get<double>());
    EXPECT_EQ(prism[k].orientation[0], 1.0);
    EXPECT_EQ(prism[k].child_frame, "prism");
  }
  EXPECT_EQ(r.report.metadataValue("prism_offset_body"), "[-0.293656, -0.012288, -0.273095]");
  std::ifstream sidecar(job.out + ".meta.yaml");
  const std::string text((std::istreambuf_iterator<char>(sidecar)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("prism_offset_body: [-0.293656, -0.012288, -0.273095]"), std::string::npos) << text;
  EXPECT_NE(text.find("preset: \"ntu_viral\""), std::string::npos);
}

TEST(RosbagImport, MalformedMessagesAreSkippedWithFileRecordAndField) {
  const std::string dir = test::freshTempDir("rosbag_bad");
  ImportJob job = bagJob(kBags + "/bad.bag", dir + "/bad.lcmlog");
  job.rosbag.imu_topic = "/imu";
  job.rosbag.lidar_topic = "/points";
  job.rosbag.camera_topic = "/camera";
  const ImportOutcome r = runImport(job, nullptr);
  EXPECT_TRUE(r.ok()) << "bad messages are skipped, not fatal";
  EXPECT_EQ(r.channel_counts.at("LIDAR"), 1);
  EXPECT_EQ(r.channel_counts.at("IMU"), 5);
  auto find = [&](const std::string& needle) -> std::string {
    for (const auto& [reason, s] : r.report.skipped())
      if (reason.find(needle) != std::string::npos) return s.first_where;
    return "";
  };
  const std::string no_z = find("field 'z': missing");
  EXPECT_NE(no_z.find("bad.bag: message record 2 (topic /points)"), std::string::npos) << no_z;
  EXPECT_NE(find("field 'time': per-point times span").find("message record 3"), std::string::npos);
  EXPECT_NE(find("field 'data'").find("message record 4"), std::string::npos);
  EXPECT_NE(find("field 'encoding': 'yuv422'").find("message record 5"), std::string::npos);
}

TEST(RosbagImport, TruncatedBagKeepsWhatCameBeforeTheCut) {
  const std::string dir = test::freshTempDir("rosbag_truncated");
  for (const std::string compression : {"none", "bz2", "lz4"}) {
    SCOPED_TRACE(compression);
    const std::vector<uint8_t> bytes = readFileBytes(kBags + "/layouts_" + compression + ".bag");
    const std::string cut = dir + "/cut_" + compression + ".bag";
    {
      std::ofstream out(cut, std::ios::binary);
      out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size() * 6 / 10));
    }
    ImportJob job = bagJob(cut, dir + "/cut_" + compression + ".lcmlog");
    job.rosbag.imu_topic = "/imu";
    job.rosbag.lidar_topic = "/velodyne_points";
    const ImportOutcome r = runImport(job, nullptr);
    EXPECT_FALSE(r.ok());
    EXPECT_TRUE(r.wrote_log);
    ASSERT_EQ(r.report.errors().size(), 1u);
    const std::string& e = r.report.errors()[0];
    EXPECT_NE(e.find(cut + ": record at offset "), std::string::npos) << e;
    EXPECT_NE(e.find("truncated"), std::string::npos) << e;
    EXPECT_GT(r.channel_counts.at("IMU"), 0) << "messages before the cut are kept";
    EXPECT_EQ(test::readLog(job.out).size(),
              static_cast<size_t>(r.channel_counts.at("IMU") + r.channel_counts.at("LIDAR")));
  }
}

TEST(RosbagImport, NotABagIsAClearError) {
  const std::string dir = test::freshTempDir("rosbag_notabag");
  ImportJob job = bagJob(std::string(LIVO_SHARED_DATA) + "/euroc_v1_01/groundtruth.tum", dir + "/x.lcmlog");
  const ImportOutcome r = runImport(job, nullptr);
  ASSERT_EQ(r.report.errors().size(), 1u);
  EXPECT_NE(r.report.errors()[0].find("groundtruth.tum: not a ROS bag"), std::string::npos) << r.report.errors()[0];
}

}  // namespace
}  // namespace livo::import

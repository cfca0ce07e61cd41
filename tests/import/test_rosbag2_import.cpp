// ROS 2 bags written by other implementations than the reader (rosbag2_fixtures/: @mcap/core's
// McapWriter with chunks none / zstd / lz4, CDR from @foxglove/rosmsg2-serialization and
// @foxglove/cdr; SQLite .db3 from Python's sqlite3), imported and compared value by value with the
// expected.json the fixture script wrote.
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "livo/image_t.hpp"
#include "livo/import/import_job.hpp"
#include "livo/import/rosbag2_import.hpp"
#include "livo/imu_t.hpp"
#include "livo/point_cloud_t.hpp"
#include "livo/pose_t.hpp"
#include "log_reading.hpp"

namespace livo::import {
namespace {

using nlohmann::json;
const std::string kFixtures = LIVO_IMPORT_TEST_ROSBAG2;

json expected() {
  std::ifstream in(kFixtures + "/expected.json");
  EXPECT_TRUE(in.good()) << kFixtures << "/expected.json (written by the import_make_rosbag2_fixtures fixture)";
  return in ? json::parse(in) : json();
}

int64_t utimeOf(const json& e) { return e["sec"].get<int64_t>() * 1000000 + e["nanosec"].get<int64_t>() / 1000; }

ImportJob rosbag2Job(const std::string& input, const std::string& out) {
  ImportJob job;
  job.format = "rosbag2";
  job.input = kFixtures + "/" + input;
  job.out = out;
  job.quiet = true;
  job.rosbag.imu_topic = "/imu";
  job.rosbag.lidar_topic = "/points";
  job.rosbag.camera_topic = "/camera/image_raw";
  job.rosbag.camera_right_topic = "/cam1/compressed";
  job.rosbag.ground_truth_topic = "/odom";
  return job;
}

/// The skip whose reason contains `needle`: its first occurrence's "where", "" if none.
std::string skipWhere(const ImportReport& report, const std::string& needle) {
  for (const auto& [reason, s] : report.skipped())
    if (reason.find(needle) != std::string::npos) return s.first_where;
  return "";
}

void expectImu(const std::vector<imu_t>& imu, const json& e) {
  ASSERT_EQ(imu.size(), e.size());
  for (size_t i = 0; i < imu.size(); ++i) {
    SCOPED_TRACE("imu " + std::to_string(i));
    EXPECT_EQ(imu[i].utime, utimeOf(e[i]));
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(imu[i].angular_velocity[k], e[i]["w"][k].get<double>());
      EXPECT_EQ(imu[i].linear_acceleration[k], e[i]["a"][k].get<double>());
    }
  }
}

void expectPoses(const std::vector<pose_t>& poses, const json& e) {
  ASSERT_EQ(poses.size(), e.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    SCOPED_TRACE("pose " + std::to_string(i));
    EXPECT_EQ(poses[i].utime, utimeOf(e[i]));
    EXPECT_EQ(poses[i].parent_frame, "W");
    for (int k = 0; k < 3; ++k) EXPECT_EQ(poses[i].position[k], e[i]["p"][k].get<double>());
    for (int k = 0; k < 4; ++k) EXPECT_EQ(poses[i].orientation[k], e[i]["q"][k].get<double>());
  }
}

void expectClouds(const std::vector<point_cloud_t>& clouds, const json& e) {
  ASSERT_EQ(clouds.size(), e.size());
  for (size_t i = 0; i < clouds.size(); ++i) {
    SCOPED_TRACE("cloud " + std::to_string(i));
    const point_cloud_t& c = clouds[i];
    EXPECT_EQ(c.utime, utimeOf(e[i]));
    EXPECT_EQ(c.num_rings, 4);
    EXPECT_EQ(c.pattern, int8_t{point_cloud_t::PATTERN_SPINNING});
    const json& pts = e[i]["points"];
    ASSERT_EQ(c.num_points, static_cast<int>(pts.size()));
    for (int j = 0; j < c.num_points; ++j) {
      EXPECT_EQ(c.x[j], pts[j][0].get<float>()) << "point " << j;
      EXPECT_EQ(c.y[j], pts[j][1].get<float>()) << "point " << j;
      EXPECT_EQ(c.z[j], pts[j][2].get<float>()) << "point " << j;
      EXPECT_EQ(c.intensity[j], pts[j][3].get<float>()) << "point " << j;
      EXPECT_EQ(c.ring[j], pts[j][4].get<int>()) << "point " << j;
      EXPECT_EQ(c.time_offset[j], pts[j][5].get<float>()) << "point " << j;
    }
  }
}

void expectImages(const std::vector<image_t>& images, const std::vector<image_t>& compressed, const json& e) {
  ASSERT_EQ(images.size(), e["image"].size());
  for (size_t i = 0; i < images.size(); ++i) {
    const json& x = e["image"][i];
    EXPECT_EQ(images[i].utime, utimeOf(x));
    EXPECT_EQ(images[i].encoding, int8_t{image_t::ENCODING_GRAY8});
    EXPECT_EQ(images[i].width, x["width"].get<int>());
    EXPECT_EQ(images[i].height, x["height"].get<int>());
    EXPECT_EQ(images[i].row_stride, x["step"].get<int>());
    EXPECT_EQ(images[i].data, x["data"].get<std::vector<uint8_t>>());
  }
  ASSERT_EQ(compressed.size(), e["compressed"].size());
  EXPECT_EQ(compressed[0].utime, utimeOf(e["compressed"][0]));
  EXPECT_EQ(compressed[0].encoding, int8_t{image_t::ENCODING_JPEG});
  EXPECT_EQ(compressed[0].size, e["compressed"][0]["size"].get<int>());
  EXPECT_EQ(compressed[0].frame, "C1");
}

class Rosbag2Storages : public ::testing::TestWithParam<std::string> {};

TEST_P(Rosbag2Storages, EveryTypeMatchesWhatTheForeignWriterWrote) {
  const std::string input = GetParam();
  const json exp = expected();
  const std::string dir = test::freshTempDir("rosbag2_" + input.substr(0, input.find('.')));
  ImportJob job = rosbag2Job(input, dir + "/out.lcmlog");
  const ImportOutcome r = runImport(job, nullptr);
  EXPECT_TRUE(r.ok()) << (r.report.errors().empty() ? "" : r.report.errors()[0]);
  const auto events = test::readLog(job.out);
  EXPECT_TRUE(test::inTimeOrder(events));
  expectImu(test::messagesOn<imu_t>(events, "IMU"), exp["imu"]);
  expectClouds(test::messagesOn<point_cloud_t>(events, "LIDAR"), exp["points"]);
  expectImages(test::messagesOn<image_t>(events, "CAMERA"), test::messagesOn<image_t>(events, "CAMERA_RIGHT"), exp);
  expectPoses(test::messagesOn<pose_t>(events, "GROUND_TRUTH"), exp["odom"]);

  // CameraInfo (found in the camera's namespace) -> the report's calibration.
  ASSERT_TRUE(r.report.calibration().camera.has_value());
  const CameraIntrinsics& k = *r.report.calibration().camera;
  const json& ci = exp["camera_info"];
  EXPECT_EQ(k.width, ci["width"].get<int>());
  EXPECT_EQ(k.height, ci["height"].get<int>());
  EXPECT_EQ(k.fx, ci["K"][0].get<double>());
  EXPECT_EQ(k.cx, ci["K"][2].get<double>());
  EXPECT_EQ(k.fy, ci["K"][4].get<double>());
  EXPECT_EQ(k.cy, ci["K"][5].get<double>());
  for (int i = 0; i < 4; ++i) EXPECT_EQ(k.distortion[i], ci["D"][i].get<double>());

  // The cut IMU message is skipped with its topic, place and field; the rest of the bag is read.
  const std::string cut = skipWhere(r.report, "undecodable sensor_msgs/msg/Imu on /imu: field 'angular_velocity.");
  EXPECT_NE(cut.find(job.input), std::string::npos) << cut;
  EXPECT_NE(cut.find(input.find("db3") != std::string::npos ? "messages row id 4 (topic /imu)" : "(topic /imu)"),
            std::string::npos)
      << cut;
  EXPECT_NE(cut.find("truncated?"), std::string::npos) << cut;
  EXPECT_EQ(r.report.skipped().at("topic not mapped: /chatter (std_msgs/msg/String)").count, 1);
  EXPECT_EQ(r.report.metadataValue("topic_imu"), "\"/imu\"");
  if (input.find("chunked_") == 0) {
    const std::string chunks = r.report.metadataValue("bag_chunks");
    EXPECT_NE(chunks.find(input.substr(8, input.find('.') - 8) + ": "), std::string::npos) << chunks;
  }
}

INSTANTIATE_TEST_SUITE_P(Files, Rosbag2Storages,
                         ::testing::Values("unchunked.mcap", "unchunked_nosummary.mcap", "chunked_none.mcap",
                                           "chunked_zstd.mcap", "chunked_lz4.mcap", "bag_mcap", "bag_split", "bag_zstd_file",
                                           "bag_zstd_message", "bag_db3",
                                           "single.db3"),
                         [](const auto& info) {
                           std::string n = info.param;
                           for (char& c : n)
                             if (c == '.') c = '_';
                           return n;
                         });

TEST(Rosbag2Import, BigEndianCdrReadsTheSameValues) {
  const json exp = expected();
  for (const std::string input : {"chunked_zstd.mcap", "single.db3"}) {
    SCOPED_TRACE(input);
    const std::string dir = test::freshTempDir("rosbag2_be");
    ImportJob job = rosbag2Job(input, dir + "/be.lcmlog");
    job.rosbag.imu_topic = "/imu_be";
    const ImportOutcome r = runImport(job, nullptr);
    EXPECT_TRUE(r.ok());
    expectImu(test::messagesOn<imu_t>(test::readLog(job.out), "IMU"), exp["imu_be"]);
  }
}

TEST(Rosbag2Import, Ros1SerialisationInMcapReadsTheSameValues) {
  const std::string dir = test::freshTempDir("rosbag2_ros1_encoded");
  ImportJob job = rosbag2Job("ros1_encoded.mcap", dir + "/ros1.lcmlog");
  const ImportOutcome r = runImport(job, nullptr);
  EXPECT_TRUE(r.ok());
  EXPECT_TRUE(r.report.skipped().empty());
  expectImu(test::messagesOn<imu_t>(test::readLog(job.out), "IMU"), expected()["imu"]);
}

TEST(Rosbag2Import, PoseStampedAndTransformStampedGroundTruth) {
  const json exp = expected();
  for (const auto& [topic, key] : {std::pair{"/pose", "pose"}, {"/tf_gt", "tf"}}) {
    SCOPED_TRACE(topic);
    const std::string dir = test::freshTempDir("rosbag2_gt");
    ImportJob job = rosbag2Job("bag_db3", dir + "/gt.lcmlog");
    job.rosbag.ground_truth_topic = topic;
    const ImportOutcome r = runImport(job, nullptr);
    EXPECT_TRUE(r.ok());
    expectPoses(test::messagesOn<pose_t>(test::readLog(job.out), "GROUND_TRUTH"), exp[key]);
  }
}

TEST(Rosbag2Import, TfMessageGroundTruthIsOneChildFramesTransforms) {
  const json exp = expected();
  for (const std::string input : {"chunked_zstd.mcap", "single.db3"}) {
    for (const std::string frame : {"base_link", ""}) {
      SCOPED_TRACE(input + " frame '" + frame + "'");
      const std::string dir = test::freshTempDir("rosbag2_tf");
      ImportJob job = rosbag2Job(input, dir + "/tf.lcmlog");
      job.rosbag.ground_truth_topic = "/tf";
      job.rosbag.ground_truth_tf_frame = frame;
      const ImportOutcome r = runImport(job, nullptr);
      EXPECT_TRUE(r.ok());
      // Without --ground-truth-frame: the first child frame on /tf (odom), said in a note.
      const std::string taken = frame.empty() ? "odom" : frame;
      expectPoses(test::messagesOn<pose_t>(test::readLog(job.out), "GROUND_TRUTH"), exp["tf_" + taken]);
      EXPECT_EQ(r.report.skipped().at("transforms on /tf to another frame than " + taken + " (--ground-truth-frame)").count,
                3);
      EXPECT_EQ(r.report.metadataValue("ground_truth_tf_frame"), "\"" + taken + "\"");
      bool noted = false;
      for (const std::string& n : r.report.notes()) noted |= n.find("--ground-truth-frame not given") != std::string::npos;
      EXPECT_EQ(noted, frame.empty());
    }
  }
}

TEST(Rosbag2Import, TopicsFromMetadataSummaryOrScanAgree) {
  for (const std::string input : {"bag_mcap", "chunked_lz4.mcap", "unchunked_nosummary.mcap", "single.db3"}) {
    SCOPED_TRACE(input);
    std::map<std::string, std::pair<std::string, int64_t>> topics;
    for (const BagTopic& t : listRosbag2Topics(kFixtures + "/" + input)) topics[t.topic] = {t.type, t.messages};
    EXPECT_EQ(topics.size(), 11u);
    EXPECT_EQ(topics["/imu"], (std::pair<std::string, int64_t>{"sensor_msgs/msg/Imu", 6}));
    EXPECT_EQ(topics["/points"], (std::pair<std::string, int64_t>{"sensor_msgs/msg/PointCloud2", 2}));
    EXPECT_EQ(topics["/tf_gt"], (std::pair<std::string, int64_t>{"geometry_msgs/msg/TransformStamped", 3}));
  }
}

TEST(Rosbag2Import, AutoMapsTheOnlyTopicOfATypeAndNotAmbiguousOnes) {
  const std::string dir = test::freshTempDir("rosbag2_auto");
  ImportJob job;
  job.format = "rosbag2";
  job.input = kFixtures + "/bag_mcap";
  job.out = dir + "/auto.lcmlog";
  job.quiet = true;
  const ImportOutcome r = runImport(job, nullptr);
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(r.report.metadataValue("topic_lidar"), "\"/points\"");
  EXPECT_EQ(r.report.metadataValue("topic_camera"), "");  // /camera/image_raw and /cam1/compressed both fit
  EXPECT_EQ(r.report.metadataValue("topic_imu"), "");     // /imu and /imu_be
  EXPECT_EQ(r.channel_counts.at("LIDAR"), 2);
}

TEST(Rosbag2Import, TruncatedMcapKeepsWhatCameBeforeTheCut) {
  const std::string dir = test::freshTempDir("rosbag2_truncated");
  ImportJob job = rosbag2Job("truncated.mcap", dir + "/cut.lcmlog");
  const ImportOutcome r = runImport(job, nullptr);
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(r.wrote_log);
  ASSERT_EQ(r.report.errors().size(), 1u);
  const std::string& e = r.report.errors()[0];
  EXPECT_NE(e.find(job.input + ": record at offset "), std::string::npos) << e;
  EXPECT_NE(e.find("truncated"), std::string::npos) << e;
  EXPECT_GT(r.channel_counts.at("IMU"), 0) << "messages before the cut are kept";
  const ImportOutcome whole = runImport(rosbag2Job("chunked_lz4.mcap", dir + "/whole.lcmlog"), nullptr);
  int64_t cut_total = 0, whole_total = 0;
  for (const auto& [channel, n] : r.channel_counts) cut_total += n;
  for (const auto& [channel, n] : whole.channel_counts) whole_total += n;
  EXPECT_LT(cut_total, whole_total) << "the file it was cut from has more";
  EXPECT_EQ(test::readLog(job.out).size(), static_cast<size_t>(cut_total));
}

TEST(Rosbag2Import, SqliteRowOfAnUnknownTopicStopsWithItsRowId) {
  const std::string dir = test::freshTempDir("rosbag2_bad_topic");
  ImportJob job = rosbag2Job("bad_topic.db3", dir + "/bad.lcmlog");
  const ImportOutcome r = runImport(job, nullptr);
  EXPECT_FALSE(r.ok());
  ASSERT_EQ(r.report.errors().size(), 1u);
  EXPECT_NE(r.report.errors()[0].find("bad_topic.db3: messages row id 3 refers to topic id 99"), std::string::npos)
      << r.report.errors()[0];
  EXPECT_EQ(r.channel_counts.at("IMU"), 2) << "the rows before it are kept";
}

TEST(Rosbag2Import, NotARosbag2IsAClearError) {
  const std::string dir = test::freshTempDir("rosbag2_notabag");
  for (const auto& [input, message] :
       {std::pair{kFixtures + "/expected.json", "expected.json: neither a .mcap nor a .db3 file"},
        {dir, "a directory without metadata.yaml"},
        {kFixtures + "/rows.json.mcap", "rows.json.mcap: no such file or directory"}}) {
    ImportJob job = rosbag2Job("", dir + "/x.lcmlog");
    job.input = input;
    const ImportOutcome r = runImport(job, nullptr);
    ASSERT_EQ(r.report.errors().size(), 1u) << input;
    EXPECT_NE(r.report.errors()[0].find(message), std::string::npos) << r.report.errors()[0];
  }
}

TEST(Rosbag2Import, PresetsApplyToRosbag2) {
  ImportJob job;
  job.format = "rosbag2";
  job.preset = "ntu_viral";
  applyPreset(job);
  EXPECT_FALSE(job.rosbag.imu_topic.empty());
  EXPECT_EQ(job.rosbag.lidar.stamp, LidarStampConvention::kEnd);
}

}  // namespace
}  // namespace livo::import

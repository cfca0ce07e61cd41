#include "livo/import/rosbag_presets.hpp"

namespace livo::import {

const std::vector<RosbagPreset>& rosbagPresets() {
  static const std::vector<RosbagPreset> presets = [] {
    std::vector<RosbagPreset> v;

    // NTU VIRAL (ntu-aris): VN100 IMU, two Ouster OS1-16 (horizontal node1, vertical node2), two
    // uEye mono cameras, Leica MS60 tracking a prism. The OS1 clouds are stamped at the end of the
    // sweep with `t` counted from its start; the ground truth is the prism's position only.
    RosbagPreset ntu;
    ntu.name = "ntu_viral";
    ntu.description =
        "NTU VIRAL: /imu/imu, /os1_cloud_node1/points (end-of-sweep stamps), /left|right/image_raw, "
        "/leica/pose/relative (prism position)";
    ntu.imu_topic = "/imu/imu";
    ntu.lidar_topic = "/os1_cloud_node1/points";
    ntu.camera_topic = "/left/image_raw";
    ntu.camera_right_topic = "/right/image_raw";
    ntu.ground_truth_topic = "/leica/pose/relative";
    ntu.ground_truth_child_frame = "prism";
    ntu.lidar_stamp = LidarStampConvention::kEnd;
    ntu.sweep_duration = 0.1;
    ntu.num_rings = 16;
    ntu.metadata = {
        {"ground_truth_point", "\"Leica prism position in W (geometry_msgs/PointStamped): no orientation\""},
        {"prism_offset_body", "[-0.293656, -0.012288, -0.273095]"},
        {"prism_offset_note",
         "\"p_W_prism = p_W_I + R_W_I * prism_offset_body; pass it to livo-evaluate --gt-offset\""},
        {"lidar_stamp", "\"end of sweep in the bag; converted to start (stamp - 0.1 s)\""},
        {"extrinsic_body_lidar_horizontal", "{translation: [-0.05, 0.0, 0.055], rotation: [1.0, 0.0, 0.0, 0.0]}"},
        {"frames_note", "\"the IMU and horizontal LiDAR z axes point down (dataset calibration)\""},
    };
    ntu.calibrated_rig = "config/rigs/ntu_viral.yaml";
    ntu.T_I_L = "{translation: [-0.05, 0.0, 0.055], rpy_deg: [0, 0, 0]}";
    ntu.T_I_C =
        "[0.02183084, -0.01312053, 0.99967558, 0.00552943, 0.99975965, 0.00230088, -0.02180248, -0.12431302, "
        "-0.00201407, 0.99991127, 0.01316761, 0.01614686, 0.0, 0.0, 0.0, 1.0]";
    ntu.extrinsics_source = "NTU VIRAL's lidar_horz.yaml / camera_left.yaml T_Body_* (config/rigs/ntu_viral.yaml)";
    v.push_back(ntu);

    // M2DGR (SJTU): Velodyne VLP-32C, Handsfree 9-axis IMU, RealSense colour camera (compressed);
    // ground truth comes as separate TUM files (pass with --ground-truth FILE).
    RosbagPreset m2dgr;
    m2dgr.name = "m2dgr";
    m2dgr.description =
        "M2DGR: /handsfree/imu, /velodyne_points (VLP-32C), /camera/color/image_raw/compressed; "
        "ground truth from the sequence's TUM file";
    m2dgr.imu_topic = "/handsfree/imu";
    m2dgr.lidar_topic = "/velodyne_points";
    m2dgr.camera_topic = "/camera/color/image_raw/compressed";
    m2dgr.lidar_stamp = LidarStampConvention::kStart;
    m2dgr.sweep_duration = 0.1;
    m2dgr.num_rings = 32;
    m2dgr.metadata = {
        {"lidar_model", "\"Velodyne VLP-32C, 10 Hz\""},
        {"ground_truth_note", "\"M2DGR ships ground truth as TUM text files: --ground-truth SEQUENCE.txt\""},
    };
    m2dgr.calibrated_rig = "config/rigs/m2dgr.yaml";
    m2dgr.T_I_L = "{translation: [0.27255, -0.00053, 0.17954], rpy_deg: [0, 0, 0]}";
    m2dgr.T_I_C = "[0.0, 0.0, 1.0, 0.57711, -1.0, 0.0, 0.0, 0.00012, 0.0, -1.0, 0.0, 0.83330, 0.0, 0.0, 0.0, 1.0]";
    m2dgr.extrinsics_source = "M2DGR's calibration_results.txt (config/rigs/m2dgr.yaml)";
    v.push_back(m2dgr);
    return v;
  }();
  return presets;
}

const RosbagPreset* findRosbagPreset(const std::string& name) {
  for (const RosbagPreset& p : rosbagPresets())
    if (p.name == name) return &p;
  return nullptr;
}

}  // namespace livo::import

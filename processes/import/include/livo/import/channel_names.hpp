// Output channels of every importer (each overridable on the command line).
#pragma once

#include <string>

namespace livo::import {

struct ChannelNames {
  std::string imu = "IMU";                    // imu_t
  std::string lidar = "LIDAR";                // point_cloud_t
  std::string camera = "CAMERA";              // image_t
  std::string camera_right = "CAMERA_RIGHT";  // image_t, second camera
  std::string depth = "DEPTH";                // image_t DEPTH16 / DEPTH32F, registered to the camera
  std::string ground_truth = "GROUND_TRUTH";  // pose_t, parent "W"
};

}  // namespace livo::import

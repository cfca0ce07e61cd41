// Decompression of ROS bag chunks: "none", "bz2" (libbz2) and "lz4" (ROS writes LZ4 frames, read
// with liblz4's frame API); and of MCAP chunks ("zstd" too). A damaged or truncated chunk yields what could be decompressed.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace livo::import {

struct DecompressedChunk {
  std::vector<uint8_t> data;
  bool complete = false;  // false: `error` says why, `data` holds what came out before
  std::string error;
};

/// `expected_size` is the chunk record's uncompressed size.
DecompressedChunk decompressChunk(const std::string& compression, const uint8_t* in, size_t size, size_t expected_size);
/// A zstd frame (MCAP chunks) of `expected_size` bytes uncompressed (libzstd's streaming API, so a
/// cut frame yields what came out before the cut).
DecompressedChunk decompressZstd(const uint8_t* in, size_t size, size_t expected_size);
/// A zstd frame of unknown uncompressed size (rosbag2's per-message compression); `error` says why
/// when it is not complete.
DecompressedChunk decompressZstdFrame(const uint8_t* in, size_t size);
/// A zstd-compressed file (rosbag2's per-file compression) into `out_path`; "" or the reason it failed.
std::string decompressZstdFile(const std::string& in_path, const std::string& out_path);

}  // namespace livo::import

// Data moved out of memory: an append-only scratch file of records, and keyframe clouds kept
// compactly in one (livo-loop, livo-octomap; livo-colour spills its map tiles to a SpillFile).
//
// The file is created in a directory (default: $TMPDIR or /tmp) and unlinked at once, so it
// takes disk space only while the process runs and nothing is left behind, even after a crash.
// Only the index of records stays in memory.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace livo {

class SpillFile {
 public:
  struct Record {
    uint64_t offset = 0;
    uint64_t bytes = 0;
  };
  /// Throws std::runtime_error if no file can be made in `directory` ("" : the temp directory).
  explicit SpillFile(const std::string& directory = "");
  ~SpillFile();
  SpillFile(const SpillFile&) = delete;
  SpillFile& operator=(const SpillFile&) = delete;
  /// Moved: the file goes with it (a map started anew takes a fresh store this way).
  SpillFile(SpillFile&& other) noexcept;
  SpillFile& operator=(SpillFile&& other) noexcept;

  /// Appends bytes; throws std::runtime_error on a write error (disk full).
  Record append(const void* data, size_t bytes);
  /// Reads a record back into out (resized); throws std::runtime_error on a read error.
  void read(const Record& record, std::vector<uint8_t>* out) const;
  /// Gives a record no longer needed back to the file system: a hole is punched over the whole
  /// blocks it covers (its offsets are not reused, so other records stay where they are). Where
  /// the file system cannot punch holes the space stays in use (liveBytes() still drops).
  void release(const Record& record);
  /// Bytes written so far (the file's length, holes included).
  uint64_t size() const { return end_; }
  /// Bytes of the records not released: about what the file takes on disk.
  uint64_t liveBytes() const { return live_; }
  /// Bytes the file system has allocated to the file (fstat's blocks).
  uint64_t allocatedBytes() const;

 private:
  int fd_ = -1;
  uint64_t end_ = 0;
  uint64_t live_ = 0;
};

/// Keyframe clouds (body frame, float) by id, on disk. step > 0: each coordinate quantised to
/// int16 in units of `step` (6 bytes a point, error <= step / 2 per axis); a cloud with a
/// coordinate beyond 32767 steps is kept as float. step 0: float, exactly as given (12 bytes).
class KeyframeCloudStore {
 public:
  explicit KeyframeCloudStore(double step, const std::string& directory = "");

  /// Stores the cloud of `id` (a later put with the same id replaces it).
  void put(int64_t id, const std::vector<Eigen::Vector3f>& points);
  /// The cloud as stored (quantised: the centres of the steps); empty for an unknown id.
  std::vector<Eigen::Vector3f> get(int64_t id) const;
  bool contains(int64_t id) const { return index_.count(id) > 0; }
  size_t size() const { return index_.size(); }
  double step() const { return step_; }
  uint64_t diskBytes() const { return file_.liveBytes(); }

 private:
  struct Entry {
    SpillFile::Record record;
    uint32_t points = 0;
    bool quantised = false;
  };
  double step_;
  SpillFile file_;
  std::map<int64_t, Entry> index_;
};

}  // namespace livo

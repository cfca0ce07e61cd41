#include "livo/spill_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace livo {

SpillFile::SpillFile(const std::string& directory) {
  std::string dir = directory;
  if (dir.empty()) {
    std::error_code ec;
    dir = std::filesystem::temp_directory_path(ec).string();
    if (ec) dir = "/tmp";
  }
  std::string pattern = dir + "/livo-spill-XXXXXX";
  std::vector<char> name(pattern.begin(), pattern.end());
  name.push_back('\0');
  fd_ = ::mkstemp(name.data());
  if (fd_ < 0) throw std::runtime_error("cannot create a spill file in " + dir + ": " + std::strerror(errno));
  ::unlink(name.data());  // gone when the process ends
}

SpillFile::~SpillFile() {
  if (fd_ >= 0) ::close(fd_);
}

SpillFile::SpillFile(SpillFile&& other) noexcept : fd_(other.fd_), end_(other.end_), live_(other.live_) {
  other.fd_ = -1;
  other.end_ = 0;
  other.live_ = 0;
}

SpillFile& SpillFile::operator=(SpillFile&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = other.fd_;
    end_ = other.end_;
    live_ = other.live_;
    other.fd_ = -1;
    other.end_ = 0;
    other.live_ = 0;
  }
  return *this;
}

SpillFile::Record SpillFile::append(const void* data, size_t bytes) {
  Record r{end_, bytes};
  const char* p = static_cast<const char*>(data);
  size_t done = 0;
  while (done < bytes) {
    const ssize_t n = ::pwrite(fd_, p + done, bytes - done, static_cast<off_t>(end_ + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw std::runtime_error(std::string("spill file write failed: ") + std::strerror(errno));
    done += static_cast<size_t>(n);
  }
  end_ += bytes;
  live_ += bytes;
  return r;
}

uint64_t SpillFile::allocatedBytes() const {
  struct stat st {};
  if (fd_ < 0 || ::fstat(fd_, &st) != 0) return 0;
  return static_cast<uint64_t>(st.st_blocks) * 512u;
}

void SpillFile::release(const Record& record) {
  if (record.bytes == 0 || fd_ < 0) return;
  live_ -= std::min(live_, record.bytes);
  // only the blocks wholly inside the record: a block it shares with a neighbour stays
  constexpr uint64_t kBlock = 4096;
  const uint64_t from = (record.offset + kBlock - 1) / kBlock * kBlock;
  const uint64_t to = (record.offset + record.bytes) / kBlock * kBlock;
  if (to > from)
    (void)::fallocate(fd_, FALLOC_FL_PUNCH_HOLE | FALLOC_FL_KEEP_SIZE, static_cast<off_t>(from),
                      static_cast<off_t>(to - from));  // best effort (EOPNOTSUPP: the space stays used)
}

void SpillFile::read(const Record& record, std::vector<uint8_t>* out) const {
  out->resize(record.bytes);
  size_t done = 0;
  while (done < record.bytes) {
    const ssize_t n = ::pread(fd_, out->data() + done, record.bytes - done, static_cast<off_t>(record.offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw std::runtime_error(std::string("spill file read failed: ") + std::strerror(errno));
    done += static_cast<size_t>(n);
  }
}

KeyframeCloudStore::KeyframeCloudStore(double step, const std::string& directory)
    : step_(step > 0 ? step : 0.0), file_(directory) {}

void KeyframeCloudStore::put(int64_t id, const std::vector<Eigen::Vector3f>& points) {
  Entry e;
  e.points = static_cast<uint32_t>(points.size());
  e.quantised = step_ > 0;
  if (e.quantised) {
    const double inv = 1.0 / step_;
    std::vector<int16_t> q;
    q.reserve(3 * points.size());
    for (const Eigen::Vector3f& p : points) {
      for (int k = 0; k < 3; ++k) {
        const double v = std::round(double(p[k]) * inv);
        if (!(std::abs(v) <= 32767.0)) {  // out of range or not finite: keep this cloud as float
          e.quantised = false;
          break;
        }
        q.push_back(static_cast<int16_t>(v));
      }
      if (!e.quantised) break;
    }
    if (e.quantised) e.record = file_.append(q.data(), q.size() * sizeof(int16_t));
  }
  if (!e.quantised) e.record = file_.append(points.data(), points.size() * sizeof(Eigen::Vector3f));
  if (const auto it = index_.find(id); it != index_.end()) file_.release(it->second.record);
  index_[id] = e;
}

std::vector<Eigen::Vector3f> KeyframeCloudStore::get(int64_t id) const {
  std::vector<Eigen::Vector3f> out;
  auto it = index_.find(id);
  if (it == index_.end()) return out;
  const Entry& e = it->second;
  std::vector<uint8_t> bytes;
  file_.read(e.record, &bytes);
  out.resize(e.points);
  if (!e.quantised) {
    // Vector3f is three packed floats (no padding): the bytes are the array as written
    static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float), "packed points");
    std::memcpy(static_cast<void*>(out.data()), bytes.data(), bytes.size());
    return out;
  }
  const auto* q = reinterpret_cast<const int16_t*>(bytes.data());
  const float step = static_cast<float>(step_);
  for (uint32_t i = 0; i < e.points; ++i) out[i] = Eigen::Vector3f(q[3 * i], q[3 * i + 1], q[3 * i + 2]) * step;
  return out;
}

}  // namespace livo

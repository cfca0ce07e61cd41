// Classic libpcap capture files (magic a1b2c3d4 with microsecond or a1b23c4d with nanosecond
// stamps, either byte order) read without libpcap, down to UDP datagrams: Ethernet (with 802.1Q
// tags), Linux cooked (SLL) and raw-IP link layers, IPv4 with fragment reassembly (Ouster LiDAR
// packets are larger than the Ethernet MTU and arrive as several fragments).
#pragma once

#include <cstdint>
#include <cstdio>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace livo::import {

class PcapError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct UdpDatagram {
  int64_t capture_time_ns = 0;  // capture stamp of the last fragment
  uint32_t src_ip = 0, dst_ip = 0;
  uint16_t src_port = 0, dst_port = 0;
  std::vector<uint8_t> payload;
  int64_t record_number = 0;  // 1-based pcap record of the last fragment
};

struct PcapStats {
  int64_t records = 0;
  int64_t non_ipv4 = 0;              // frames that are not IPv4 (ARP, IPv6, ...)
  int64_t non_udp = 0;               // IPv4 but not UDP
  int64_t fragments = 0;             // IPv4 fragments seen
  int64_t incomplete_datagrams = 0;  // fragment sets never completed
  int64_t truncated_records = 0;     // captured shorter than on the wire (snaplen)
};

class PcapReader {
 public:
  /// Throws PcapError naming the file if it is not a pcap file.
  explicit PcapReader(std::string path);
  ~PcapReader();
  PcapReader(const PcapReader&) = delete;
  PcapReader& operator=(const PcapReader&) = delete;

  /// Calls `fn` for every complete UDP datagram in capture order. Throws PcapError naming the
  /// file and record at a truncated record, after every datagram before it was delivered.
  void readAll(const std::function<void(const UdpDatagram&)>& fn);

  const PcapStats& stats() const { return stats_; }
  uint64_t fileSize() const { return file_size_; }
  uint64_t position() const { return position_; }
  uint32_t linkType() const { return link_type_; }

 private:
  struct Fragments {
    std::map<uint32_t, std::vector<uint8_t>> parts;  // offset -> bytes
    uint32_t total = 0;                              // known once the last fragment arrived
    int64_t first_record = 0;
  };
  void handleFrame(const uint8_t* data, size_t size, int64_t time_ns,
                   const std::function<void(const UdpDatagram&)>& fn);
  void handleIpv4(const uint8_t* data, size_t size, int64_t time_ns, const std::function<void(const UdpDatagram&)>& fn);
  void deliverUdp(uint32_t src, uint32_t dst, const uint8_t* data, size_t size, int64_t time_ns,
                  const std::function<void(const UdpDatagram&)>& fn);

  std::string path_;
  std::FILE* file_ = nullptr;
  uint64_t file_size_ = 0, position_ = 0;
  bool swapped_ = false, nanoseconds_ = false;
  uint32_t link_type_ = 0;
  int64_t record_ = 0;
  PcapStats stats_;
  std::map<uint64_t, Fragments> pending_;  // (src, id, dst low bits) -> fragments
};

}  // namespace livo::import

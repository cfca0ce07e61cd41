#include "livo/import/pcap_reader.hpp"

#include <cstring>

namespace livo::import {

namespace {
uint16_t be16(const uint8_t* p) { return static_cast<uint16_t>((p[0] << 8) | p[1]); }
uint32_t be32(const uint8_t* p) {
  return (uint32_t(p[0]) << 24) | (uint32_t(p[1]) << 16) | (uint32_t(p[2]) << 8) | p[3];
}
uint32_t swap32(uint32_t v) { return __builtin_bswap32(v); }
constexpr size_t kMaxPendingDatagrams = 256;  // bound on half-reassembled datagrams kept
constexpr uint32_t kLinkEthernet = 1, kLinkRaw = 101, kLinkIpv4 = 228, kLinkSll = 113, kLinkLoop = 0;
}  // namespace

PcapReader::PcapReader(std::string path) : path_(std::move(path)) {
  file_ = std::fopen(path_.c_str(), "rb");
  if (!file_) throw PcapError(path_ + ": cannot open");
  std::fseek(file_, 0, SEEK_END);
  file_size_ = static_cast<uint64_t>(std::ftell(file_));
  std::fseek(file_, 0, SEEK_SET);
  uint8_t h[24];
  if (std::fread(h, 1, 24, file_) != 24) {
    std::fclose(file_);
    file_ = nullptr;
    throw PcapError(path_ + ": too short for a pcap header");
  }
  uint32_t magic;
  std::memcpy(&magic, h, 4);
  if (magic == 0xa1b2c3d4 || magic == 0xa1b23c4d) {
    swapped_ = false;
  } else if (magic == 0xd4c3b2a1 || magic == 0x4d3cb2a1) {
    swapped_ = true;
    magic = swap32(magic);
  } else {
    std::fclose(file_);
    file_ = nullptr;
    throw PcapError(path_ + ": not a classic pcap file (magic " + std::to_string(magic) +
                    "; pcapng is not supported: convert with editcap -F pcap)");
  }
  nanoseconds_ = magic == 0xa1b23c4d;
  std::memcpy(&link_type_, h + 20, 4);
  if (swapped_) link_type_ = swap32(link_type_);
  link_type_ &= 0x0fffffff;
  position_ = 24;
}

PcapReader::~PcapReader() {
  if (file_) std::fclose(file_);
}

void PcapReader::readAll(const std::function<void(const UdpDatagram&)>& fn) {
  std::vector<uint8_t> frame;
  while (true) {
    uint32_t rh[4];
    const size_t got = std::fread(rh, 1, 16, file_);
    if (got == 0) break;
    ++record_;
    const std::string where = path_ + ": record " + std::to_string(record_) + " at offset " + std::to_string(position_);
    if (got != 16) throw PcapError(where + ": file ends inside the record header (truncated)");
    if (swapped_)
      for (uint32_t& v : rh) v = swap32(v);
    const uint32_t incl = rh[2], orig = rh[3];
    if (incl > (256u << 10))
      throw PcapError(where + ": field 'incl_len' " + std::to_string(incl) + " is implausible (corrupt)");
    frame.resize(incl);
    const size_t body = std::fread(frame.data(), 1, incl, file_);
    position_ += 16 + body;
    if (body != incl)
      throw PcapError(where + ": packet data needs " + std::to_string(incl) + " bytes, the file ends after " +
                      std::to_string(body) + " (truncated)");
    ++stats_.records;
    if (incl < orig) ++stats_.truncated_records;
    const int64_t t =
        static_cast<int64_t>(rh[0]) * 1000000000LL + static_cast<int64_t>(rh[1]) * (nanoseconds_ ? 1 : 1000);
    handleFrame(frame.data(), frame.size(), t, fn);
  }
  stats_.incomplete_datagrams += static_cast<int64_t>(pending_.size());
  pending_.clear();
}

void PcapReader::handleFrame(const uint8_t* d, size_t n, int64_t t, const std::function<void(const UdpDatagram&)>& fn) {
  size_t off = 0;
  uint16_t proto = 0;
  if (link_type_ == kLinkEthernet) {
    if (n < 14) return void(++stats_.non_ipv4);
    proto = be16(d + 12);
    off = 14;
    while ((proto == 0x8100 || proto == 0x88a8) && n >= off + 4) {
      proto = be16(d + off + 2);
      off += 4;
    }
  } else if (link_type_ == kLinkSll) {
    if (n < 16) return void(++stats_.non_ipv4);
    proto = be16(d + 14);
    off = 16;
  } else if (link_type_ == kLinkRaw || link_type_ == kLinkIpv4) {
    proto = (n > 0 && (d[0] >> 4) == 4) ? 0x0800 : 0;
  } else if (link_type_ == kLinkLoop) {
    if (n < 4) return void(++stats_.non_ipv4);
    uint32_t family;
    std::memcpy(&family, d, 4);
    proto = (family == 2 || swap32(family) == 2) ? 0x0800 : 0;
    off = 4;
  } else {
    throw PcapError(path_ + ": link type " + std::to_string(link_type_) + " is not supported (Ethernet, SLL, raw IP)");
  }
  if (proto != 0x0800) return void(++stats_.non_ipv4);
  handleIpv4(d + off, n - off, t, fn);
}

void PcapReader::handleIpv4(const uint8_t* d, size_t n, int64_t t, const std::function<void(const UdpDatagram&)>& fn) {
  if (n < 20 || (d[0] >> 4) != 4) return void(++stats_.non_ipv4);
  const size_t ihl = static_cast<size_t>(d[0] & 0x0f) * 4;
  const size_t total = be16(d + 2);
  if (ihl < 20 || total < ihl || total > n) return void(++stats_.non_ipv4);  // cut by snaplen
  if (d[9] != 17) return void(++stats_.non_udp);
  const uint16_t id = be16(d + 4);
  const uint16_t flags_frag = be16(d + 6);
  const bool more = flags_frag & 0x2000;
  const uint32_t frag_off = static_cast<uint32_t>(flags_frag & 0x1fff) * 8;
  const uint32_t src = be32(d + 12), dst = be32(d + 16);
  const uint8_t* payload = d + ihl;
  const size_t len = total - ihl;
  if (!more && frag_off == 0) return deliverUdp(src, dst, payload, len, t, fn);

  ++stats_.fragments;
  const uint64_t key = (uint64_t(src) << 32) ^ (uint64_t(dst) << 16) ^ id;
  Fragments& f = pending_[key];
  if (f.parts.empty()) f.first_record = record_;
  f.parts[frag_off].assign(payload, payload + len);
  if (!more) f.total = frag_off + static_cast<uint32_t>(len);
  if (f.total) {
    uint32_t covered = 0;
    for (const auto& [o, bytes] : f.parts) {
      if (o > covered) break;
      covered = std::max<uint32_t>(covered, o + static_cast<uint32_t>(bytes.size()));
    }
    if (covered >= f.total) {
      std::vector<uint8_t> whole(f.total);
      for (const auto& [o, bytes] : f.parts)
        std::memcpy(whole.data() + o, bytes.data(), std::min<size_t>(bytes.size(), f.total - o));
      pending_.erase(key);
      return deliverUdp(src, dst, whole.data(), whole.size(), t, fn);
    }
  }
  if (pending_.size() > kMaxPendingDatagrams) {  // drop the oldest half-assembled datagram
    auto oldest = pending_.begin();
    for (auto it = pending_.begin(); it != pending_.end(); ++it)
      if (it->second.first_record < oldest->second.first_record) oldest = it;
    pending_.erase(oldest);
    ++stats_.incomplete_datagrams;
  }
}

void PcapReader::deliverUdp(uint32_t src, uint32_t dst, const uint8_t* d, size_t n, int64_t t,
                            const std::function<void(const UdpDatagram&)>& fn) {
  if (n < 8) return void(++stats_.non_udp);
  const size_t udp_len = be16(d + 4);
  if (udp_len < 8 || udp_len > n) return void(++stats_.non_udp);
  UdpDatagram u;
  u.capture_time_ns = t;
  u.src_ip = src, u.dst_ip = dst;
  u.src_port = be16(d), u.dst_port = be16(d + 2);
  u.payload.assign(d + 8, d + udp_len);
  u.record_number = record_;
  fn(u);
}

}  // namespace livo::import

#include "ros_decoding.hpp"

namespace livo::import {

int pointFieldSize(uint8_t datatype) {
  switch (datatype) {
    case 1:
    case 2: return 1;
    case 3:
    case 4: return 2;
    case 5:
    case 6:
    case 7: return 4;
    case 8: return 8;
    default: return 0;
  }
}

namespace {
template <class Reader>
RosPointCloud2 decodePointCloud2(Reader& r) {
  RosPointCloud2 m;
  m.header = detail::decodeHeader(r);
  m.height = r.u32("height");
  m.width = r.u32("width");
  const uint32_t n = r.arrayLength("fields", 13);
  m.fields.resize(n);
  for (RosPointField& f : m.fields) {
    f.name = r.string("fields[].name");
    f.offset = r.u32("fields[].offset");
    f.datatype = r.u8("fields[].datatype");
    f.count = r.u32("fields[].count");
  }
  m.is_bigendian = r.u8("is_bigendian") != 0;
  m.point_step = r.u32("point_step");
  m.row_step = r.u32("row_step");
  const uint32_t size = r.u32("data");
  m.data = r.bytes(size, "data");
  m.data_size = size;
  m.is_dense = r.u8("is_dense") != 0;
  return m;
}
}  // namespace

RosPointCloud2 decodeRosPointCloud2(ByteReader& r) { return decodePointCloud2(r); }
RosPointCloud2 decodeCdrPointCloud2(CdrReader& r) { return decodePointCloud2(r); }

}  // namespace livo::import

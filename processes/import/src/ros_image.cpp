#include "livo/import/ros_messages.hpp"

namespace livo::import {

RosImage decodeRosImage(ByteReader& r) {
  RosImage m;
  m.header = decodeRosHeader(r);
  m.height = r.u32("height");
  m.width = r.u32("width");
  m.encoding = r.string("encoding");
  m.is_bigendian = r.u8("is_bigendian") != 0;
  m.step = r.u32("step");
  const uint32_t size = r.u32("data");
  m.data = r.bytes(size, "data");
  m.data_size = size;
  return m;
}

RosCompressedImage decodeRosCompressedImage(ByteReader& r) {
  RosCompressedImage m;
  m.header = decodeRosHeader(r);
  m.format = r.string("format");
  const uint32_t size = r.u32("data");
  m.data = r.bytes(size, "data");
  m.data_size = size;
  return m;
}

}  // namespace livo::import

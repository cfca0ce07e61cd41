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

RosCameraInfo decodeRosCameraInfo(ByteReader& r) {
  RosCameraInfo m;
  m.header = decodeRosHeader(r);
  m.height = r.u32("height");
  m.width = r.u32("width");
  m.distortion_model = r.string("distortion_model");
  const uint32_t n = r.arrayLength("D", 8);
  m.D.resize(n);
  for (uint32_t i = 0; i < n; ++i) m.D[i] = r.f64("D");
  for (double& k : m.K) k = r.f64("K");
  r.skip(9 * 8, "R");
  r.skip(12 * 8, "P");
  m.binning_x = r.u32("binning_x");
  m.binning_y = r.u32("binning_y");
  m.roi_x_offset = r.u32("roi.x_offset");
  m.roi_y_offset = r.u32("roi.y_offset");
  m.roi_height = r.u32("roi.height");
  m.roi_width = r.u32("roi.width");
  r.u8("roi.do_rectify");
  return m;
}

}  // namespace livo::import

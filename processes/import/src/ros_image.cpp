#include "ros_decoding.hpp"

namespace livo::import {

namespace {

template <class Reader>
RosImage decodeImage(Reader& r) {
  RosImage m;
  m.header = detail::decodeHeader(r);
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

template <class Reader>
RosCompressedImage decodeCompressedImage(Reader& r) {
  RosCompressedImage m;
  m.header = detail::decodeHeader(r);
  m.format = r.string("format");
  const uint32_t size = r.u32("data");
  m.data = r.bytes(size, "data");
  m.data_size = size;
  return m;
}

template <class Reader>
RosCameraInfo decodeCameraInfo(Reader& r) {
  RosCameraInfo m;
  m.header = detail::decodeHeader(r);
  m.height = r.u32("height");
  m.width = r.u32("width");
  m.distortion_model = r.string("distortion_model");
  const uint32_t n = r.arrayLength("D", 8);
  m.D.resize(n);
  for (uint32_t i = 0; i < n; ++i) m.D[i] = r.f64("D");
  for (double& k : m.K) k = r.f64("K");
  r.skipF64(9, "R");
  r.skipF64(12, "P");
  m.binning_x = r.u32("binning_x");
  m.binning_y = r.u32("binning_y");
  m.roi_x_offset = r.u32("roi.x_offset");
  m.roi_y_offset = r.u32("roi.y_offset");
  m.roi_height = r.u32("roi.height");
  m.roi_width = r.u32("roi.width");
  r.u8("roi.do_rectify");
  return m;
}

}  // namespace

RosImage decodeRosImage(ByteReader& r) { return decodeImage(r); }
RosImage decodeCdrImage(CdrReader& r) { return decodeImage(r); }
RosCompressedImage decodeRosCompressedImage(ByteReader& r) { return decodeCompressedImage(r); }
RosCompressedImage decodeCdrCompressedImage(CdrReader& r) { return decodeCompressedImage(r); }
RosCameraInfo decodeRosCameraInfo(ByteReader& r) { return decodeCameraInfo(r); }
RosCameraInfo decodeCdrCameraInfo(CdrReader& r) { return decodeCameraInfo(r); }

}  // namespace livo::import

// The message decoders' shared bodies: each decoder is a template over the reader (ByteReader for
// ROS 1 serialisation, CdrReader for ROS 2's CDR), instantiated by the decodeRos* / decodeCdr*
// functions of ros_messages.hpp. Private to the import library.
#pragma once

#include "livo/import/ros_messages.hpp"

namespace livo::import::detail {

inline RosHeader decodeHeader(ByteReader& r) { return decodeRosHeader(r); }
inline RosHeader decodeHeader(CdrReader& r) { return decodeCdrHeader(r); }

}  // namespace livo::import::detail

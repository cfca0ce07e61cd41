#include "livo/camera_image.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstring>
#include <exception>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "livo/image_t.hpp"

namespace livo {

namespace {

std::string sizeText(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

std::string wrongSize(int w, int h, int width, int height) {
  return "image is " + sizeText(w, h) + ", not the camera's " + sizeText(width, height);
}

/// 8-bit pixels with 1, 3 or 4 channels (B, G, R[, A] if `bgr`, else R, G, B[, A]) in `format`.
/// `src` is copied where the result would share its pixels and `src` is not `owned`.
bool toFormat(const cv::Mat& src, bool bgr, bool owned, PixelFormat format, cv::Mat* out, std::string* why) {
  const int c = src.channels();
  if (c != 1 && c != 3 && c != 4) {
    *why = "image has " + std::to_string(c) + " channels (1, 3 or 4 can be used)";
    return false;
  }
  const bool grey_out = format == PixelFormat::kGrey || (format == PixelFormat::kGreyOrRgb && c == 1);
  int code = -1;  // -1: the pixels are already as wanted
  if (grey_out) {
    if (c == 3)
      code = bgr ? cv::COLOR_BGR2GRAY : cv::COLOR_RGB2GRAY;
    else if (c == 4)
      code = bgr ? cv::COLOR_BGRA2GRAY : cv::COLOR_RGBA2GRAY;
  } else {
    if (c == 1)
      code = cv::COLOR_GRAY2RGB;
    else if (c == 3 && bgr)
      code = cv::COLOR_BGR2RGB;
    else if (c == 4)
      code = bgr ? cv::COLOR_BGRA2RGB : cv::COLOR_RGBA2RGB;
  }
  // into a new Mat: converting into *out would write into pixels it may share with another Mat
  cv::Mat converted;
  if (code < 0)
    converted = owned ? src : src.clone();
  else
    cv::cvtColor(src, converted, code);
  *out = converted;
  return true;
}

/// "" if the bytes start as the encoding says (and a JPEG ends with its end-of-image marker, so a
/// cut-off JPEG is refused rather than decoded with made-up rows), else what is wrong. Also keeps
/// imdecode from reading any of the other formats it knows.
std::string containerProblem(const RawImage& raw) {
  const uint8_t* d = raw.data;
  size_t n = raw.size;
  if (raw.encoding == static_cast<int>(ImageEncoding::kPng)) {
    static const uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a};
    return n >= 8 && std::memcmp(d, kSignature, 8) == 0 ? "" : "no PNG signature";
  }
  if (n < 4 || d[0] != 0xff || d[1] != 0xd8 || d[2] != 0xff) return "no JPEG start-of-image marker";
  while (n > 4 && d[n - 1] == 0x00) --n;  // zero padding after the image
  if (d[n - 2] != 0xff || d[n - 1] != 0xd9) return "no end-of-image marker (the data is cut off)";
  return "";
}

const char* encodingName(int encoding) {
  switch (static_cast<ImageEncoding>(encoding)) {
    case ImageEncoding::kGray8: return "GRAY8";
    case ImageEncoding::kRgb8: return "RGB8";
    case ImageEncoding::kBgr8: return "BGR8";
    case ImageEncoding::kJpeg: return "JPEG";
    case ImageEncoding::kPng: return "PNG";
    case ImageEncoding::kDepth16: return "DEPTH16";
    case ImageEncoding::kDepth32f: return "DEPTH32F";
  }
  return nullptr;
}

/// "encoding NAME (N)", or "unknown image encoding N".
std::string encodingText(int encoding) {
  const char* name = encodingName(encoding);
  return name ? std::string("encoding ") + name + " (" + std::to_string(encoding) + ")"
              : "unknown image encoding " + std::to_string(encoding);
}

/// The JPEG or PNG in `raw` decoded with imdecode `flags` (not yet checked for depth or size).
bool imdecodeChecked(const RawImage& raw, int flags, cv::Mat* img, std::string* why) {
  const char* name = raw.encoding == static_cast<int>(ImageEncoding::kJpeg) ? "JPEG" : "PNG";
  if (raw.data == nullptr || raw.size == 0) {
    *why = std::string("empty ") + name + " image";
    return false;
  }
  if (raw.size > static_cast<size_t>(INT_MAX)) {
    *why = std::string(name) + " image of " + std::to_string(raw.size) + " bytes is too large";
    return false;
  }
  if (const std::string bad = containerProblem(raw); !bad.empty()) {
    *why = std::string(name) + " image does not decode: " + bad;
    return false;
  }
  const cv::Mat buf(1, static_cast<int>(raw.size), CV_8UC1, const_cast<uint8_t*>(raw.data));
  try {
    *img = cv::imdecode(buf, flags);
  } catch (const std::exception& e) {
    *why = std::string(name) + " image does not decode: " + e.what();
    return false;
  }
  if (img->empty()) {
    *why = std::string(name) + " image does not decode";
    return false;
  }
  return true;
}

bool decodeCompressed(const RawImage& raw, int width, int height, PixelFormat format, cv::Mat* out, std::string* why) {
  // a JPEG wanted in grey is decoded to its luma directly (no chroma work); the rest as stored
  const bool jpeg_luma = format == PixelFormat::kGrey && raw.encoding == static_cast<int>(ImageEncoding::kJpeg);
  cv::Mat img;
  if (!imdecodeChecked(raw, jpeg_luma ? cv::IMREAD_GRAYSCALE | cv::IMREAD_IGNORE_ORIENTATION : cv::IMREAD_UNCHANGED,
                       &img, why))
    return false;
  if (img.depth() == CV_16U)
    img.convertTo(img, CV_8U, 1.0 / 257.0);
  else if (img.depth() != CV_8U) {
    *why = std::string(encodingName(raw.encoding)) + " image has pixels of neither 8 nor 16 bits";
    return false;
  }
  if (img.cols != width || img.rows != height) {
    *why = wrongSize(img.cols, img.rows, width, height);
    return false;
  }
  return toFormat(img, true, true, format, out, why);  // imdecode gives B, G, R[, A]
}

/// A view (no copy) of raw pixels of `type` laid out `width` x `height`, rows `row_stride` bytes
/// apart (0: packed); false with `why` if the layout is not the camera's or the data is short.
bool rawView(const RawImage& raw, int width, int height, int type, cv::Mat* view, std::string* why) {
  if (raw.width != width || raw.height != height) {
    *why = wrongSize(raw.width, raw.height, width, height);
    return false;
  }
  const size_t row = static_cast<size_t>(width) * CV_ELEM_SIZE(type);
  if (raw.row_stride != 0 && (raw.row_stride < 0 || static_cast<size_t>(raw.row_stride) < row)) {
    *why = "image row_stride " + std::to_string(raw.row_stride) + " is shorter than a row of " + std::to_string(width) +
           " pixels (" + std::to_string(row) + " bytes)";
    return false;
  }
  const size_t stride = raw.row_stride > 0 ? static_cast<size_t>(raw.row_stride) : row;
  const size_t needed = stride * static_cast<size_t>(height - 1) + row;
  if (raw.data == nullptr || raw.size < needed) {
    *why = "image data shorter than its width x height (" + std::to_string(raw.data ? raw.size : 0) + " of " +
           std::to_string(needed) + " bytes)";
    return false;
  }
  *view = cv::Mat(height, width, type, const_cast<uint8_t*>(raw.data), stride);
  return true;
}

bool checkCameraSize(int width, int height, std::string* why) {
  if (width > 0 && height > 0) return true;
  *why = "no camera size to check the image against (" + sizeText(width, height) + ")";
  return false;
}

}  // namespace

RawImage rawImage(const image_t& m) {
  RawImage r;
  r.utime = m.utime;
  r.width = m.width;
  r.height = m.height;
  r.row_stride = m.row_stride;
  r.encoding = m.encoding;
  r.exposure_time = m.exposure_time;
  r.data = m.data.data();
  r.size = std::min<size_t>(m.data.size(), m.size > 0 ? static_cast<size_t>(m.size) : 0);
  return r;
}

float exposureTime(const RawImage& raw) {
  return std::isfinite(raw.exposure_time) && raw.exposure_time > 0.0f ? raw.exposure_time : 0.0f;
}

bool decodeImage(const RawImage& raw, int width, int height, PixelFormat format, cv::Mat* out, std::string* why) {
  if (!checkCameraSize(width, height, why)) return false;
  const auto enc = static_cast<ImageEncoding>(raw.encoding);
  if (enc == ImageEncoding::kJpeg || enc == ImageEncoding::kPng)
    return decodeCompressed(raw, width, height, format, out, why);
  int channels = 0;
  if (enc == ImageEncoding::kGray8)
    channels = 1;
  else if (enc == ImageEncoding::kRgb8 || enc == ImageEncoding::kBgr8)
    channels = 3;
  else if (enc == ImageEncoding::kDepth16 || enc == ImageEncoding::kDepth32f) {
    *why = "image " + encodingText(raw.encoding) + " is a depth image, not a picture";
    return false;
  } else {
    *why = encodingText(raw.encoding);
    return false;
  }
  cv::Mat view;
  if (!rawView(raw, width, height, CV_8UC(channels), &view, why)) return false;
  return toFormat(view, enc == ImageEncoding::kBgr8, false, format, out, why);
}

bool decodeDepth(const RawImage& raw, int width, int height, cv::Mat* out, std::string* why) {
  if (!checkCameraSize(width, height, why)) return false;
  const auto enc = static_cast<ImageEncoding>(raw.encoding);
  cv::Mat metres;
  if (enc == ImageEncoding::kDepth16 || enc == ImageEncoding::kDepth32f) {
    // the bytes are little-endian, as is every machine this runs on
    cv::Mat view;
    if (!rawView(raw, width, height, enc == ImageEncoding::kDepth16 ? CV_16UC1 : CV_32FC1, &view, why)) return false;
    view.convertTo(metres, CV_32F, enc == ImageEncoding::kDepth16 ? 1e-3 : 1.0);  // a copy in both cases
  } else if (enc == ImageEncoding::kPng) {
    cv::Mat img;
    if (!imdecodeChecked(raw, cv::IMREAD_UNCHANGED, &img, why)) return false;
    if (img.depth() != CV_16U || img.channels() != 1) {
      *why = "PNG depth image must be 16-bit grey (millimetres), not " + std::to_string(8 * img.elemSize1()) +
             "-bit with " + std::to_string(img.channels()) + " channels";
      return false;
    }
    if (img.cols != width || img.rows != height) {
      *why = wrongSize(img.cols, img.rows, width, height);
      return false;
    }
    img.convertTo(metres, CV_32F, 1e-3);
  } else {
    *why = "image " + encodingText(raw.encoding) + " is not depth (DEPTH16, DEPTH32F or 16-bit PNG)";
    return false;
  }
  // no depth: 0 (NaN, infinities and negatives included)
  for (int y = 0; y < metres.rows; ++y) {
    float* row = metres.ptr<float>(y);
    for (int x = 0; x < metres.cols; ++x)
      if (!(std::isfinite(row[x]) && row[x] > 0.0f)) row[x] = 0.0f;
  }
  *out = metres;
  return true;
}

}  // namespace livo

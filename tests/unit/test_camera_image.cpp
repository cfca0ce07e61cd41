// The shared camera image decoder (livo_camera_image): every encoding to the right pixels in grey
// and RGB, row_stride padding, the camera's size, cut-off and undecodable data, and the view of an
// image_t.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "livo/camera_image.hpp"
#include "livo/image_t.hpp"

using namespace livo;

namespace {

RawImage raw(const std::vector<uint8_t>& bytes, int w, int h, int stride, ImageEncoding enc) {
  RawImage r;
  r.utime = 1000;
  r.width = w;
  r.height = h;
  r.row_stride = stride;
  r.encoding = static_cast<int>(enc);
  r.exposure_time = 0.004f;
  r.data = bytes.data();
  r.size = bytes.size();
  return r;
}

/// A smooth colour pattern, channels R, G, B.
cv::Mat rgbPattern(int w, int h) {
  cv::Mat img(h, w, CV_8UC3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      img.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uint8_t>(20 + 3 * x), static_cast<uint8_t>(30 + 4 * y),
                                          static_cast<uint8_t>(200 - 2 * x - y));
  return img;
}

/// 0.299 R + 0.587 G + 0.114 B of an R, G, B image, as double.
cv::Mat luma(const cv::Mat& rgb) {
  cv::Mat out(rgb.size(), CV_64F);
  for (int y = 0; y < rgb.rows; ++y)
    for (int x = 0; x < rgb.cols; ++x) {
      const cv::Vec3b p = rgb.at<cv::Vec3b>(y, x);
      out.at<double>(y, x) = 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2];
    }
  return out;
}

double maxDiff(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat a64, b64;
  a.convertTo(a64, CV_64F);
  b.convertTo(b64, CV_64F);
  return cv::norm(a64, b64, cv::NORM_INF);
}
double meanDiff(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat a64, b64;
  a.convertTo(a64, CV_64F);
  b.convertTo(b64, CV_64F);
  return cv::norm(a64, b64, cv::NORM_L1) / static_cast<double>(a.total() * a.channels());
}

std::vector<uint8_t> encode(const char* ext, const cv::Mat& img, const std::vector<int>& params = {}) {
  std::vector<uint8_t> bytes;
  EXPECT_TRUE(cv::imencode(ext, img, bytes, params));
  return bytes;
}

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST(CameraImage, Gray8WithRowStrideDecodesToGreyAndRgb) {
  const int w = 6, h = 4, stride = 8;
  std::vector<uint8_t> bytes(stride * (h - 1) + w, 0xEE);  // padding 0xEE; the last row unpadded
  cv::Mat expected(h, w, CV_8UC1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) bytes[y * stride + x] = expected.at<uint8_t>(y, x) = static_cast<uint8_t>(10 * x + y);
  const RawImage r = raw(bytes, w, h, stride, ImageEncoding::kGray8);
  cv::Mat grey, rgb, native;
  std::string why;
  ASSERT_TRUE(decodeGrey(r, w, h, &grey, &why)) << why;
  ASSERT_EQ(grey.type(), CV_8UC1);
  EXPECT_EQ(maxDiff(grey, expected), 0.0);
  ASSERT_TRUE(decodeRgb(r, w, h, &rgb, &why)) << why;
  ASSERT_EQ(rgb.type(), CV_8UC3);
  std::vector<cv::Mat> planes;
  cv::split(rgb, planes);
  for (const cv::Mat& p : planes) EXPECT_EQ(maxDiff(p, expected), 0.0);
  ASSERT_TRUE(decodeImage(r, w, h, PixelFormat::kGreyOrRgb, &native, &why)) << why;
  EXPECT_EQ(native.type(), CV_8UC1);
  // the result is a copy, not a view of the message's bytes
  std::fill(bytes.begin(), bytes.end(), 0);
  EXPECT_EQ(maxDiff(grey, expected), 0.0);
  EXPECT_EQ(maxDiff(native, expected), 0.0);
}

TEST(CameraImage, Rgb8AndBgr8WithRowStrideDecodeToTheSamePixels) {
  const int w = 7, h = 5;
  const cv::Mat img = rgbPattern(w, h);
  std::vector<uint8_t> rgb_bytes(img.datastart, img.dataend);  // packed
  const int stride = 3 * w + 5;
  std::vector<uint8_t> bgr_bytes(stride * h, 0xEE);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int k = 0; k < 3; ++k) bgr_bytes[y * stride + 3 * x + k] = img.at<cv::Vec3b>(y, x)[2 - k];
  const RawImage as_rgb = raw(rgb_bytes, w, h, 0, ImageEncoding::kRgb8);
  const RawImage as_bgr = raw(bgr_bytes, w, h, stride, ImageEncoding::kBgr8);
  std::string why;
  for (const RawImage& r : {as_rgb, as_bgr}) {
    cv::Mat rgb, native, grey;
    ASSERT_TRUE(decodeRgb(r, w, h, &rgb, &why)) << why;
    ASSERT_EQ(rgb.type(), CV_8UC3);
    EXPECT_EQ(maxDiff(rgb, img), 0.0) << "encoding " << r.encoding;
    ASSERT_TRUE(decodeImage(r, w, h, PixelFormat::kGreyOrRgb, &native, &why)) << why;
    EXPECT_EQ(maxDiff(native, img), 0.0) << "encoding " << r.encoding;
    ASSERT_TRUE(decodeGrey(r, w, h, &grey, &why)) << why;
    ASSERT_EQ(grey.type(), CV_8UC1);
    EXPECT_LE(maxDiff(grey, luma(img)), 0.5) << "encoding " << r.encoding;  // rounded luminance
  }
}

TEST(CameraImage, PngOfEveryDepthAndChannelCount) {
  const int w = 9, h = 6;
  const cv::Mat img = rgbPattern(w, h);  // R, G, B
  cv::Mat bgr, grey_expected;
  cv::cvtColor(img, bgr, cv::COLOR_RGB2BGR);  // what imencode takes
  cv::extractChannel(img, grey_expected, 1);  // a grey image: the G channel
  for (const int depth : {CV_8U, CV_16U}) {
    const double scale = depth == CV_16U ? 257.0 : 1.0;  // 16 bit: v * 257 decodes to v
    for (const int channels : {1, 3, 4}) {
      SCOPED_TRACE("depth " + std::to_string(depth) + ", channels " + std::to_string(channels));
      cv::Mat source;
      if (channels == 1)
        source = grey_expected.clone();
      else if (channels == 3)
        source = bgr.clone();
      else {
        cv::cvtColor(bgr, source, cv::COLOR_BGR2BGRA);
        for (int y = 0; y < h; ++y)  // alpha varies: it must not matter
          for (int x = 0; x < w; ++x) source.at<cv::Vec4b>(y, x)[3] = static_cast<uint8_t>(25 * x);
      }
      source.convertTo(source, depth, scale);
      const std::vector<uint8_t> png = encode(".png", source);
      const RawImage r = raw(png, 0, 0, 0, ImageEncoding::kPng);  // size comes from the data
      cv::Mat rgb, grey, native;
      std::string why;
      ASSERT_TRUE(decodeRgb(r, w, h, &rgb, &why)) << why;
      ASSERT_TRUE(decodeGrey(r, w, h, &grey, &why)) << why;
      ASSERT_TRUE(decodeImage(r, w, h, PixelFormat::kGreyOrRgb, &native, &why)) << why;
      ASSERT_EQ(rgb.type(), CV_8UC3);
      ASSERT_EQ(grey.type(), CV_8UC1);
      if (channels == 1) {
        EXPECT_EQ(maxDiff(grey, grey_expected), 0.0);
        cv::Mat grey3;
        cv::cvtColor(grey_expected, grey3, cv::COLOR_GRAY2RGB);
        EXPECT_EQ(maxDiff(rgb, grey3), 0.0);
        EXPECT_EQ(native.type(), CV_8UC1);
      } else {
        EXPECT_EQ(maxDiff(rgb, img), 0.0);
        EXPECT_LE(maxDiff(grey, luma(img)), 0.5);
        EXPECT_EQ(native.type(), CV_8UC3);
      }
    }
  }
}

TEST(CameraImage, JpegDecodesInGreyAndRgb) {
  const int w = 64, h = 48;
  const cv::Mat img = rgbPattern(w, h);
  cv::Mat bgr;
  cv::cvtColor(img, bgr, cv::COLOR_RGB2BGR);
  const std::vector<uint8_t> jpg = encode(".jpg", bgr, {cv::IMWRITE_JPEG_QUALITY, 95});
  cv::Mat rgb, grey, native;
  std::string why;
  ASSERT_TRUE(decodeRgb(raw(jpg, w, h, 0, ImageEncoding::kJpeg), w, h, &rgb, &why)) << why;
  EXPECT_LT(meanDiff(rgb, img), 3.0);  // lossy
  ASSERT_TRUE(decodeGrey(raw(jpg, w, h, 0, ImageEncoding::kJpeg), w, h, &grey, &why)) << why;
  ASSERT_EQ(grey.type(), CV_8UC1);
  EXPECT_LT(meanDiff(grey, luma(img)), 3.0);
  ASSERT_TRUE(decodeImage(raw(jpg, w, h, 0, ImageEncoding::kJpeg), w, h, PixelFormat::kGreyOrRgb, &native, &why));
  EXPECT_EQ(native.type(), CV_8UC3);

  // a grey JPEG: grey stays grey, RGB repeats it; zero padding after the end marker is fine
  cv::Mat g;
  cv::extractChannel(img, g, 1);
  std::vector<uint8_t> gjpg = encode(".jpg", g, {cv::IMWRITE_JPEG_QUALITY, 95});
  gjpg.resize(gjpg.size() + 16, 0);
  ASSERT_TRUE(decodeImage(raw(gjpg, w, h, 0, ImageEncoding::kJpeg), w, h, PixelFormat::kGreyOrRgb, &native, &why))
      << why;
  EXPECT_EQ(native.type(), CV_8UC1);
  EXPECT_LT(meanDiff(native, g), 2.0);
  ASSERT_TRUE(decodeRgb(raw(gjpg, w, h, 0, ImageEncoding::kJpeg), w, h, &rgb, &why)) << why;
  std::vector<cv::Mat> planes;
  cv::split(rgb, planes);
  EXPECT_EQ(maxDiff(planes[0], native), 0.0);
  EXPECT_EQ(maxDiff(planes[2], native), 0.0);
}

TEST(CameraImage, RefusesAnotherSizeThanTheCameras) {
  const cv::Mat img = rgbPattern(64, 48);
  cv::Mat g;
  cv::extractChannel(img, g, 0);
  std::vector<uint8_t> bytes(g.datastart, g.dataend);
  cv::Mat out;
  std::string why;
  EXPECT_FALSE(decodeGrey(raw(bytes, 64, 48, 0, ImageEncoding::kGray8), 64, 50, &out, &why));
  EXPECT_TRUE(has(why, "64x48") && has(why, "64x50")) << why;
  EXPECT_FALSE(decodeRgb(raw(bytes, 48, 64, 0, ImageEncoding::kGray8), 64, 48, &out, &why));  // same bytes, turned
  EXPECT_TRUE(has(why, "48x64") && has(why, "64x48")) << why;
  // compressed: the decoded size counts (the message's width and height say the same here)
  const std::vector<uint8_t> png = encode(".png", g), jpg = encode(".jpg", g);
  EXPECT_FALSE(decodeRgb(raw(png, 64, 48, 0, ImageEncoding::kPng), 32, 48, &out, &why));
  EXPECT_TRUE(has(why, "64x48") && has(why, "32x48")) << why;
  EXPECT_FALSE(decodeGrey(raw(jpg, 64, 48, 0, ImageEncoding::kJpeg), 64, 24, &out, &why));
  EXPECT_TRUE(has(why, "64x48") && has(why, "64x24")) << why;
  EXPECT_TRUE(out.empty());  // untouched
  // no camera size to check against
  EXPECT_FALSE(decodeGrey(raw(bytes, 0, 0, 0, ImageEncoding::kGray8), 0, 0, &out, &why));
  EXPECT_FALSE(why.empty());
}

TEST(CameraImage, RefusesTruncatedData) {
  const int w = 64, h = 48;
  const cv::Mat img = rgbPattern(w, h);
  std::vector<uint8_t> rgb(img.datastart, img.dataend);
  cv::Mat out(2, 2, CV_8UC1, cv::Scalar(9));
  const uint8_t* before = out.data;
  std::string why;
  // raw: one byte short, with and without row padding
  std::vector<uint8_t> short_rgb(rgb.begin(), rgb.end() - 1);
  EXPECT_FALSE(decodeRgb(raw(short_rgb, w, h, 0, ImageEncoding::kRgb8), w, h, &out, &why));
  EXPECT_TRUE(has(why, "shorter")) << why;
  std::vector<uint8_t> padded((3 * w + 4) * (h - 1) + 3 * w - 1);
  EXPECT_FALSE(decodeGrey(raw(padded, w, h, 3 * w + 4, ImageEncoding::kBgr8), w, h, &out, &why));
  EXPECT_TRUE(has(why, "shorter")) << why;
  EXPECT_FALSE(decodeGrey(raw(rgb, w, h, 3 * w - 1, ImageEncoding::kRgb8), w, h, &out, &why));  // rows overlap
  EXPECT_TRUE(has(why, "row_stride")) << why;
  EXPECT_FALSE(decodeGrey(raw(rgb, w, h, -1, ImageEncoding::kRgb8), w, h, &out, &why));
  EXPECT_TRUE(has(why, "row_stride")) << why;
  RawImage no_data = raw(rgb, w, h, 0, ImageEncoding::kRgb8);
  no_data.data = nullptr;
  EXPECT_FALSE(decodeRgb(no_data, w, h, &out, &why));
  EXPECT_TRUE(has(why, "shorter")) << why;
  // compressed: cut in half
  cv::Mat bgr;
  cv::cvtColor(img, bgr, cv::COLOR_RGB2BGR);
  const std::vector<uint8_t> png = encode(".png", bgr), jpg = encode(".jpg", bgr);
  const std::vector<uint8_t> half_png(png.begin(), png.begin() + png.size() / 2);
  EXPECT_FALSE(decodeRgb(raw(half_png, w, h, 0, ImageEncoding::kPng), w, h, &out, &why));
  EXPECT_TRUE(has(why, "decode")) << why;
  const std::vector<uint8_t> half_jpg(jpg.begin(), jpg.begin() + jpg.size() / 2);
  for (const PixelFormat f : {PixelFormat::kGrey, PixelFormat::kRgb, PixelFormat::kGreyOrRgb}) {
    EXPECT_FALSE(decodeImage(raw(half_jpg, w, h, 0, ImageEncoding::kJpeg), w, h, f, &out, &why));
    EXPECT_TRUE(has(why, "decode") && has(why, "cut off")) << why;
  }
  // and nothing was written on any refusal
  EXPECT_EQ(out.data, before);
  EXPECT_EQ(out.at<uint8_t>(1, 1), 9);
}

TEST(CameraImage, RefusesUndecodableJpegAndUnknownEncodings) {
  const cv::Mat img = rgbPattern(32, 24);
  std::vector<uint8_t> rgb(img.datastart, img.dataend);
  cv::Mat out;
  std::string why;
  const std::vector<uint8_t> junk(100, 0xAB);
  EXPECT_FALSE(decodeRgb(raw(junk, 32, 24, 0, ImageEncoding::kJpeg), 32, 24, &out, &why));
  EXPECT_TRUE(has(why, "JPEG") && has(why, "decode")) << why;
  EXPECT_FALSE(decodeGrey(raw(junk, 32, 24, 0, ImageEncoding::kPng), 32, 24, &out, &why));
  EXPECT_TRUE(has(why, "PNG") && has(why, "decode")) << why;
  // JPEG start and end markers around garbage
  std::vector<uint8_t> framed = {0xff, 0xd8, 0xff, 0xe0, 0x00, 0x10, 'J', 'F', 'I', 'F', 0x00};
  framed.insert(framed.end(), 200, 0x5a);
  framed.insert(framed.end(), {0xff, 0xd9});
  for (const PixelFormat f : {PixelFormat::kGrey, PixelFormat::kRgb}) {
    EXPECT_FALSE(decodeImage(raw(framed, 32, 24, 0, ImageEncoding::kJpeg), 32, 24, f, &out, &why));
    EXPECT_TRUE(has(why, "decode")) << why;
  }
  // a PNG sent as JPEG is not taken for one
  const std::vector<uint8_t> png = encode(".png", img);
  EXPECT_FALSE(decodeRgb(raw(png, 32, 24, 0, ImageEncoding::kJpeg), 32, 24, &out, &why));
  EXPECT_TRUE(has(why, "JPEG")) << why;
  const std::vector<uint8_t> none;
  EXPECT_FALSE(decodeRgb(raw(none, 32, 24, 0, ImageEncoding::kJpeg), 32, 24, &out, &why));
  EXPECT_TRUE(has(why, "empty")) << why;
  RawImage unknown = raw(rgb, 32, 24, 0, ImageEncoding::kRgb8);
  unknown.encoding = 42;
  EXPECT_FALSE(decodeRgb(unknown, 32, 24, &out, &why));
  EXPECT_TRUE(has(why, "encoding 42")) << why;
  EXPECT_TRUE(out.empty());
}

// Decoding into a Mat that shares its pixels with another leaves the other alone.
TEST(CameraImage, DecodesIntoItsOwnPixels) {
  const cv::Mat img = rgbPattern(8, 6);
  std::vector<uint8_t> bytes(img.datastart, img.dataend);
  const cv::Mat kept(6, 8, CV_8UC3, cv::Scalar(1, 2, 3));
  cv::Mat out = kept;  // shares kept's pixels, same size and type as the result
  std::string why;
  ASSERT_TRUE(decodeRgb(raw(bytes, 8, 6, 0, ImageEncoding::kBgr8), 8, 6, &out, &why)) << why;
  EXPECT_NE(out.data, kept.data);
  EXPECT_EQ(kept.at<cv::Vec3b>(5, 7), cv::Vec3b(1, 2, 3));
}

TEST(CameraImage, RawImageViewsTheMessage) {
  image_t m{};
  m.utime = 123456;
  m.width = 4;
  m.height = 2;
  m.row_stride = 5;
  m.encoding = image_t::ENCODING_BGR8;
  m.exposure_time = 0.02f;
  m.data.assign(30, 7);
  m.size = 20;  // fewer than the vector holds: the message's size counts
  RawImage r = rawImage(m);
  EXPECT_EQ(r.utime, 123456);
  EXPECT_EQ(r.width, 4);
  EXPECT_EQ(r.height, 2);
  EXPECT_EQ(r.row_stride, 5);
  EXPECT_EQ(r.encoding, static_cast<int>(ImageEncoding::kBgr8));
  EXPECT_EQ(r.data, m.data.data());
  EXPECT_EQ(r.size, 20u);
  EXPECT_FLOAT_EQ(exposureTime(r), 0.02f);
  m.size = 50;  // more than it holds: only what is there
  EXPECT_EQ(rawImage(m).size, 30u);
  m.size = -3;
  EXPECT_EQ(rawImage(m).size, 0u);
  for (const float bad :
       {0.0f, -0.01f, std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    m.exposure_time = bad;
    EXPECT_EQ(exposureTime(rawImage(m)), 0.0f) << bad;
  }
  // the constants agree with the message's
  EXPECT_EQ(static_cast<int>(ImageEncoding::kGray8), static_cast<int>(image_t::ENCODING_GRAY8));
  EXPECT_EQ(static_cast<int>(ImageEncoding::kRgb8), static_cast<int>(image_t::ENCODING_RGB8));
  EXPECT_EQ(static_cast<int>(ImageEncoding::kBgr8), static_cast<int>(image_t::ENCODING_BGR8));
  EXPECT_EQ(static_cast<int>(ImageEncoding::kJpeg), static_cast<int>(image_t::ENCODING_JPEG));
  EXPECT_EQ(static_cast<int>(ImageEncoding::kPng), static_cast<int>(image_t::ENCODING_PNG));
}

// Depth images: DEPTH16 (mm) and DEPTH32F (m) with row padding, 16-bit PNG (mm), to metres with 0
// where there is no depth; everything that is not depth refused, and depth refused as a picture.
TEST(CameraImage, DepthEncodingsDecodeToMetresWithZeroForNoDepth) {
  const int w = 3, h = 2;
  // DEPTH16, rows padded to 8 bytes (little-endian)
  const uint16_t mm[6] = {0, 500, 1000, 2500, 65535, 7};
  std::vector<uint8_t> d16(8 * h, 0xEE);
  for (int i = 0; i < 6; ++i) {
    d16[(i / 3) * 8 + (i % 3) * 2] = static_cast<uint8_t>(mm[i] & 0xff);
    d16[(i / 3) * 8 + (i % 3) * 2 + 1] = static_cast<uint8_t>(mm[i] >> 8);
  }
  cv::Mat out;
  std::string why;
  ASSERT_TRUE(decodeDepth(raw(d16, w, h, 8, ImageEncoding::kDepth16), w, h, &out, &why)) << why;
  ASSERT_EQ(out.type(), CV_32FC1);
  for (int i = 0; i < 6; ++i) EXPECT_FLOAT_EQ(out.at<float>(i / 3, i % 3), static_cast<float>(mm[i] * 1e-3));
  // DEPTH32F: NaN, infinities and negatives are no depth
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const float metres[6] = {1.25f, nan, inf, -2.0f, 0.0f, 7.5f};
  std::vector<uint8_t> d32(sizeof(metres));
  std::memcpy(d32.data(), metres, sizeof(metres));
  ASSERT_TRUE(decodeDepth(raw(d32, w, h, 0, ImageEncoding::kDepth32f), w, h, &out, &why)) << why;
  const float want[6] = {1.25f, 0.0f, 0.0f, 0.0f, 0.0f, 7.5f};
  for (int i = 0; i < 6; ++i) EXPECT_EQ(out.at<float>(i / 3, i % 3), want[i]) << "pixel " << i;
  // a 16-bit grey PNG, as ROS and the RGB-D datasets store depth: millimetres
  cv::Mat png16(h, w, CV_16UC1);
  for (int i = 0; i < 6; ++i) png16.at<uint16_t>(i / 3, i % 3) = mm[i];
  const std::vector<uint8_t> png = encode(".png", png16);
  ASSERT_TRUE(decodeDepth(raw(png, 0, 0, 0, ImageEncoding::kPng), w, h, &out, &why)) << why;
  for (int i = 0; i < 6; ++i) EXPECT_FLOAT_EQ(out.at<float>(i / 3, i % 3), static_cast<float>(mm[i] * 1e-3));
}

TEST(CameraImage, DepthRefusesWhatIsNotDepthAndPicturesRefuseDepth) {
  const int w = 3, h = 2;
  const std::vector<uint8_t> d16(w * h * 2, 1);
  cv::Mat out;
  std::string why;
  // short data, another size, a bad stride
  const std::vector<uint8_t> short_data(w * h * 2 - 1, 1);
  EXPECT_FALSE(decodeDepth(raw(short_data, w, h, 0, ImageEncoding::kDepth16), w, h, &out, &why));
  EXPECT_TRUE(has(why, "shorter")) << why;
  EXPECT_FALSE(decodeDepth(raw(d16, w, h, 0, ImageEncoding::kDepth16), 4, 2, &out, &why));
  EXPECT_TRUE(has(why, "3x2") && has(why, "4x2")) << why;
  EXPECT_FALSE(decodeDepth(raw(d16, w, h, 4, ImageEncoding::kDepth16), w, h, &out, &why));
  EXPECT_TRUE(has(why, "row_stride")) << why;
  // a picture is not depth
  const std::vector<uint8_t> grey(w * h, 100);
  EXPECT_FALSE(decodeDepth(raw(grey, w, h, 0, ImageEncoding::kGray8), w, h, &out, &why));
  EXPECT_TRUE(has(why, "GRAY8") && has(why, "not depth")) << why;
  const std::vector<uint8_t> png8 = encode(".png", cv::Mat(h, w, CV_8UC1, cv::Scalar(9)));
  EXPECT_FALSE(decodeDepth(raw(png8, 0, 0, 0, ImageEncoding::kPng), w, h, &out, &why));
  EXPECT_TRUE(has(why, "16-bit grey")) << why;
  EXPECT_TRUE(out.empty());
  // depth is not a picture
  EXPECT_FALSE(decodeGrey(raw(d16, w, h, 0, ImageEncoding::kDepth16), w, h, &out, &why));
  EXPECT_TRUE(has(why, "DEPTH16") && has(why, "depth image, not a picture")) << why;
  EXPECT_FALSE(decodeRgb(raw(d16, w, h, 0, ImageEncoding::kDepth32f), w, h, &out, &why));
  EXPECT_TRUE(has(why, "DEPTH32F")) << why;
  EXPECT_TRUE(out.empty());
}

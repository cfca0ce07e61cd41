// Image handling of the VIO core: refusing bad images with a reason (decoding itself is the shared
// livo_camera_image, tested in tests/unit/test_camera_image.cpp), the pyramid, patch sampling, the
// affine warp between views, and the depth grid's occlusion and depth-edge tests.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <random>
#include <vector>

#include "livo/vio/grey_image.hpp"
#include "livo/vio/image_pyramid.hpp"
#include "livo/vio/patch.hpp"
#include "livo/vio/point_selection.hpp"

using namespace livo;
using namespace livo::vio;

namespace {

cv::Mat pattern(int w, int h) {
  cv::Mat img(h, w, CV_8UC1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      img.at<uint8_t>(y, x) = static_cast<uint8_t>((x * 7 + y * 13 + (x * y) % 11) % 200 + 20);
  return img;
}

/// Packed bytes as an image taken at 1000 us with 4 ms exposure (utime, width, height, row_stride,
/// encoding, exposure_time, data, size).
RawImage raw(const std::vector<uint8_t>& bytes, int w, int h, ImageEncoding enc) {
  return RawImage{1000, w, h, 0, static_cast<int>(enc), 0.004f, bytes.data(), bytes.size()};
}

CameraRig camera() {
  CameraRig c;
  c.width = 320;
  c.height = 256;
  c.fx = c.fy = 250.0;
  c.cx = 159.5;
  c.cy = 127.5;
  c.distortion = {{-0.1, 0.02, 0.0, 0.0}};
  return c;
}

}  // namespace

TEST(VioImage, RefusesBadImagesWithAReason) {
  const cv::Mat img = pattern(64, 48);
  ImageCheckOptions o;
  EXPECT_EQ(imageProblem(img, o), "");
  cv::Mat black(48, 64, CV_8UC1, cv::Scalar(3));
  black.at<uint8_t>(10, 10) = 200;
  EXPECT_NE(imageProblem(black, o).find("black"), std::string::npos);
  cv::Mat white(48, 64, CV_8UC1, cv::Scalar(255));
  EXPECT_NE(imageProblem(white, o).find("blown out"), std::string::npos);
  cv::Mat half = img.clone();
  half.rowRange(0, 24).setTo(255);  // half saturated: still usable
  EXPECT_EQ(imageProblem(half, o), "");

  // readGreyImage: the shared decoder first (its reasons pass through), then these checks
  std::vector<uint8_t> bytes(img.data, img.data + img.total());
  GreyImage out;
  std::string why;
  ASSERT_TRUE(readGreyImage(raw(bytes, 64, 48, ImageEncoding::kGray8), 64, 48, o, &out, &why)) << why;
  EXPECT_EQ(cv::norm(out.pixels, img, cv::NORM_INF), 0.0);
  EXPECT_EQ(out.utime, 1000);
  EXPECT_FLOAT_EQ(out.exposure_time, 0.004f);
  EXPECT_FALSE(readGreyImage(raw(bytes, 64, 48, ImageEncoding::kGray8), 64, 50, o, &out, &why));
  EXPECT_NE(why.find("64x48"), std::string::npos) << why;
  std::vector<uint8_t> garbage(500, 0x5a);
  EXPECT_FALSE(readGreyImage(raw(garbage, 64, 48, ImageEncoding::kJpeg), 64, 48, o, &out, &why));
  EXPECT_NE(why.find("decode"), std::string::npos) << why;
  std::vector<uint8_t> dark(black.data, black.data + black.total());
  EXPECT_FALSE(readGreyImage(raw(dark, 64, 48, ImageEncoding::kGray8), 64, 48, o, &out, &why));
  EXPECT_NE(why.find("black"), std::string::npos) << why;
  RawImage unknown_exposure = raw(bytes, 64, 48, ImageEncoding::kGray8);
  unknown_exposure.exposure_time = NAN;
  ASSERT_TRUE(readGreyImage(unknown_exposure, 64, 48, o, &out, &why)) << why;
  EXPECT_EQ(out.exposure_time, 0.0f);
}

TEST(VioImage, PyramidAveragesAndSamplesConsistently) {
  const cv::Mat img = pattern(64, 48);
  ImagePyramid pyr;
  pyr.build(img, 3);
  ASSERT_EQ(pyr.levels(), 3);
  EXPECT_EQ(pyr.level(1).cols, 32);
  EXPECT_EQ(pyr.level(2).rows, 12);
  const int s = img.at<uint8_t>(6, 10) + img.at<uint8_t>(6, 11) + img.at<uint8_t>(7, 10) + img.at<uint8_t>(7, 11);
  EXPECT_EQ(pyr.level(1).at<uint8_t>(3, 5), (s + 2) / 4);
  // level coordinates: the centre of level-1 pixel (5, 3) is level-0 (10.5, 6.5)
  EXPECT_TRUE(ImagePyramid::toLevel(Eigen::Vector2d(10.5, 6.5), 1).isApprox(Eigen::Vector2d(5, 3)));
  // the grid sampler agrees with single bilinear samples
  float grid[25];
  const Eigen::Vector2d c(20.3, 17.8);
  ASSERT_TRUE(pyr.sampleGrid(0, c, 5, grid));
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 5; ++i) EXPECT_NEAR(grid[j * 5 + i], pyr.sample(0, c.x() + i - 2, c.y() + j - 2), 1e-3);
  EXPECT_FALSE(pyr.sampleGrid(0, Eigen::Vector2d(1.0, 20.0), 5, grid));  // leaves on the left
  EXPECT_FALSE(pyr.sampleGrid(2, Eigen::Vector2d(14.0, 6.0), 5, grid));  // and on the right at level 2
}

TEST(VioImage, StoredPatchAndIdentityWarpReproduceTheImage) {
  const cv::Mat img = pattern(160, 120);
  ImagePyramid pyr;
  pyr.build(img, 3);
  const Eigen::Vector2d u0(80.4, 61.7);
  std::vector<uint8_t> stored(3 * kStoredArea);
  ASSERT_TRUE(extractStoredPatches(pyr, u0, 3, stored.data()));
  float warped[kPatchArea];
  for (int l = 0; l < 3; ++l) {
    ASSERT_TRUE(warpReferencePatch(stored.data() + l * kStoredArea, Eigen::Matrix2d::Identity(),
                                   Eigen::Vector2d::Zero(), warped));
    const Eigen::Vector2d ul = ImagePyramid::toLevel(u0, l);
    for (int j = 0; j < kPatch; ++j)
      for (int i = 0; i < kPatch; ++i)
        EXPECT_NEAR(warped[j * kPatch + i], pyr.sample(l, ul.x() + i - 3.5, ul.y() + j - 3.5), 0.51);
    // re-centred by a whole-pixel shift (level pixels): the image around the shifted point (the
    // stored samples themselves: a fractional shift interpolates between them, not the image)
    ASSERT_TRUE(warpReferencePatch(stored.data() + l * kStoredArea, Eigen::Matrix2d::Identity(),
                                   Eigen::Vector2d(2.0, -3.0), warped));
    for (int j = 0; j < kPatch; ++j)
      for (int i = 0; i < kPatch; ++i)
        EXPECT_NEAR(warped[j * kPatch + i], pyr.sample(l, ul.x() + 2.0 + i - 3.5, ul.y() - 3.0 + j - 3.5), 0.51);
    // the derivative of each sample along a (fractional) shift: that of the bilinear interpolant
    const Eigen::Vector2d shift(1.6, -2.3);
    float gx[kPatchArea], gy[kPatchArea], ahead[kPatchArea];
    ASSERT_TRUE(
        warpReferencePatch(stored.data() + l * kStoredArea, Eigen::Matrix2d::Identity(), shift, warped, gx, gy));
    const double h = 0.01;  // within one bilinear cell: the interpolant is linear in each coordinate
    ASSERT_TRUE(warpReferencePatch(stored.data() + l * kStoredArea, Eigen::Matrix2d::Identity(),
                                   shift + Eigen::Vector2d(h, 0.0), ahead));
    for (int k = 0; k < kPatchArea; ++k) EXPECT_NEAR(gx[k], (ahead[k] - warped[k]) / h, 1e-2) << k;
    ASSERT_TRUE(warpReferencePatch(stored.data() + l * kStoredArea, Eigen::Matrix2d::Identity(),
                                   shift + Eigen::Vector2d(0.0, h), ahead));
    for (int k = 0; k < kPatchArea; ++k) EXPECT_NEAR(gy[k], (ahead[k] - warped[k]) / h, 1e-2) << k;
  }
  // the stored patch leaves a margin of (kStored - kPatch) / 2 = 4 pixels: a warp scaling by 2.5
  // needs offsets up to 8.75 > 7.5 from its centre, and so does a shift of 4.5 with the identity
  EXPECT_FALSE(warpReferencePatch(stored.data(), 2.5 * Eigen::Matrix2d::Identity(), Eigen::Vector2d::Zero(), warped));
  EXPECT_TRUE(warpReferencePatch(stored.data(), Eigen::Matrix2d::Identity(), Eigen::Vector2d(-4.0, 4.0), warped));
  EXPECT_FALSE(warpReferencePatch(stored.data(), Eigen::Matrix2d::Identity(), Eigen::Vector2d(4.5, 0.0), warped));
  EXPECT_FALSE(extractStoredPatches(pyr, Eigen::Vector2d(10.0, 60.0), 3, stored.data()));  // too near the border
}

// The sampling the update runs on is written so that the compiler vectorises it; each sample must
// still be the scalar formula, evaluated in the same order, to the bit (the VIO's outputs are
// reproducible across such changes). The references below are the formulas as first written.
TEST(VioImage, VectorisedSamplingIsTheScalarFormulaBitForBit) {
  const cv::Mat img = pattern(160, 120);
  ImagePyramid pyr;
  pyr.build(img, 3);
  auto gridReference = [&](int level, const Eigen::Vector2d& centre, int n, std::vector<float>* out) {
    const cv::Mat& l = pyr.level(level);
    const double half = 0.5 * (n - 1);
    const double x0 = centre.x() - half, y0 = centre.y() - half;
    const int ix = static_cast<int>(x0), iy = static_cast<int>(y0);
    const float ax = static_cast<float>(x0 - ix), ay = static_cast<float>(y0 - iy);
    const float w00 = (1 - ax) * (1 - ay), w10 = ax * (1 - ay), w01 = (1 - ax) * ay, w11 = ax * ay;
    out->assign(static_cast<size_t>(n * n), 0.0f);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const uint8_t* r0 = l.ptr<uint8_t>(iy + j) + ix + i;
        const uint8_t* r1 = r0 + l.step[0];
        (*out)[static_cast<size_t>(j * n + i)] = w00 * r0[0] + w10 * r0[1] + w01 * r1[0] + w11 * r1[1];
      }
  };
  // (the shift re-centring the reference, and the samples' derivatives along it, added since)
  auto warpReference = [](const uint8_t* stored, const Eigen::Matrix2d& A, const Eigen::Vector2d& shift, float* out,
                          float* gx, float* gy) {
    const double c = 0.5 * (kStored - 1), h = 0.5 * (kPatch - 1);
    const double cx = c + shift.x(), cy = c + shift.y();
    for (int j = 0; j < kPatch; ++j)
      for (int i = 0; i < kPatch; ++i) {
        const double dx = i - h, dy = j - h;
        const double x = cx + A(0, 0) * dx + A(0, 1) * dy, y = cy + A(1, 0) * dx + A(1, 1) * dy;
        const int ix = std::min(static_cast<int>(x), kStored - 2), iy = std::min(static_cast<int>(y), kStored - 2);
        const float ax = static_cast<float>(x - ix), ay = static_cast<float>(y - iy);
        const uint8_t* r0 = stored + iy * kStored + ix;
        const uint8_t* r1 = r0 + kStored;
        out[j * kPatch + i] =
            (1 - ax) * (1 - ay) * r0[0] + ax * (1 - ay) * r0[1] + (1 - ax) * ay * r1[0] + ax * ay * r1[1];
        gx[j * kPatch + i] = (1 - ay) * (r0[1] - r0[0]) + ay * (r1[1] - r1[0]);
        gy[j * kPatch + i] = (1 - ax) * (r1[0] - r0[0]) + ax * (r1[1] - r0[1]);
      }
  };
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<float> got, want;
  int grids = 0, warps = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const int level = trial % 3;
    const Eigen::Vector2d centre(12.0 + u(rng) * (pyr.level(level).cols - 24.0) * 0.9,
                                 12.0 + u(rng) * (pyr.level(level).rows - 24.0) * 0.9);
    for (const int n : {kWindow, kStored, 5}) {  // the two vectorised sizes and the generic path
      got.assign(static_cast<size_t>(n * n), -1.0f);
      if (!pyr.sampleGrid(level, centre, n, got.data())) continue;
      gridReference(level, centre, n, &want);
      ASSERT_EQ(std::memcmp(got.data(), want.data(), want.size() * sizeof(float)), 0)
          << "level " << level << " centre " << centre.transpose() << " n " << n;
      ++grids;
    }
    // a stored patch here, warped by a random affine map that mostly stays inside it
    std::vector<uint8_t> stored(3 * kStoredArea);
    if (!extractStoredPatches(pyr, centre * static_cast<double>(1 << level), 1, stored.data())) continue;
    Eigen::Matrix2d A;
    A << 0.7 + 0.6 * u(rng), 0.4 * (u(rng) - 0.5), 0.4 * (u(rng) - 0.5), 0.7 + 0.6 * u(rng);
    // half the trials re-centred by a shift of up to 1.5 pixels
    const Eigen::Vector2d shift =
        trial % 2 == 0 ? Eigen::Vector2d::Zero() : Eigen::Vector2d(3.0 * (u(rng) - 0.5), 3.0 * (u(rng) - 0.5));
    float warped[kPatchArea], scalar[kPatchArea], gx[kPatchArea], gy[kPatchArea], sgx[kPatchArea], sgy[kPatchArea];
    if (!warpReferencePatch(stored.data(), A, shift, warped, gx, gy)) continue;
    warpReference(stored.data(), A, shift, scalar, sgx, sgy);
    ASSERT_EQ(std::memcmp(warped, scalar, sizeof(warped)), 0) << "A\n" << A << "\nshift " << shift.transpose();
    ASSERT_EQ(std::memcmp(gx, sgx, sizeof(gx)), 0) << "A\n" << A << "\nshift " << shift.transpose();
    ASSERT_EQ(std::memcmp(gy, sgy, sizeof(gy)), 0) << "A\n" << A << "\nshift " << shift.transpose();
    // without the derivatives: the same samples
    float plain[kPatchArea];
    ASSERT_TRUE(warpReferencePatch(stored.data(), A, shift, plain));
    ASSERT_EQ(std::memcmp(plain, warped, sizeof(plain)), 0);
    ++warps;
  }
  EXPECT_GT(grids, 600);  // the trials did exercise both paths
  EXPECT_GT(warps, 100);

  // the pyramid's averaging, in blocks with a remainder (an odd width: 37 pixels at level 1)
  const cv::Mat odd = pattern(75, 61);
  ImagePyramid p2;
  p2.build(odd, 3);
  for (int l = 1; l < 3; ++l) {
    const cv::Mat& src = p2.level(l - 1);
    const cv::Mat& dst = p2.level(l);
    ASSERT_EQ(dst.cols, src.cols / 2);
    for (int y = 0; y < dst.rows; ++y)
      for (int x = 0; x < dst.cols; ++x) {
        const int sum = src.at<uint8_t>(2 * y, 2 * x) + src.at<uint8_t>(2 * y, 2 * x + 1) +
                        src.at<uint8_t>(2 * y + 1, 2 * x) + src.at<uint8_t>(2 * y + 1, 2 * x + 1);
        ASSERT_EQ(dst.at<uint8_t>(y, x), (sum + 2) >> 2) << "level " << l << " at " << x << ", " << y;
      }
  }
}

TEST(VioImage, AffineWarpBetweenViews) {
  const CameraRig rig = camera();
  const CameraProjection cam(rig);
  const Pose3 T_ref = Pose3::Identity();
  const Vec3 p(0.4, -0.3, 4.0);
  Eigen::Matrix2d A;
  ASSERT_TRUE(affineWarp(cam, T_ref, T_ref, p, Vec3::Zero(), &A));
  EXPECT_TRUE(A.isApprox(Eigen::Matrix2d::Identity(), 1e-9));
  // moving halfway towards the point doubles its image size: reference offsets are half
  Pose3 T_cur = Pose3::Identity();
  T_cur.translation() = 0.5 * p;
  ASSERT_TRUE(affineWarp(cam, T_cur, T_ref, p, Vec3::Zero(), &A));
  EXPECT_NEAR(A.determinant(), 0.25, 0.03);  // 0.5 per axis, modulated by the distortion
  // rolling the camera about its axis by 10 deg rotates the offsets by 10 deg
  Pose3 T_roll = Pose3::Identity();
  T_roll.linear() = so3::Exp(Vec3(0.0, 0.0, 10.0 * M_PI / 180.0));
  const Vec3 q(0.0, 0.0, 3.0);  // on the axis: no distortion effect
  ASSERT_TRUE(affineWarp(cam, T_roll, T_ref, q, Vec3::Zero(), &A));
  EXPECT_NEAR(std::atan2(A(1, 0), A(0, 0)) * 180.0 / M_PI, 10.0, 1e-6);
  EXPECT_NEAR(A.determinant(), 1.0, 1e-9);
  // the warp predicts where a nearby surface point appears: a point on the fronto-parallel plane
  // 2 cm to the side of p, seen from both cameras
  T_cur.translation() = Vec3(0.3, 0.1, 0.5);
  T_cur.linear() = so3::Exp(Vec3(0.02, -0.05, 0.03));
  ASSERT_TRUE(affineWarp(cam, T_cur, T_ref, p, Vec3::Zero(), &A));
  const Vec3 n = p.normalized(), t1 = n.unitOrthogonal();
  const Vec3 p2 = p + 0.02 * t1;
  Eigen::Vector2d c0, c1, r0, r1;
  ASSERT_TRUE(cam.project(T_cur.inverse() * p, &c0) && cam.project(T_cur.inverse() * p2, &c1));
  ASSERT_TRUE(cam.project(p, &r0) && cam.project(p2, &r1));
  EXPECT_LT((A * (c1 - c0) - (r1 - r0)).norm(), 0.01 * (r1 - r0).norm());
}

TEST(VioImage, AffineWarpFollowsTheSurfaceNormal) {
  // a floor 1.5 m below the cameras seen obliquely from views 20 deg apart about the vertical and
  // at 0.7 of the distance: the warp with the floor's normal maps offsets on the floor between the
  // views; the fronto-parallel one is off by the change of foreshortening
  const CameraProjection cam(camera());
  const Vec3 n(0.0, -1.0, 0.0);  // camera frame: y down, the floor at y = 1.5 faces up
  const Vec3 p(0.2, 1.5, 3.0);
  const Pose3 T_ref = Pose3::Identity();
  Pose3 T_cur = Pose3::Identity();
  T_cur.linear() = so3::Exp(Vec3(0.0, 20.0 * M_PI / 180.0, 0.0));
  T_cur.translation() = p - 0.7 * (T_cur.linear() * p);
  Eigen::Matrix2d A_n, A_fp;
  ASSERT_TRUE(affineWarp(cam, T_cur, T_ref, p, n, &A_n));
  ASSERT_TRUE(affineWarp(cam, T_cur, T_ref, p, Vec3::Zero(), &A_fp));
  double worst_n = 0.0, worst_fp = 0.0;
  for (const Vec3& d : {Vec3(0.02, 0.0, 0.0), Vec3(0.0, 0.0, 0.02), Vec3(0.014, 0.0, -0.014)}) {
    const Vec3 q = p + d;  // on the floor
    Eigen::Vector2d c0, c1, r0, r1;
    ASSERT_TRUE(cam.project(T_cur.inverse() * p, &c0) && cam.project(T_cur.inverse() * q, &c1));
    ASSERT_TRUE(cam.project(p, &r0) && cam.project(q, &r1));
    const double scale = (r1 - r0).norm();
    worst_n = std::max(worst_n, (A_n * (c1 - c0) - (r1 - r0)).norm() / scale);
    worst_fp = std::max(worst_fp, (A_fp * (c1 - c0) - (r1 - r0)).norm() / scale);
  }
  EXPECT_LT(worst_n, 0.01);  // first order in the 2 cm offset (0.3 % for a pinhole)
  EXPECT_GT(worst_fp, 0.3);  // the fronto-parallel plane is not the floor (57 % for a pinhole)
  // seen edge-on from the reference (|cos| below kMinNormalIncidence): fronto-parallel
  Eigen::Matrix2d A_edge;
  ASSERT_TRUE(affineWarp(cam, T_cur, T_ref, p, p.normalized().unitOrthogonal(), &A_edge));
  EXPECT_TRUE(A_edge.isApprox(A_fp, 1e-12));
}

TEST(VioSelection, DepthEdgeTellsSlantedPlanesFromSteps) {
  const CameraRig rig = camera();
  const CameraProjection cam(rig);
  auto fill = [&](DepthGrid* g, const std::function<double(double, double)>& depth_at) {
    // LiDAR-like rows every 12 px, a point every 2 px along them
    g->clear();
    for (double v = 2.0; v < rig.height; v += 12.0)
      for (double u = 1.0; u < rig.width; u += 2.0) g->add(Eigen::Vector2d(u, v), static_cast<float>(depth_at(u, v)));
  };
  DepthGrid g(rig.width, rig.height, 6);
  const Eigen::Vector2d px(160.0, 140.0);
  // a floor seen at a grazing angle: camera 0.8 m above it, inverse depth linear in the row
  auto floor = [&](double, double v) { return 0.8 * rig.fy / std::max(1.0, v - rig.cy + 40.0); };
  fill(&g, floor);
  const double z = floor(px.x(), px.y());
  EXPECT_GT(floor(px.x(), px.y() - 16.0) - floor(px.x(), px.y() + 16.0), 0.5 * z);  // steep in depth
  EXPECT_FALSE(g.depthEdge(px, z, 16.0, 0.03, 0.03));
  // a box face at 3.4 m in front of a wall at 4 m, its edge 5 px left of the point
  auto step = [&](double u, double) { return u < px.x() - 5.0 ? 4.0 : 3.4; };
  fill(&g, step);
  EXPECT_TRUE(g.depthEdge(px, 3.4, 16.0, 0.03, 0.03));                                // on the box, next to the edge
  EXPECT_FALSE(g.depthEdge(px + Eigen::Vector2d(30.0, 0.0), 3.4, 16.0, 0.03, 0.03));  // well inside the face
  // on a LiDAR row (v = 146): the wall behind the box is hidden, the box itself is not; between
  // rows nothing is known
  EXPECT_TRUE(g.occluded(Eigen::Vector2d(px.x() + 20.0, 146.0), 4.0, 0.1, 0.1));
  EXPECT_FALSE(g.occluded(Eigen::Vector2d(px.x() + 20.0, 146.0), 3.45, 0.1, 0.1));
  EXPECT_FALSE(g.occluded(Eigen::Vector2d(px.x() + 20.0, 140.0), 4.0, 0.1, 0.1));
  // nothing known around a point: no edge claimed
  DepthGrid empty(rig.width, rig.height, 6);
  EXPECT_FALSE(empty.depthEdge(px, 3.0, 16.0, 0.03, 0.03));
}

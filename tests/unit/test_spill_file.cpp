// The shared spill file and the keyframe cloud store (common/spill_file.hpp): records come back
// byte for byte, float clouds exactly, quantised clouds within half a step.
#include <random>

#include <gtest/gtest.h>

#include "livo/spill_file.hpp"

using namespace livo;

namespace {
std::vector<Eigen::Vector3f> randomCloud(size_t n, float extent, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-extent, extent);
  std::vector<Eigen::Vector3f> c;
  for (size_t i = 0; i < n; ++i) c.emplace_back(u(rng), u(rng), u(rng));
  return c;
}
}  // namespace

TEST(SpillFile, RecordsComeBackByteForByte) {
  SpillFile f;
  std::vector<uint8_t> a(1000), b(3);
  for (size_t i = 0; i < a.size(); ++i) a[i] = static_cast<uint8_t>(i * 7);
  b = {1, 2, 3};
  const SpillFile::Record ra = f.append(a.data(), a.size());
  const SpillFile::Record rb = f.append(b.data(), b.size());
  EXPECT_EQ(f.size(), 1003u);
  std::vector<uint8_t> back;
  f.read(rb, &back);
  EXPECT_EQ(back, b);
  f.read(ra, &back);
  EXPECT_EQ(back, a);
}

TEST(SpillFile, ReleasedRecordsGiveTheirDiskSpaceBack) {
  SpillFile f;
  std::vector<uint8_t> a(1 << 20), b(1 << 20), c(1000);
  for (size_t i = 0; i < a.size(); ++i) a[i] = static_cast<uint8_t>(i * 7), b[i] = static_cast<uint8_t>(i * 13);
  for (size_t i = 0; i < c.size(); ++i) c[i] = static_cast<uint8_t>(i);
  const SpillFile::Record ra = f.append(a.data(), a.size());
  const SpillFile::Record rb = f.append(b.data(), b.size());
  const SpillFile::Record rc = f.append(c.data(), c.size());
  EXPECT_EQ(f.liveBytes(), a.size() + b.size() + c.size());
  const uint64_t allocated = f.allocatedBytes();
  EXPECT_GE(allocated, a.size() + b.size());
  f.release(rb);
  EXPECT_EQ(f.liveBytes(), a.size() + c.size());
  EXPECT_EQ(f.size(), a.size() + b.size() + c.size());  // offsets are not reused
  // the hole: all of b's blocks but the one it shares with c (the temp file system punches holes:
  // ext4, xfs, btrfs, tmpfs all do)
  EXPECT_LE(f.allocatedBytes(), allocated - b.size() + 4096);
  // the neighbours are intact
  std::vector<uint8_t> back;
  f.read(ra, &back);
  EXPECT_EQ(back, a);
  f.read(rc, &back);
  EXPECT_EQ(back, c);
}

TEST(SpillFile, RefusesADirectoryItCannotWriteTo) { EXPECT_THROW(SpillFile("/nonexistent/livo"), std::runtime_error); }

TEST(KeyframeCloudStore, FloatCloudsComeBackExactly) {
  KeyframeCloudStore store(0.0);
  const auto c = randomCloud(5000, 80.f, 1);
  store.put(3, c);
  store.put(4, {});
  EXPECT_EQ(store.get(3), c);
  EXPECT_TRUE(store.get(4).empty());
  EXPECT_TRUE(store.get(5).empty());
  EXPECT_EQ(store.size(), 2u);
  EXPECT_EQ(store.diskBytes(), 5000u * 12u);
}

TEST(KeyframeCloudStore, QuantisationErrorIsAtMostHalfAStep) {
  for (double step : {0.01, 0.002}) {
    KeyframeCloudStore store(step);
    const auto c = randomCloud(20000, static_cast<float>(step * 32000), 2);
    store.put(7, c);
    EXPECT_EQ(store.diskBytes(), 20000u * 6u);  // int16 x 3
    const auto back = store.get(7);
    ASSERT_EQ(back.size(), c.size());
    double worst = 0.0;
    for (size_t i = 0; i < c.size(); ++i) worst = std::max(worst, double((back[i] - c[i]).cwiseAbs().maxCoeff()));
    // half a step, plus float rounding of the coordinates (|v| < 330 m: 3e-5 m)
    EXPECT_LE(worst, 0.5 * step + 4e-5) << "step " << step;
    EXPECT_GT(worst, 0.4 * step) << "step " << step;  // it does quantise
  }
}

TEST(KeyframeCloudStore, ACloudBeyondTheInt16RangeIsKeptAsFloat) {
  KeyframeCloudStore store(0.01);
  auto c = randomCloud(100, 10.f, 3);
  c[50] = Eigen::Vector3f(400.f, 0.f, 0.f);  // 40,000 steps
  store.put(1, c);
  EXPECT_EQ(store.get(1), c);
  store.put(1, randomCloud(10, 1.f, 4));  // replaces
  EXPECT_EQ(store.get(1).size(), 10u);
}

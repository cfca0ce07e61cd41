#include "livo/import/lidar_models.hpp"

#include <cstdlib>
#include <optional>

namespace livo::import {

const std::vector<LidarModelFacts>& lidarModelFacts() {
  using F = LidarFamily;
  // Order matters where rings tie within a family: the first is the guess (OS1-128 for 128 beams).
  static const std::vector<LidarModelFacts> models = {
      {"VLP-16", 16, false, F::kVelodyne, 100.0, 0.03, "VLP-16 datasheet: 100 m, range accuracy +-3 cm"},
      {"VLP-32C", 32, false, F::kVelodyne, 200.0, 0.03, "VLP-32C datasheet: 200 m, range accuracy +-3 cm"},
      {"HDL-64E", 64, false, F::kVelodyne, 120.0, 0.02, "HDL-64E S2 datasheet: 120 m, accuracy < 2 cm"},
      {"OS1-16", 16, false, F::kOuster, 120.0, 0.03, "Ouster OS1 gen-1 datasheet: 120 m, precision about 1.5-5 cm"},
      {"OS1-64", 64, false, F::kOuster, 120.0, 0.02, "assumed: Ouster's OS1 class, about 120 m, a few cm of precision"},
      {"OS1-128", 128, false, F::kOuster, 120.0, 0.02,
       "assumed: Ouster's OS1 class, about 120 m, a few cm of precision"},
      {"OS0-128", 128, false, F::kOuster, 50.0, 0.02, "assumed: Ouster's OS0 class, about 50 m, a few cm of precision"},
      {"OS2-128", 128, false, F::kOuster, 240.0, 0.02,
       "assumed: Ouster's OS2 class, about 240 m, a few cm of precision"},
      {"hesai-xt32", 32, false, F::kHesai, 120.0, 0.01, "PandarXT-32 datasheet: 120 m, range accuracy +-1 cm"},
      {"livox-avia", 6, true, F::kLivox, 190.0, 0.02, "Livox Avia datasheet: 190 m at 10 %, precision 2 cm"},
      {"livox-mid360", 4, true, F::kLivox, 70.0, 0.02, "Livox Mid-360 datasheet: 70 m at 80 %, precision 2 cm"},
  };
  return models;
}

const LidarModelFacts* findLidarModel(const std::string& model) {
  for (const LidarModelFacts& f : lidarModelFacts())
    if (f.model == model) return &f;
  return nullptr;
}

LidarModelGuess guessLidarModel(int rings, bool solid_state, const std::string& layout,
                                const std::string& named_model) {
  LidarModelGuess g;
  if (const LidarModelFacts* named = findLidarModel(named_model)) {
    g.facts = named;
    g.exact = true;
    g.reason = "named by the input";
    return g;
  }
  // The family from the per-point time field the cloud carries (point_cloud2_conversion's layout).
  std::optional<LidarFamily> family;
  std::string family_reason;
  auto has = [&](const char* field) { return layout.find(std::string(" ") + field + "(") != std::string::npos; };
  if (solid_state || has("offset_time"))
    family = LidarFamily::kLivox, family_reason = "Livox layout";
  else if (has("t"))
    family = LidarFamily::kOuster, family_reason = "Ouster time layout (t)";
  else if (has("timestamp"))
    family = LidarFamily::kHesai, family_reason = "Hesai time layout (timestamp)";
  else if (has("time"))
    family = LidarFamily::kVelodyne, family_reason = "Velodyne time layout (time)";
  // Exact ring count in the family, else exact ring count in any family (spinning or not as
  // seen), else the nearest ring count.
  const LidarModelFacts* best = nullptr;
  int best_score = 1 << 30;
  for (const LidarModelFacts& f : lidarModelFacts()) {
    int score = std::abs(f.rings - rings) * 4;
    if (family && f.family != *family) score += 2;
    if (f.solid_state != solid_state) score += 1000;
    if (score < best_score) best = &f, best_score = score;
  }
  g.facts = best;
  g.exact = best->rings == rings && (!family || best->family == *family);
  g.reason = std::to_string(rings) + (solid_state ? " scan lines" : " rings") +
             (family_reason.empty() ? "" : ", " + family_reason);
  if (!g.exact) g.reason += "; no known model fits exactly, the nearest is named";
  return g;
}

}  // namespace livo::import

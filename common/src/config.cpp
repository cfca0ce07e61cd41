#include "livo/config.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>

namespace livo {

const std::vector<std::string> kConfigSections = {"rig",       "sim",      "bus",         "playback",  "lio",
                                                  "lio_graph", "vio",      "vio_feature", "loop",      "colour",
                                                  "octomap",   "pipeline", "evaluate",    "ros_bridge"};

namespace {

size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::string describe(const YAML::Node& n) {
  if (n.IsScalar()) return "'" + n.Scalar() + "'";
  if (n.IsSequence()) return "a list of " + std::to_string(n.size());
  if (n.IsMap()) return "a map";
  return "nothing";
}

}  // namespace

namespace {

std::string readFile(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw ConfigError(file + ": cannot open config file");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

YAML::Node parseRoot(const std::string& yaml, const std::string& name) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    throw ConfigError(name + ": invalid YAML at line " + std::to_string(e.mark.line + 1) + ", column " +
                      std::to_string(e.mark.column + 1) + ": " + e.msg);
  }
  if (!root.IsNull() && !root.IsMap()) throw ConfigError(name + ": the top level must be a map of sections");
  return root;
}

/// `over` merged into a copy of `base` (Config::load with overlays).
YAML::Node merged(const YAML::Node& base, const YAML::Node& over) {
  if (!base.IsDefined() || !base.IsMap() || !over.IsMap()) return YAML::Clone(over);
  YAML::Node out = YAML::Clone(base);
  for (const auto& kv : over) {
    const std::string key = kv.first.as<std::string>();
    out[key] = merged(base[key], kv.second);
  }
  return out;
}

/// The root of `file` with `overlays` merged over it; *name gets "file + overlay + ...".
YAML::Node loadMerged(const std::string& file, const std::vector<std::string>& overlays, std::string* name) {
  YAML::Node root = parseRoot(readFile(file), file);
  *name = file;
  for (const std::string& overlay : overlays) {
    const YAML::Node over = parseRoot(readFile(overlay), overlay);
    if (!over.IsNull()) root = merged(root, over);  // an empty overlay changes nothing
    *name += " + " + overlay;
  }
  return root;
}

}  // namespace

Config Config::load(const std::string& file) { return load(file, {}); }

Config Config::load(const std::string& file, const std::vector<std::string>& overlays) {
  auto state = std::make_shared<State>();
  YAML::Node root = loadMerged(file, overlays, &state->file);
  return Config(root, state, "");
}

std::string Config::mergedText(const std::string& file, const std::vector<std::string>& overlays) {
  std::string name;
  const YAML::Node root = loadMerged(file, overlays, &name);
  YAML::Emitter out;
  out.SetSeqFormat(YAML::Flow);
  out << root;
  return std::string(out.c_str()) + "\n";
}

Config Config::fromString(const std::string& yaml, const std::string& name) {
  auto state = std::make_shared<State>();
  state->file = name;
  return Config(parseRoot(yaml, name), state, "");
}

Config::Config(const YAML::Node& node, std::shared_ptr<State> state, std::string path)
    : node_(std::make_shared<const YAML::Node>(node)), state_(std::move(state)), path_(std::move(path)) {}

bool Config::isNull() const { return !*node_ || node_->IsNull(); }

std::string Config::where(const std::string& key) const { return state_->file + ": " + keyPath(key); }

YAML::Node Config::child(const std::string& key, bool required) const {
  state_->asked.insert(keyPath(key));
  if (*node_ && node_->IsMap()) {
    YAML::Node n = (*node_)[key];
    if (n && !n.IsNull()) {
      state_->used.insert(keyPath(key));
      return n;
    }
  }
  if (required) throw ConfigError(where(key) + ": missing required key");
  return YAML::Node(YAML::NodeType::Undefined);
}

bool Config::has(const std::string& key) const {
  return *node_ && node_->IsMap() && (*node_)[key] && !(*node_)[key].IsNull();
}

std::vector<std::string> Config::keys() const {
  std::vector<std::string> out;
  if (*node_ && node_->IsMap())
    for (const auto& kv : *node_) out.push_back(kv.first.as<std::string>());
  return out;
}

Config Config::section(const std::string& key) const {
  YAML::Node n = child(key, true);
  state_->used.erase(keyPath(key));  // a section is checked key by key, not taken whole
  state_->opened.insert(keyPath(key));
  if (!n.IsMap()) throw ConfigError(where(key) + ": expected a map, got " + describe(n));
  return Config(n, state_, keyPath(key));
}

Config Config::optionalSection(const std::string& key) const {
  YAML::Node n = child(key, false);
  if (!n) return Config(YAML::Node(YAML::NodeType::Null), state_, keyPath(key));
  state_->used.erase(keyPath(key));
  state_->opened.insert(keyPath(key));
  if (!n.IsMap()) throw ConfigError(where(key) + ": expected a map, got " + describe(n));
  return Config(n, state_, keyPath(key));
}

void Config::ignore(const std::string& key) const { state_->used.insert(keyPath(key)); }

void Config::collectUnused(const YAML::Node& n, const std::string& path, std::vector<std::string>* out) const {
  if (!n.IsMap()) return;
  for (const auto& kv : n) {
    const std::string k = kv.first.as<std::string>();
    const std::string p = path.empty() ? k : path + "." + k;
    if (state_->used.count(p)) continue;  // read or ignored whole
    if (kv.second.IsMap()) {
      // a section that was opened but has unread keys, or was never opened at all
      bool any_used = state_->opened.count(p) > 0;
      for (const auto& u : state_->used)
        if (u.compare(0, p.size() + 1, p + ".") == 0) any_used = true;
      if (any_used) {
        collectUnused(kv.second, p, out);
        continue;
      }
    }
    out->push_back(p);
  }
}

void Config::checkAllUsed() const {
  if (isNull()) return;
  std::vector<std::string> unused;
  collectUnused(*node_, path_, &unused);
  if (unused.empty()) return;
  std::string msg = state_->file + ": unknown key" + (unused.size() > 1 ? "s" : "") + ":";
  for (const auto& u : unused) {
    msg += " " + u;
    // suggest the closest key that was read, if it is a likely typo
    const std::string leaf = u.substr(u.rfind('.') == std::string::npos ? 0 : u.rfind('.') + 1);
    const std::string parent = u.size() > leaf.size() ? u.substr(0, u.size() - leaf.size()) : "";
    std::string best;
    size_t best_d = 3;
    for (const auto& used : state_->asked) {
      if (used.compare(0, parent.size(), parent) != 0) continue;
      const std::string cand = used.substr(parent.size());
      if (cand.find('.') != std::string::npos) continue;
      const size_t d = editDistance(leaf, cand);
      if (d < best_d) best_d = d, best = cand;
    }
    if (!best.empty()) msg += " (did you mean " + parent + best + "?)";
  }
  throw ConfigError(msg);
}

void Config::checkKeysIn(const std::vector<std::string>& allowed) const {
  for (const auto& k : keys()) {
    if (std::find(allowed.begin(), allowed.end(), k) == allowed.end()) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      throw ConfigError(where(k) + ": unknown section (expected one of: " + list + ")");
    }
  }
}

// ---- conversions ----------------------------------------------------------------------------

namespace {

template <class T>
T scalarAs(const Config& cfg, const YAML::Node& n, const std::string& key, const char* what) {
  if (!n.IsScalar()) throw ConfigError(cfg.where(key) + ": expected " + what + ", got " + describe(n));
  try {
    return n.as<T>();
  } catch (const YAML::Exception&) {
    throw ConfigError(cfg.where(key) + ": expected " + what + ", got " + describe(n));
  }
}

std::vector<double> numbers(const Config& cfg, const YAML::Node& n, const std::string& key, size_t expected) {
  if (!n.IsSequence() || (expected && n.size() != expected)) {
    throw ConfigError(cfg.where(key) + ": expected a list of " + (expected ? std::to_string(expected) + " " : "") +
                      "numbers, got " + describe(n));
  }
  std::vector<double> v;
  for (size_t i = 0; i < n.size(); ++i) {
    const double x = scalarAs<double>(cfg, n[i], key + "[" + std::to_string(i) + "]", "a number");
    if (!std::isfinite(x)) throw ConfigError(cfg.where(key) + "[" + std::to_string(i) + "]: not a finite number");
    v.push_back(x);
  }
  return v;
}

Eigen::Quaterniond quaternionFrom(const Config& cfg, const std::vector<double>& q, const std::string& key) {
  Eigen::Quaterniond out(q[0], q[1], q[2], q[3]);
  const double n = out.norm();
  if (std::abs(n - 1.0) > 1e-3)
    throw ConfigError(cfg.where(key) + ": quaternion [w, x, y, z] must have unit norm (norm " + std::to_string(n) +
                      ")");
  return out.normalized();
}

}  // namespace

template <>
bool Config::convert<bool>(const YAML::Node& n, const std::string& key) const {
  return scalarAs<bool>(*this, n, key, "true or false");
}
template <>
int Config::convert<int>(const YAML::Node& n, const std::string& key) const {
  return scalarAs<int>(*this, n, key, "an integer");
}
template <>
int64_t Config::convert<int64_t>(const YAML::Node& n, const std::string& key) const {
  return scalarAs<int64_t>(*this, n, key, "an integer");
}
template <>
double Config::convert<double>(const YAML::Node& n, const std::string& key) const {
  const double v = scalarAs<double>(*this, n, key, "a number");
  if (!std::isfinite(v)) throw ConfigError(where(key) + ": not a finite number");
  return v;
}
template <>
float Config::convert<float>(const YAML::Node& n, const std::string& key) const {
  return static_cast<float>(convert<double>(n, key));
}
template <>
std::string Config::convert<std::string>(const YAML::Node& n, const std::string& key) const {
  return scalarAs<std::string>(*this, n, key, "a string");
}
template <>
std::vector<double> Config::convert<std::vector<double>>(const YAML::Node& n, const std::string& key) const {
  return numbers(*this, n, key, 0);
}
template <>
std::vector<int> Config::convert<std::vector<int>>(const YAML::Node& n, const std::string& key) const {
  if (!n.IsSequence()) throw ConfigError(where(key) + ": expected a list of integers, got " + describe(n));
  std::vector<int> v;
  for (size_t i = 0; i < n.size(); ++i)
    v.push_back(scalarAs<int>(*this, n[i], key + "[" + std::to_string(i) + "]", "an integer"));
  return v;
}
template <>
std::vector<std::string> Config::convert<std::vector<std::string>>(const YAML::Node& n, const std::string& key) const {
  if (!n.IsSequence()) throw ConfigError(where(key) + ": expected a list of strings, got " + describe(n));
  std::vector<std::string> v;
  for (size_t i = 0; i < n.size(); ++i)
    v.push_back(scalarAs<std::string>(*this, n[i], key + "[" + std::to_string(i) + "]", "a string"));
  return v;
}
template <>
Eigen::Vector3d Config::convert<Eigen::Vector3d>(const YAML::Node& n, const std::string& key) const {
  const auto v = numbers(*this, n, key, 3);
  return Eigen::Vector3d(v[0], v[1], v[2]);
}
template <>
Eigen::Matrix3d Config::convert<Eigen::Matrix3d>(const YAML::Node& n, const std::string& key) const {
  const auto v = numbers(*this, n, key, 9);
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(v.data());
}
template <>
Eigen::Matrix4d Config::convert<Eigen::Matrix4d>(const YAML::Node& n, const std::string& key) const {
  const auto v = numbers(*this, n, key, 16);
  return Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(v.data());
}
template <>
Eigen::Quaterniond Config::convert<Eigen::Quaterniond>(const YAML::Node& n, const std::string& key) const {
  return quaternionFrom(*this, numbers(*this, n, key, 4), key);
}
template <>
Eigen::Isometry3d Config::convert<Eigen::Isometry3d>(const YAML::Node& n, const std::string& key) const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (n.IsSequence()) {
    const Eigen::Matrix4d M = convert<Eigen::Matrix4d>(n, key);
    const Eigen::Matrix3d R = M.topLeftCorner<3, 3>();
    if ((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-4 || R.determinant() < 0.0 ||
        (M.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-9)
      throw ConfigError(where(key) + ": the 4x4 matrix is not a rigid transform");
    T.linear() = Eigen::Quaterniond(R).normalized().toRotationMatrix();
    T.translation() = M.topRightCorner<3, 1>();
    return T;
  }
  if (!n.IsMap())
    throw ConfigError(where(key) + ": expected {translation, rotation|rpy_deg} or 16 numbers, got " + describe(n));
  const Config sub(n, state_, keyPath(key));
  T.translation() = sub.get<Eigen::Vector3d>("translation");
  const bool has_q = sub.has("rotation"), has_rpy = sub.has("rpy_deg");
  if (has_q == has_rpy) throw ConfigError(where(key) + ": give exactly one of rotation ([w, x, y, z]) or rpy_deg");
  if (has_q) {
    T.linear() = sub.get<Eigen::Quaterniond>("rotation").toRotationMatrix();
  } else {
    const Eigen::Vector3d rpy = sub.get<Eigen::Vector3d>("rpy_deg") * M_PI / 180.0;
    T.linear() =
        (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
            .toRotationMatrix();
  }
  sub.checkAllUsed();
  return T;
}

#define LIVO_CONFIG_FETCH(T)                                                \
  bool Config::fetch(const std::string& key, bool required, T& out) const { \
    const YAML::Node n = child(key, required);                              \
    if (!n) return false;                                                   \
    out = convert<T>(n, key);                                               \
    return true;                                                            \
  }
LIVO_CONFIG_VALUE_TYPES(LIVO_CONFIG_FETCH)
#undef LIVO_CONFIG_FETCH

}  // namespace livo

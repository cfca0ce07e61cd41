// YAML configuration with strict checking: a missing required key, a value of the wrong type or
// a key nobody reads is an error naming the file and the full key path.
//
//   livo::Config cfg = livo::Config::load("config/sim/room.yaml");
//   livo::Config lio = cfg.section("lio");
//   lio.read("max_iterations", opts.max_iterations);          // required
//   lio.readOptional("voxel_size", opts.voxel_size);           // keeps the struct's default
//   lio.checkAllUsed();                                        // unknown keys under lio.*
#pragma once

#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace YAML {
class Node;  // yaml-cpp stays inside config.cpp
}  // namespace YAML

namespace livo {

// The value types Config reads (see the end of this file), as an X-macro: X(T) for each.
// clang-format off
#define LIVO_CONFIG_VALUE_TYPES(X)                                                                          \
  X(bool) X(int) X(int64_t) X(double) X(float) X(std::string) X(std::vector<double>) X(std::vector<int>) \
  X(std::vector<std::string>) X(Eigen::Vector3d) X(Eigen::Matrix3d) X(Eigen::Matrix4d)                  \
  X(Eigen::Quaterniond) X(Eigen::Isometry3d)
// clang-format on

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Config {
 public:
  /// Parses a YAML file; throws ConfigError if it is missing or malformed.
  static Config load(const std::string& file);
  /// A file with overlay files merged over it in order: where both hold a map, the overlay's keys
  /// are merged into it one by one (recursively); any other value of the overlay (a number, a
  /// string, a list, null) replaces what was there. Messages name "file + overlay + ...".
  static Config load(const std::string& file, const std::vector<std::string>& overlays);
  /// The YAML text of `file` with `overlays` merged over it as load() does (livo-config merge).
  static std::string mergedText(const std::string& file, const std::vector<std::string>& overlays);
  /// Parses YAML text (tests, embedded defaults); `name` stands for the file in messages.
  static Config fromString(const std::string& yaml, const std::string& name = "<string>");

  /// A required nested map.
  Config section(const std::string& key) const;
  /// An optional nested map; an empty (null) config if absent.
  Config optionalSection(const std::string& key) const;
  bool has(const std::string& key) const;
  bool isNull() const;
  /// Keys of this map in file order.
  std::vector<std::string> keys() const;

  template <class T>
  void read(const std::string& key, T& value) const {
    fetch(key, /*required=*/true, value);
  }
  template <class T>
  bool readOptional(const std::string& key, T& value) const {
    return fetch(key, /*required=*/false, value);
  }
  template <class T>
  T get(const std::string& key) const {
    T v{};
    read(key, v);
    return v;
  }

  /// Marks a key (and everything under it) as handled without reading it.
  void ignore(const std::string& key) const;
  /// Throws ConfigError listing every key under this section that was never read.
  void checkAllUsed() const;
  /// Throws ConfigError if this map has a top-level key outside `allowed`.
  void checkKeysIn(const std::vector<std::string>& allowed) const;

  const std::string& file() const { return state_->file; }
  /// Dotted path of this section ("" for the root).
  const std::string& path() const { return path_; }
  std::string keyPath(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  /// "file: key.path: what" for error messages.
  std::string where(const std::string& key) const;

 private:
  struct State {
    std::string file;
    std::set<std::string> used;    // full key paths read or ignored
    std::set<std::string> opened;  // sections opened with section()/optionalSection()
    std::set<std::string> asked;   // every key path asked for, present or not (for suggestions)
  };
  Config(const YAML::Node& node, std::shared_ptr<State> state, std::string path);

  // One overload per supported value type (LIVO_CONFIG_VALUE_TYPES, defined in config.cpp): reads
  // `key` into `out` if present; a missing required key throws. Returns whether the key was present.
#define LIVO_CONFIG_FETCH(T) bool fetch(const std::string& key, bool required, T& out) const;
  LIVO_CONFIG_VALUE_TYPES(LIVO_CONFIG_FETCH)
#undef LIVO_CONFIG_FETCH

  YAML::Node child(const std::string& key, bool required) const;
  template <class T>
  T convert(const YAML::Node& n, const std::string& key) const;
  void collectUnused(const YAML::Node& n, const std::string& path, std::vector<std::string>* out) const;

  std::shared_ptr<const YAML::Node> node_;  // never null
  std::shared_ptr<State> state_;
  std::string path_;
};

// Supported value types (defined in config.cpp): bool, int, int64_t, double, float,
// std::string, std::vector<double|int|std::string>, Eigen::Vector3d, Eigen::Matrix3d (9 numbers,
// row-major), Eigen::Matrix4d (16 numbers, row-major), Eigen::Quaterniond ([w, x, y, z]),
// Eigen::Isometry3d ({translation: [x, y, z], rotation: [w, x, y, z]} or
// {translation: [...], rpy_deg: [roll, pitch, yaw]} or a 16-number row-major matrix).

/// Top-level sections a project config file may hold; each process reads those it needs.
extern const std::vector<std::string> kConfigSections;

}  // namespace livo

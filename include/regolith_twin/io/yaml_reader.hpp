// Typed access to a YAML mapping for scene files: numbers with ranges,
// integers, booleans, strings, choices, vectors, sub-mappings and the list of
// allowed keys, every error an InputError naming the file, the full dotted key
// and the allowed range. Used by the scenario reader and the scene kinds.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "regolith_twin/core/types.hpp"

namespace rt {

// The keys the readers ask for while a scene file is read on this thread,
// with what each expects: installed by `regolith_sim --list-keys`, which the
// input fuzzer (test/fuzz/input_fuzz.py) reads, so a new key is fuzzed
// without editing the test. Nested logs restore the outer one.
struct KeyUse {
  std::string path;  // dotted, list entries as [i]: walls[0].radius
  std::string kind;  // number, integer, bool, text, choice, vector, map
};

class KeyLog {
 public:
  KeyLog() : outer_(current()) { current() = this; }
  ~KeyLog() { current() = outer_; }
  KeyLog(const KeyLog&) = delete;
  KeyLog& operator=(const KeyLog&) = delete;
  static void note(const std::string& path, const char* kind) {
    KeyLog* l = current();
    if (!l) return;
    for (const KeyUse& k : l->keys_)
      if (k.path == path) return;
    l->keys_.push_back({path, kind});
  }
  const std::vector<KeyUse>& keys() const { return keys_; }

 private:
  static KeyLog*& current() {
    static thread_local KeyLog* log = nullptr;
    return log;
  }
  KeyLog* outer_;
  std::vector<KeyUse> keys_;
};


// Physical bounds of scene-file values (docs/scenes.md, "Input ranges"): far
// beyond any scene, yet small enough that their products stay finite and a
// run stays meaningful. A key with no narrower range of its own has these.
constexpr double kMaxSceneLength = 1e4;    // m: coordinates, sizes, distances
constexpr double kMaxSceneMass = 1e6;      // kg
constexpr double kMaxSceneStiffness = 1e12;  // N/m
constexpr double kMaxSceneDuration = 1e6;  // s
constexpr double kMaxSceneSpeed = 1e5;     // m/s (also m/s^2 for accelerations in vectors)

class YamlReader {
 public:
  static constexpr double kInf = std::numeric_limits<double>::infinity();

  explicit YamlReader(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw InputError(source_ + ": key '" + key + "': " + what);
  }

  // map[key], or an undefined node when map itself is absent or not a mapping.
  static YAML::Node get(const YAML::Node& map, const std::string& key) {
    if (!map || !map.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
    return map[key];
  }

  static std::string join(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }

  double number(const YAML::Node& node, const std::string& path, double lo, double hi, bool lo_open = false) const {
    KeyLog::note(path, "number");
    double v = 0;
    try {
      v = node.as<double>();
    } catch (const YAML::Exception&) {
      fail(path, "expected a number" + range_text(lo, hi, lo_open) + ", got '" + scalar_text(node) + "'");
    }
    if (!std::isfinite(v) && lo == -kInf && hi == kInf) fail(path, "value " + scalar_text(node) + " is not a finite number");
    if (!std::isfinite(v) || (lo_open ? !(v > lo) : !(v >= lo)) || !(v <= hi))
      fail(path, "value " + scalar_text(node) + " out of range (allowed" + range_text(lo, hi, lo_open) + ")");
    return v;
  }

  double number(const YAML::Node& map, const std::string& path, const std::string& key, double dflt, double lo,
                double hi, bool lo_open = false) const {
    KeyLog::note(join(path, key), "number");
    const YAML::Node n = get(map, key);
    if (!n) return dflt;
    return number(n, join(path, key), lo, hi, lo_open);
  }

  long integer(const YAML::Node& map, const std::string& path, const std::string& key, long dflt, long lo,
               long hi) const {
    KeyLog::note(join(path, key), "integer");
    const YAML::Node n = get(map, key);
    if (!n) return dflt;
    long v = 0;
    try {
      v = n.as<long>();
    } catch (const YAML::Exception&) {
      fail(join(path, key), "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                                "], got '" + scalar_text(n) + "'");
    }
    if (v < lo || v > hi)
      fail(join(path, key), "value " + std::to_string(v) + " out of range (allowed [" + std::to_string(lo) + ", " +
                                std::to_string(hi) + "])");
    return v;
  }

  bool boolean(const YAML::Node& map, const std::string& path, const std::string& key, bool dflt) const {
    KeyLog::note(join(path, key), "bool");
    const YAML::Node n = get(map, key);
    if (!n) return dflt;
    try {
      return n.as<bool>();
    } catch (const YAML::Exception&) {
      fail(join(path, key), "expected true or false, got '" + scalar_text(n) + "'");
    }
  }

  std::string text(const YAML::Node& map, const std::string& path, const std::string& key,
                   const std::string& dflt) const {
    KeyLog::note(join(path, key), "text");
    const YAML::Node n = get(map, key);
    if (!n) return dflt;
    if (!n.IsScalar()) fail(join(path, key), "expected a string");
    return n.as<std::string>();
  }

  std::string choice(const YAML::Node& map, const std::string& path, const std::string& key,
                     const std::string& dflt, const std::vector<std::string>& allowed) const {
    KeyLog::note(join(path, key), "choice");
    const std::string v = text(map, path, key, dflt);
    for (const auto& a : allowed)
      if (v == a) return v;
    std::string list;
    for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
    fail(join(path, key), "'" + v + "' is not one of: " + list);
  }

  Vec3 vec3(const YAML::Node& map, const std::string& path, const std::string& key, const Vec3& dflt,
            bool required = false) const {
    KeyLog::note(join(path, key), "vector");
    const YAML::Node n = get(map, key);
    if (!n) {
      if (required) fail(join(path, key), "missing (expected [x, y, z])");
      return dflt;
    }
    if (!n.IsSequence() || n.size() != 3) fail(join(path, key), "expected a list of three numbers [x, y, z]");
    Vec3 v;
    // Positions, directions, velocities, gravity, inertias: each component
    // within +-kMaxSceneLength (1e4), which holds every one of them.
    for (int i = 0; i < 3; ++i)
      v[i] = number(n[i], join(path, key) + "[" + std::to_string(i) + "]", -kMaxSceneLength, kMaxSceneLength);
    return v;
  }

  YAML::Node map(const YAML::Node& parent, const std::string& path, const std::string& key, bool required) const {
    KeyLog::note(join(path, key), "map");
    const YAML::Node n = get(parent, key);
    if (!n) {
      if (required) fail(join(path, key), "missing");
      return n;
    }
    if (!n.IsMap()) fail(join(path, key), "expected a mapping");
    return n;
  }

  // Unknown keys are refused, so typos do not silently fall back to defaults.
  void only(const YAML::Node& map, const std::string& path, const std::vector<std::string>& keys) const {
    if (!map || !map.IsMap()) return;
    for (const auto& kv : map) {
      if (!kv.first.IsScalar()) fail(join(path, "?"), "a key must be a plain name, not a list or mapping");
      const std::string k = kv.first.as<std::string>();
      bool ok = false;
      for (const auto& a : keys) ok = ok || a == k;
      if (!ok) {
        std::string list;
        for (const auto& a : keys) list += (list.empty() ? "" : ", ") + a;
        fail(join(path, k), "unknown key (allowed here: " + list + ")");
      }
    }
  }

  const std::string& source() const { return source_; }

  // A number as messages print it (6 significant digits).
  static std::string num_text(double v) {
    std::ostringstream os;
    os << v;
    return os.str();
  }

  // "list[0].name = 'a', list[1].name = 'b'" ("none" when empty): the entries
  // a reference may name, for the message of one that names none of them.
  static std::string entry_names(const std::string& list, const std::vector<std::string>& names) {
    std::string t;
    for (size_t k = 0; k < names.size(); ++k)
      t += (k ? ", " : "") + list + "[" + std::to_string(k) + "].name = '" + names[k] + "'";
    return t.empty() ? "none" : t;
  }

 private:
  static std::string scalar_text(const YAML::Node& n) {
    if (n.IsScalar()) return n.Scalar();
    std::ostringstream os;
    os << n;
    return os.str();
  }
  static std::string range_text(double lo, double hi, bool lo_open) {
    if (lo == -kInf && hi == kInf) return " (any finite number)";
    std::string s = " ";
    if (hi == kInf) return s + (lo_open ? "> " : ">= ") + num_text(lo);
    if (lo == -kInf) return s + "<= " + num_text(hi);
    return s + "in " + (lo_open ? "(" : "[") + num_text(lo) + ", " + num_text(hi) + "]";
  }

  std::string source_;
};

}  // namespace rt

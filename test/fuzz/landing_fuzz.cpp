// Fuzz target: the landing file as regolith_bag_outcome (src/ros/bag_outcome.cpp)
// and regolith_land read it: the document with `base:` and --set overrides,
// the `landing` block (scenes/landing/landing.hpp), then the scenario. The bag
// itself is read by rosbag and is not fuzzed here. Input: see
// rt::fuzz::write_documents.
#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <cstdint>

#include "fuzz_support.hpp"
#include "regolith_twin/io/scenario.hpp"
#include "regolith_twin/scenes/landing/landing.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<std::string> overrides;
  const std::string path =
      rt::fuzz::write_documents(std::string(reinterpret_cast<const char*>(data), size), overrides);
  try {
    YAML::Node root = rt::load_document(path, overrides);
    const rt::LandingSpec spec = rt::parse_landing(root["landing"], path);
    root.remove("landing");
    const rt::Scenario sc = rt::parse_scenario(root, path);
    rt::landing_gravity(spec);
  } catch (const rt::InputError&) {
  }
  return 0;
}

// Fuzz target: scenario files (scene/scenario.hpp) with `base:` inheritance
// and --set overrides. Input: see rt::fuzz::write_documents. An InputError is
// the expected answer to a bad file; anything else is a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_support.hpp"
#include "regolith_twin/io/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<std::string> overrides;
  const std::string path =
      rt::fuzz::write_documents(std::string(reinterpret_cast<const char*>(data), size), overrides);
  try {
    rt::load_scenario(path, overrides);
  } catch (const rt::InputError&) {
  }
  return 0;
}

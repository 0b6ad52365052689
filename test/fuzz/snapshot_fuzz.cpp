// Fuzz target: bed snapshots (scene/snapshot.hpp). Each input is read twice:
// as it is, and with its checksum (the last 8 bytes) recomputed, so that
// mutations reach the record checks behind the checksum.
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "fuzz_support.hpp"
#include "regolith_twin/core/hash.hpp"
#include "regolith_twin/io/snapshot.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string bytes(reinterpret_cast<const char*>(data), size);
  const auto file = rt::fuzz::scratch() / "fuzz.bed";
  for (int pass = 0; pass < 2; ++pass) {
    if (pass == 1) {
      if (bytes.size() < 8) break;
      const uint64_t sum = rt::fnv1a(bytes.data(), bytes.size() - 8);
      std::memcpy(bytes.data() + bytes.size() - 8, &sum, 8);
    }
    const std::string path = rt::fuzz::write(file, bytes);
    try {
      rt::is_snapshot(path);
      rt::read_snapshot(path);
    } catch (const rt::InputError&) {
    }
  }
  return 0;
}

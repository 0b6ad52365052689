// FNV-1a, 64 bit: checksums of checkpoint and snapshot files, keys of cached
// beds and the state hashes of the determinism tests.
#pragma once

#include <cstddef>
#include <cstdint>

namespace rt {

constexpr uint64_t kFnvOffset = 1469598103934665603ULL;

// Hash of n bytes at p, continuing from h.
inline uint64_t fnv1a(const void* p, size_t n, uint64_t h = kFnvOffset) {
  const unsigned char* c = static_cast<const unsigned char*>(p);
  for (size_t i = 0; i < n; ++i) {
    h ^= c[i];
    h *= 1099511628211ULL;
  }
  return h;
}

}  // namespace rt

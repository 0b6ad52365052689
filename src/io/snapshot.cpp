// Compact bed snapshots, float32 or float64 (see snapshot.hpp).
#include "regolith_twin/core/hold.hpp"
#include "regolith_twin/io/snapshot.hpp"

#include "regolith_twin/core/hash.hpp"
#include "regolith_twin/io/data_file.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>

namespace rt {
namespace {

constexpr char kMagic[8] = {'R', 'G', 'T', 'W', 'B', 'E', 'D', '1'};    // float32 records
constexpr char kMagic64[8] = {'R', 'G', 'T', 'W', 'B', 'E', 'D', '2'};  // float64 records

}  // namespace

void write_snapshot(const std::string& path, const Model& m, const State& s, bool include_fixed,
                    SnapshotPrecision precision) {
  const bool wide = precision == SnapshotPrecision::Float64;
  std::string buf(wide ? kMagic64 : kMagic, 8);
  uint64_t n = 0;
  for (int i = 0; i < m.n_grains; ++i) n += include_fixed || !held(m, i);
  buf.append(reinterpret_cast<const char*>(&n), sizeof n);
  for (int i = 0; i < m.n_grains; ++i) {
    if (!include_fixed && held(m, i)) continue;
    if (wide) {
      const double rec[4] = {s.pos[i].x(), s.pos[i].y(), s.pos[i].z(), m.grain_radius[i]};
      buf.append(reinterpret_cast<const char*>(rec), sizeof rec);
    } else {
      const float rec[4] = {float(s.pos[i].x()), float(s.pos[i].y()), float(s.pos[i].z()), float(m.grain_radius[i])};
      buf.append(reinterpret_cast<const char*>(rec), sizeof rec);
    }
  }
  const uint64_t sum = fnv1a(buf.data(), buf.size());
  buf.append(reinterpret_cast<const char*>(&sum), sizeof sum);
  write_file_replacing(path, buf, "snapshot", /*sync=*/true);
}

bool is_snapshot(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[8] = {};
  return in.read(head, 8) && (std::memcmp(head, kMagic, 8) == 0 || std::memcmp(head, kMagic64, 8) == 0);
}

std::vector<SnapshotGrain> read_snapshot(const std::string& path) {
  const std::string data = read_file_limited(path, kMaxSnapshotBytes, "bed snapshot");  // docs/files.md
  auto fail = [&](const std::string& what) { throw InputError(path + ": not a usable bed snapshot: " + what); };
  if (data.size() < 24 || (std::memcmp(data.data(), kMagic, 8) != 0 && std::memcmp(data.data(), kMagic64, 8) != 0))
    fail("wrong file type (no snapshot header)");
  const bool wide = std::memcmp(data.data(), kMagic64, 8) == 0;
  const uint64_t rec_size = wide ? 32 : 16;
  uint64_t n = 0, sum = 0;
  std::memcpy(&n, data.data() + 8, 8);
  if (n > (data.size() - 24) / rec_size || data.size() != 24 + rec_size * n)
    fail("truncated file (length does not match the grain count)");
  std::memcpy(&sum, data.data() + data.size() - 8, 8);
  if (fnv1a(data.data(), data.size() - 8) != sum) fail("checksum mismatch (corrupted file)");
  std::vector<SnapshotGrain> out(n);
  for (uint64_t i = 0; i < n; ++i) {
    if (wide) {
      double rec[4];
      std::memcpy(rec, data.data() + 16 + 32 * i, 32);
      out[i].pos = Vec3(rec[0], rec[1], rec[2]);
      out[i].radius = rec[3];
    } else {
      float rec[4];
      std::memcpy(rec, data.data() + 16 + 16 * i, 16);
      out[i].pos = Vec3(rec[0], rec[1], rec[2]);
      out[i].radius = rec[3];
    }
    if (!(out[i].radius > 0 && out[i].radius <= kMaxCoordinate) || !(out[i].pos.cwiseAbs().maxCoeff() <= kMaxCoordinate))
      fail("grain " + std::to_string(i) + " has an invalid radius or a position beyond 1e6 m");
  }
  return out;
}

}  // namespace rt

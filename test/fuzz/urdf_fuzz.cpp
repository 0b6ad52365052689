// Fuzz target: URDF bodies and their STL meshes (scene/urdf_body.hpp), merged
// and finalized (Bullet's mesh hierarchy included). Input: the URDF text, then
// parts after lines "<!--@mesh-->", written as mesh0.stl, mesh1.stl, ... beside it.
#include <cstddef>
#include <cstdint>

#include "fuzz_support.hpp"
#include "regolith_twin/io/urdf_body.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::vector<std::string> parts =
      rt::fuzz::split(std::string(reinterpret_cast<const char*>(data), size), "\n<!--@mesh-->\n");
  const auto dir = rt::fuzz::scratch() / "config";
  for (std::size_t k = 1; k < parts.size(); ++k)
    rt::fuzz::write(dir / ("mesh" + std::to_string(k - 1) + ".stl"), parts[k]);
  const std::string path = rt::fuzz::write(dir / "body.urdf", parts[0]);
  try {
    rt::load_urdf_body(path);
  } catch (const rt::InputError&) {
  }
  return 0;
}

// Fuzz target: STL meshes, binary and ASCII (rt::load_stl, scene/urdf_body.hpp).
#include <cstddef>
#include <cstdint>

#include "fuzz_support.hpp"
#include "regolith_twin/io/urdf_body.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = rt::fuzz::write(rt::fuzz::scratch() / "mesh.stl",
                                           std::string(reinterpret_cast<const char*>(data), size));
  try {
    rt::load_stl(path, rt::Vec3(1, -2, 0.5));
  } catch (const rt::InputError&) {
  }
  return 0;
}

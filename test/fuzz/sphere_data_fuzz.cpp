// Fuzz target: LAMMPS sphere data files (rt::read_sphere_data, scene/data_file.hpp).
#include <cstddef>
#include <cstdint>

#include "fuzz_support.hpp"
#include "regolith_twin/io/data_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = rt::fuzz::write(rt::fuzz::scratch() / "grains.data",
                                           std::string(reinterpret_cast<const char*>(data), size));
  try {
    rt::read_sphere_data(path);
  } catch (const rt::InputError&) {
  }
  return 0;
}

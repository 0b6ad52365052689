// The fuzzing corpus (test/fuzz/corpus/<target>/: seeds, inputs the fuzzer
// kept, and every input that once made a reader crash) replayed through the
// fuzz targets built with the ordinary compiler (docs/validation/reliability.md,
// "Fuzzing"): every input is read or refused with an InputError.
#include <gtest/gtest.h>

#include <cstdint>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

// Each target's LLVMFuzzerTestOneInput, renamed by CMakeLists.txt.
extern "C" {
int scenario_fuzz(const uint8_t*, size_t);
int landing_fuzz(const uint8_t*, size_t);
int urdf_fuzz(const uint8_t*, size_t);
int stl_fuzz(const uint8_t*, size_t);
int snapshot_fuzz(const uint8_t*, size_t);
int checkpoint_fuzz(const uint8_t*, size_t);
int sphere_data_fuzz(const uint8_t*, size_t);
}

namespace {

namespace fs = std::filesystem;

struct Target {
  const char* name;
  int (*one_input)(const uint8_t*, size_t);
};

class FuzzCorpus : public ::testing::TestWithParam<Target> {};

TEST_P(FuzzCorpus, EveryInputIsReadOrRefusedWithAnInputError) {
  const fs::path dir = fs::path(REGOLITH_FUZZ_ROOT) / "test" / "fuzz" / "corpus" / GetParam().name;
  ASSERT_TRUE(fs::is_directory(dir)) << dir;
  int inputs = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    std::ifstream in(entry.path(), std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    try {
      GetParam().one_input(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
    } catch (const std::exception& e) {
      ADD_FAILURE() << entry.path() << ": " << e.what();
    } catch (...) {
      ADD_FAILURE() << entry.path() << ": an exception that is not a std::exception";
    }
    ++inputs;
  }
  EXPECT_GT(inputs, 0) << dir;
  RecordProperty("inputs", inputs);
}

INSTANTIATE_TEST_SUITE_P(Readers, FuzzCorpus,
                         ::testing::Values(Target{"scenario", scenario_fuzz}, Target{"landing", landing_fuzz},
                                           Target{"urdf", urdf_fuzz}, Target{"stl", stl_fuzz},
                                           Target{"snapshot", snapshot_fuzz},
                                           Target{"checkpoint", checkpoint_fuzz},
                                           Target{"sphere_data", sphere_data_fuzz}),
                         [](const ::testing::TestParamInfo<Target>& p) { return std::string(p.param.name); });

}  // namespace

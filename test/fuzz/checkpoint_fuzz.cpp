// Fuzz target: checkpoints (scene/checkpoint.hpp) of the scene
// test/fuzz/checkpoint_scene.yaml (grains, walls, a body, sleep, the stiffness
// schedule and free flight). Each input is read twice: as it is, and with its
// checksum (the last 8 bytes) recomputed, so that mutations reach the parser
// and the state checks behind the checksum. A state that is accepted is
// stepped once (a guard may stop it: BlowUpError).
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "fuzz_support.hpp"
#include "regolith_twin/core/hash.hpp"
#include "regolith_twin/core/step.hpp"
#include "regolith_twin/io/checkpoint.hpp"
#include "regolith_twin/io/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const rt::Scenario sc =
      rt::load_scenario((rt::fuzz::repo_root() / "test" / "fuzz" / "checkpoint_scene.yaml").string());
  std::string bytes(reinterpret_cast<const char*>(data), size);
  for (int pass = 0; pass < 2; ++pass) {
    if (pass == 1) {
      if (bytes.size() < 8) break;
      const uint64_t sum = rt::fnv1a(bytes.data(), bytes.size() - 8);
      std::memcpy(bytes.data() + bytes.size() - 8, &sum, 8);
    }
    try {
      rt::State s = rt::state_from_checkpoint("fuzz.ckpt", bytes, sc.model);
      rt::step(sc.model, s);
    } catch (const rt::InputError&) {
    } catch (const rt::BlowUpError&) {  // a guard of the step (docs/model.md §13)
    }
  }
  return 0;
}

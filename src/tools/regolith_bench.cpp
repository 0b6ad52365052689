// regolith_bench: timed throughput of a scenario from a settled state.
//   regolith_bench SCENARIO.yaml [--settle-steps N] [--cache DIR] [--threads 1,2]
//                  [--blocks 3] [--block-steps 2000] [--label NAME] [--dump FILE] [--set k=v]...
// Settles the scene once (cached as a checkpoint), then for each thread count
// restarts from the settled state and times blocks of steps, printing
//   RESULT engine=regolith label=L threads=T block=B steps=S seconds=X particle_steps_per_s=P cpu_seconds=C rebuilds=R
// and writes the final state as a LAMMPS-style dump for the physics check.
#include <sys/stat.h>

#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "regolith_twin/core/energy.hpp"
#include "regolith_twin/core/step.hpp"
#include "regolith_twin/io/checkpoint.hpp"
#include "regolith_twin/io/scenario.hpp"

namespace {

void write_dump(const std::string& path, const rt::Model& m, const rt::State& s) {
  std::ofstream f(path);
  f.precision(10);
  f << "ITEM: TIMESTEP\n" << s.step << "\nITEM: NUMBER OF ATOMS\n" << m.n_grains << "\n";
  f << "ITEM: BOX BOUNDS ff ff ff\n0 1\n0 1\n0 1\n";
  f << "ITEM: ATOMS id x y z radius vx vy vz omegax omegay omegaz\n";
  for (int i = 0; i < m.n_grains; ++i) {
    const auto &p = s.pos[i], &v = s.vel[i], &w = s.omega[i];
    f << i + 1 << ' ' << p.x() << ' ' << p.y() << ' ' << p.z() << ' ' << m.grain_radius[i] << ' ' << v.x() << ' '
      << v.y() << ' ' << v.z() << ' ' << w.x() << ' ' << w.y() << ' ' << w.z() << '\n';
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::string file, cache = "bench/.cache/regolith", label = "default", dump;
  std::vector<std::string> overrides;
  std::vector<int> threads = {1, 2};
  long settle_steps = 30000, block_steps = 2000;
  int blocks = 3;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto val = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "regolith_bench: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--settle-steps") settle_steps = std::atol(val().c_str());
    else if (a == "--cache") cache = val();
    else if (a == "--blocks") blocks = std::atoi(val().c_str());
    else if (a == "--block-steps") block_steps = std::atol(val().c_str());
    else if (a == "--label") label = val();
    else if (a == "--dump") dump = val();
    else if (a == "--set") overrides.push_back(val());
    else if (a == "--threads") {
      threads.clear();
      std::stringstream ss(val());
      for (std::string t; std::getline(ss, t, ',');) threads.push_back(std::atoi(t.c_str()));
    } else if (file.empty() && a[0] != '-') file = a;
    else {
      std::fprintf(stderr, "regolith_bench: unknown argument '%s'\n", a.c_str());
      return 2;
    }
  }
  if (file.empty()) {
    std::fprintf(stderr, "usage: regolith_bench SCENARIO.yaml [options] (see the source header)\n");
    return 2;
  }
  try {
    const rt::Scenario sc = rt::load_scenario(file, overrides);
    const rt::Model& m = sc.model;
    ::mkdir(cache.c_str(), 0755);
    const std::string ckpt = cache + "/" + sc.name + "_settled_" + std::to_string(settle_steps) + ".ckpt";
    rt::State settled;
    bool have = false;
    try {
      settled = rt::load_checkpoint(ckpt, m);
      have = true;
    } catch (const rt::InputError&) {
    }
    if (!have) {
      std::fprintf(stderr, "regolith_bench: settling %s for %ld steps (cached in %s)\n", sc.name.c_str(), settle_steps,
                   ckpt.c_str());
      settled = sc.initial;
      const auto t0 = std::chrono::steady_clock::now();
      for (long k = 0; k < settle_steps; ++k) rt::step(m, settled);
      const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::printf("SETTLE engine=regolith steps=%ld seconds=%.2f particle_steps_per_s=%.4g\n", settle_steps, sec,
                  double(settle_steps) * m.n_grains / sec);
      rt::save_checkpoint(ckpt, m, settled);
    }
    rt::State s;
    for (int t : threads) {
#ifdef _OPENMP
      omp_set_num_threads(t);
#endif
      s = settled;
      s.rebuild_requested = true;  // lists for this model's skin, from the settled positions
      rt::step(m, s);  // warm caches and first-touch pages outside the timing
      for (int b = 1; b <= blocks; ++b) {
        const auto t0 = std::chrono::steady_clock::now();
        const std::clock_t c0 = std::clock();
        const long rebuilds0 = s.rebuilds;
        for (long k = 0; k < block_steps; ++k) rt::step(m, s);
        const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const double cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;
        std::printf("RESULT engine=regolith label=%s threads=%d block=%d steps=%ld seconds=%.4f "
                    "particle_steps_per_s=%.4g cpu_seconds=%.4f rebuilds=%ld\n",
                    label.c_str(), t, b, block_steps, sec, double(block_steps) * m.n_grains / sec, cpu,
                    s.rebuilds - rebuilds0);
        std::fflush(stdout);
      }
    }
    const rt::Energy e = rt::energy(m, s);
    std::printf("STATE engine=regolith label=%s rebuilds=%ld contacts=%ld wall_contacts=%ld coordination=%.4f ke=%.6g\n",
                label.c_str(), s.rebuilds, s.stats.contacts, s.stats.wall_contacts, rt::coordination_number(m, s),
                e.translational);
    if (!dump.empty()) write_dump(dump, m, s);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "regolith_bench: error: %s\n", e.what());
    return 1;
  }
}

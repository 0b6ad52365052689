// regolith_sim: run any scenario YAML headless.
//   regolith_sim SCENARIO.yaml [--out DIR] [--threads N] [--set key=value ...] [--quiet]
// Exit codes: 0 finished, 2 bad input, 3 numerical blow-up (outputs so far kept), 1 other error.
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "regolith_twin/observe/runner.hpp"
#include "regolith_twin/scene/checkpoint.hpp"
#include "regolith_twin/scene/snapshot.hpp"

namespace {

void usage(std::FILE* f) {
  std::fprintf(f,
               "usage: regolith_sim SCENARIO.yaml [--out DIR] [--threads N] [--set key=value]... [--quiet]\n"
               "  --out DIR       write series.csv, summary.json, final_grains.txt to DIR (default out/<name>)\n"
               "  --threads N     OpenMP threads (default: all cores)\n"
               "  --set k=v       override a scenario key, e.g. --set contact.steps_per_contact=60\n"
               "  --snapshot F    also write the final grains as a compact bed snapshot F (float32)\n"
               "  --checkpoint F  also write the exact final state (with contact history) to F\n"
               "  --stage-snapshots  also write DIR/<stage>.bed after every stage (restart points)\n"
               "  --quiet         no progress lines\n");
}

}  // namespace

int main(int argc, char** argv) {
  std::string file, out, snapshot, checkpoint;
  std::vector<std::string> overrides;
  int threads = 0;
  bool quiet = false, stage_snapshots = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](const char* name) -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "regolith_sim: %s needs a value\n", name);
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--out") {
      out = value("--out");
    } else if (a == "--threads") {
      const std::string v = value("--threads");
      char* end = nullptr;
      threads = int(std::strtol(v.c_str(), &end, 10));
      if (*end || threads < 1 || threads > 256) {
        std::fprintf(stderr, "regolith_sim: --threads '%s': expected an integer in [1, 256]\n", v.c_str());
        return 2;
      }
    } else if (a == "--set") {
      overrides.push_back(value("--set"));
    } else if (a == "--snapshot") {
      snapshot = value("--snapshot");
    } else if (a == "--checkpoint") {
      checkpoint = value("--checkpoint");
    } else if (a == "--stage-snapshots") {
      stage_snapshots = true;
    } else if (a == "--quiet") {
      quiet = true;
    } else if (a == "-h" || a == "--help") {
      usage(stdout);
      return 0;
    } else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "regolith_sim: unknown option '%s'\n", a.c_str());
      usage(stderr);
      return 2;
    } else if (file.empty()) {
      file = a;
    } else {
      std::fprintf(stderr, "regolith_sim: only one scenario file may be given\n");
      return 2;
    }
  }
  if (file.empty()) {
    usage(stderr);
    return 2;
  }
#ifdef _OPENMP
  if (threads > 0) omp_set_num_threads(threads);
  threads = omp_get_max_threads();
#else
  threads = 1;
#endif
  try {
    rt::Scenario sc = rt::load_scenario(file, overrides);
    if (out.empty()) out = "out/" + sc.name;
    for (const auto& w : sc.warnings) std::fprintf(stderr, "regolith_sim: warning: %s\n", w.c_str());
    if (!quiet) {
      std::fprintf(stderr, "[%s] %d grains, %zu walls, dt = %.4g s, k_n = %.4g N/m, %d thread(s)\n", sc.name.c_str(),
                   sc.model.n_grains, sc.model.walls.size(), sc.model.dt, sc.model.kn, threads);
      for (const auto& r : sc.resolution)
        std::fprintf(stderr, "[%s]   %s: %.1f steps per contact\n", sc.name.c_str(), r.label.c_str(), r.steps);
    }
    rt::RunOptions opt;
    opt.out_dir = out;
    opt.progress_every = quiet ? 0 : 2.0;
    opt.threads = threads;
    opt.stage_snapshots = stage_snapshots;
    rt::State s = sc.initial;
    const rt::RunReport rep = rt::run_scenario(sc, s, opt);
    if (rep.status != "ok") {
      std::fprintf(stderr, "regolith_sim: %s\nregolith_sim: outputs written so far are in %s/\n", rep.message.c_str(),
                   out.c_str());
      return 3;
    }
    if (!snapshot.empty()) {
      rt::write_snapshot(snapshot, sc.model, s);
      std::printf("snapshot:    %s (%d grains)\n", snapshot.c_str(), sc.model.n_grains);
    }
    if (!checkpoint.empty()) {
      rt::save_checkpoint(checkpoint, sc.model, s);
      std::printf("checkpoint:  %s\n", checkpoint.c_str());
    }
    std::printf("finished %s: %ld steps, %.4g s simulated in %.3g s wall (%.3g grain-steps/s)\n", sc.name.c_str(),
                rep.steps, rep.sim_time, rep.wall_seconds, double(rep.steps) * sc.model.n_grains / rep.wall_seconds);
    std::printf("summary:     %s/summary.json\ntime series: %s/series.csv\nfinal state: %s/final_grains.txt\n",
                out.c_str(), out.c_str(), out.c_str());
    return 0;
  } catch (const rt::InputError& e) {
    std::fprintf(stderr, "regolith_sim: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "regolith_sim: error: %s\n", e.what());
    return 1;
  }
}

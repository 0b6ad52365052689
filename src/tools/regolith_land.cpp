// regolith_land: one lander touchdown on a prepared bed (SCENARIOS.md A).
//   regolith_land LANDING.yaml [--out DIR] [--threads N] [--set key=value ...] [--cache DIR] [--quiet]
// The file is a scenario (materials, walls, bodies, grains from a bed
// snapshot) plus a `landing:` block. The bed is first relaxed under the scene
// gravity with the lander parked away; the relaxed state is cached as an
// exact checkpoint, so later landings on the same bed start from it
// bit-identically. Exit codes: 0 done, 2 bad input, 3 numerical blow-up, 1 other.
#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "regolith_twin/observe/landing_scene.hpp"
#include "regolith_twin/observe/series.hpp"
#include "regolith_twin/scene/scenario.hpp"

namespace {

void usage(std::FILE* f) {
  std::fprintf(f,
               "usage: regolith_land LANDING.yaml [--out DIR] [--threads N] [--set key=value]... [--cache DIR] [--quiet]\n"
               "  --out DIR     summary.json, series.csv, surface.csv (default out/<name>)\n"
               "  --set k=v     override a key, e.g. --set landing.angle_deg=60 --set landing.attitude=Flat\n"
               "  --cache DIR   where relaxed beds are kept (default $REGOLITH_CACHE or ~/.cache/regolith_twin)\n"
               "  --threads N   OpenMP threads (default: all cores)\n");
}

}  // namespace

int main(int argc, char** argv) {
  std::string file, out, cache;
  std::vector<std::string> overrides;
  int threads = 0;
  bool quiet = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](const char* name) -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "regolith_land: %s needs a value\n", name);
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--out") out = value("--out");
    else if (a == "--cache") cache = value("--cache");
    else if (a == "--set") overrides.push_back(value("--set"));
    else if (a == "--quiet") quiet = true;
    else if (a == "--threads") {
      const std::string v = value("--threads");
      char* end = nullptr;
      threads = int(std::strtol(v.c_str(), &end, 10));
      if (*end || threads < 1 || threads > 256) {
        std::fprintf(stderr, "regolith_land: --threads '%s': expected an integer in [1, 256]\n", v.c_str());
        return 2;
      }
    } else if (a == "-h" || a == "--help") {
      usage(stdout);
      return 0;
    } else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "regolith_land: unknown option '%s'\n", a.c_str());
      usage(stderr);
      return 2;
    } else if (file.empty()) file = a;
    else {
      std::fprintf(stderr, "regolith_land: only one landing file may be given\n");
      return 2;
    }
  }
  if (file.empty()) {
    usage(stderr);
    return 2;
  }
#ifdef _OPENMP
  if (threads > 0) omp_set_num_threads(threads);
#endif
  try {
    rt::LandingSetupOptions so;
    so.cache_dir = cache;
    so.quiet = quiet;
    if (out.empty()) out = "out/" + rt::load_document(file, overrides)["name"].as<std::string>("scenario");
    rt::make_dirs(out);
    so.relax_out = out + "/bed_relax";
    rt::LandingScene ls = rt::prepare_landing(file, overrides, so);
    rt::State s = ls.start;
    rt::LandingOptions lo;
    lo.out_dir = out;
    lo.progress_every = quiet ? 0 : 2.0;
    const rt::LandingOutcome o = rt::run_landing(ls.sc.model, s, ls.lander, ls.run_spec, lo);
    rt::write_surface(out + "/surface.csv", ls.sc.model, s, ls.run_spec, 0.01);
    int nthreads = 0;
#ifdef _OPENMP
    nthreads = omp_get_max_threads();
#endif
    rt::write_landing_summary(out + "/summary.json", ls, o, nthreads);
    if (o.status != "ok") {
      std::fprintf(stderr, "regolith_land: %s\nregolith_land: outputs written so far are in %s/\n", o.message.c_str(),
                   out.c_str());
      return 3;
    }
    std::printf("landing %s: %s, speed ratio %.3f, collision %.3g s, penetration %.3g m, travel %.3g m (%.0f s wall)\n",
                ls.sc.name.c_str(), o.lifted_off ? "lifted off" : "no lift-off", o.speed_ratio, o.collision_duration,
                o.max_penetration, o.travel_distance, o.wall_seconds);
    std::printf("summary:     %s/summary.json\ntime series: %s/series.csv\nsurface:     %s/surface.csv\n", out.c_str(),
                out.c_str(), out.c_str());
    return 0;
  } catch (const rt::BlowUpError& e) {
    std::fprintf(stderr, "regolith_land: %s\n", e.what());
    return 3;
  } catch (const rt::InputError& e) {
    std::fprintf(stderr, "regolith_land: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "regolith_land: error: %s\n", e.what());
    return 1;
  }
}

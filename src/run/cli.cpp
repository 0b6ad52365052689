// The command-line tools' shared main (see cli.hpp).
#include "regolith_twin/run/cli.hpp"

#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "regolith_twin/run/scene.hpp"
#include "regolith_twin/run/series.hpp"
#include "regolith_twin/io/checkpoint.hpp"
#include "regolith_twin/io/data_file.hpp"
#include "regolith_twin/io/snapshot.hpp"
#include "regolith_twin/io/yaml_reader.hpp"

namespace rt {
namespace {

void usage(std::FILE* f, const char* tool) {
  std::fprintf(f,
               "usage: %s SCENE.yaml [--out DIR] [--threads N] [--set key=value]... [--cache DIR] [--quiet]\n"
               "  --out DIR       results (summary.json, series.csv and the scene's own files; default out/<name>)\n"
               "  --threads N     OpenMP threads (default: all cores)\n"
               "  --set k=v       override a key, e.g. --set contact.steps_per_contact=60 or --set landing.angle_deg=60\n"
               "  --profile P     named settings applied before any --set: profiles/P.yaml beside the scene file,\n"
               "                  or a file path (e.g. --profile preview: faster, less accurate; docs/bench/b4_landing.md)\n"
               "  --cache DIR     where relaxed beds are kept (default $REGOLITH_CACHE or ~/.cache/regolith_twin)\n"
               "  --relaxed-bed F start from this relaxed bed (a checkpoint of the same grains, e.g. a cache file)\n"
               "  --snapshot F    also write the final grains as a compact bed snapshot F (float32)\n"
               "  --snapshot-precision 32|64  positions of the snapshot in float32 (default) or float64 (stiff beds)\n"
               "  --checkpoint F  also write the exact final state (with contact history) to F\n"
               "  --stage-snapshots  also write DIR/<stage>.bed after every stage (restart points)\n"
               "  --max-steps N   refuse a run longer than N steps (default %ld: a run past it stops with status\n"
               "                  step_limit); raise it for a run that needs more\n"
               "  --list-keys     print every key the scene's readers ask for (key and kind) and exit\n"
               "  --quiet         no progress lines\n"
               "scene kinds: a plain scenario, or a file with one of these blocks:",
               tool, kDefaultMaxSteps);
  for (const std::string& k : scene_kind_names()) std::fprintf(f, " %s:", k.c_str());
  std::fprintf(f, "\n");
}

struct Args {
  std::string file, out, cache, snapshot, checkpoint, profile, relaxed_bed;
  std::vector<std::string> overrides;
  int threads = 0;
  long max_steps = kDefaultMaxSteps;
  bool quiet = false, stage_snapshots = false, list_keys = false;
  SnapshotPrecision precision = SnapshotPrecision::Float32;
};

// Returns -1 when the arguments are good, else the exit code.
int parse(int argc, char** argv, const char* tool, Args& a) {
  for (int i = 1; i < argc; ++i) {
    const std::string o = argv[i];
    auto value = [&](std::string& into) {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s: %s needs a value\n", tool, o.c_str());
        return false;
      }
      into = argv[++i];
      return true;
    };
    std::string v;
    if (o == "--out" || o == "--cache" || o == "--relaxed-bed" || o == "--snapshot" || o == "--checkpoint" || o == "--set" ||
        o == "--threads" || o == "--snapshot-precision" || o == "--profile" || o == "--max-steps") {
      if (!value(v)) return 2;
      if (o == "--out") a.out = v;
      else if (o == "--cache") a.cache = v;
      else if (o == "--relaxed-bed") a.relaxed_bed = v;
      else if (o == "--snapshot") a.snapshot = v;
      else if (o == "--checkpoint") a.checkpoint = v;
      else if (o == "--set") a.overrides.push_back(v);
      else if (o == "--profile") a.profile = v;
      else if (o == "--max-steps") {
        char* end = nullptr;
        errno = 0;
        const double n = std::strtod(v.c_str(), &end);
        if (v.empty() || *end || errno || !(n >= 1 && n <= 1e15) || n != std::floor(n)) {
          std::fprintf(stderr, "%s: --max-steps '%s': expected a whole number in [1, 1e15]\n", tool, v.c_str());
          return 2;
        }
        a.max_steps = long(n);
      }
      else if (o == "--snapshot-precision") {
        if (v != "32" && v != "64") {
          std::fprintf(stderr, "%s: --snapshot-precision '%s': expected 32 or 64\n", tool, v.c_str());
          return 2;
        }
        a.precision = v == "64" ? SnapshotPrecision::Float64 : SnapshotPrecision::Float32;
      }
      else {
        char* end = nullptr;
        a.threads = int(std::strtol(v.c_str(), &end, 10));
        if (*end || a.threads < 1 || a.threads > 256) {
          std::fprintf(stderr, "%s: --threads '%s': expected an integer in [1, 256]\n", tool, v.c_str());
          return 2;
        }
      }
    } else if (o == "--quiet") {
      a.quiet = true;
    } else if (o == "--list-keys") {
      a.list_keys = true;
    } else if (o == "--stage-snapshots") {
      a.stage_snapshots = true;
    } else if (o == "-h" || o == "--help") {
      usage(stdout, tool);
      return 0;
    } else if (!o.empty() && o[0] == '-') {
      std::fprintf(stderr, "%s: unknown option '%s'\n", tool, o.c_str());
      usage(stderr, tool);
      return 2;
    } else if (a.file.empty()) {
      a.file = o;
    } else {
      std::fprintf(stderr, "%s: only one scene file may be given\n", tool);
      return 2;
    }
  }
  if (a.file.empty()) {
    usage(stderr, tool);
    return 2;
  }
  return -1;
}

// A profile is a YAML map of dotted keys to values (config/profiles/*.yaml),
// turned into --set overrides that come before the command line's own.
std::vector<std::string> profile_overrides(const std::string& name, const std::string& scene_file) {
  std::string path = name;
  if (name.find('/') == std::string::npos && name.find(".yaml") == std::string::npos) {
    const std::size_t slash = scene_file.rfind('/');
    path = (slash == std::string::npos ? std::string() : scene_file.substr(0, slash + 1)) + "profiles/" + name +
           ".yaml";
  }
  YAML::Node doc;
  try {
    // Size and nesting bounded as for scenario files (docs/files.md, "Loaded files").
    const std::string text = read_file_limited(path, kMaxYamlBytes, "profile");
    check_yaml_nesting(path, text);
    doc = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError("--profile " + name + ": cannot read " + path + ": " + e.msg);
  } catch (const InputError& e) {
    throw InputError("--profile " + name + ": " + e.what());
  }
  if (!doc.IsMap()) throw InputError(path + ": a profile is a map of keys to values (e.g. sleep.enabled: true)");
  std::vector<std::string> out;
  for (const auto& kv : doc) {
    if (!kv.second.IsScalar())
      throw InputError(path + ": " + kv.first.as<std::string>() + ": expected a single value");
    out.push_back(kv.first.as<std::string>() + "=" + kv.second.as<std::string>());
  }
  return out;
}

}  // namespace

int run_cli(int argc, char** argv, const char* tool) {
  Args a;
  if (const int rc = parse(argc, argv, tool, a); rc >= 0) return rc;
  // A file grown past the size limit (ulimit -f) fails its write with EFBIG
  // and is reported naming it, like a full disk, instead of killing the
  // tool mid-write (docs/files.md, outputs).
  std::signal(SIGXFSZ, SIG_IGN);
#ifdef _OPENMP
  if (a.threads > 0) omp_set_num_threads(a.threads);
  const int threads = omp_get_max_threads();
#else
  const int threads = 1;
#endif
  try {
    if (!a.profile.empty()) {
      std::vector<std::string> o = profile_overrides(a.profile, a.file);
      o.insert(o.end(), a.overrides.begin(), a.overrides.end());
      a.overrides = std::move(o);
    }
    if (a.list_keys) {
      // Keys are noted as the readers ask for them, present or not; a scene
      // refused for its own values still lists the keys read before the error.
      KeyLog log;
      SceneOptions so;
      so.cache_dir = a.cache;
      so.quiet = true;
      so.max_steps = a.max_steps;
      std::string error;
      try {
        load_scene(a.file, a.overrides, so);
      } catch (const InputError& e) {
        error = e.what();
      }
      for (const KeyUse& k : log.keys()) std::printf("%s %s\n", k.path.c_str(), k.kind.c_str());
      if (!error.empty()) {
        std::fprintf(stderr, "%s: error: %s\n", tool, error.c_str());
        return 2;
      }
      return 0;
    }
    if (a.out.empty()) a.out = "out/" + load_document(a.file, a.overrides)["name"].as<std::string>("scenario");
    const OutputFolder out_folder(a.out);  // refused at once if in use or not writable
    if (!a.snapshot.empty()) check_writable(a.snapshot);
    if (!a.checkpoint.empty()) check_writable(a.checkpoint);
    SceneOptions so;
    so.cache_dir = a.cache;
    so.relaxed_bed = a.relaxed_bed;
    so.quiet = a.quiet;
    so.relax_out = a.out + "/bed_relax";
    so.max_steps = a.max_steps;
    std::unique_ptr<Scene> scene;
    try {
      scene = load_scene(a.file, a.overrides, so);
    } catch (const BlowUpError& e) {
      // A preparation run (a bed relaxation) that stopped: the folder still
      // gets a summary saying so, as a run that stops does.
      JsonObject j;
      j.str("status", dynamic_cast<const StepLimitError*>(&e) ? "step_limit" : "blow_up")
          .str("stage", "preparation")
          .str("file", a.file)
          .str("message", e.what());
      j.write(a.out + "/summary.json");
      throw;
    }
    Model m = scene->sc.model;
    State s = scene->start;
    SceneRunOptions ro;
    ro.out_dir = a.out;
    ro.progress_every = a.quiet ? 0 : 2.0;
    ro.stage_snapshots = a.stage_snapshots;
    ro.threads = threads;
    ro.max_steps = a.max_steps;
    std::unique_ptr<SceneRun> run;
    const RunReport rep = run_scene(*scene, m, s, ro, &run);
    if (rep.status != "ok") {
      std::fprintf(stderr, "%s: %s\n%s: outputs written so far are in %s/\n", tool, rep.message.c_str(), tool,
                   a.out.c_str());
      return 3;
    }
    if (!a.snapshot.empty()) {
      write_snapshot(a.snapshot, m, s, false, a.precision);
      std::printf("snapshot:    %s (%d grains)\n", a.snapshot.c_str(), m.n_grains);
    }
    if (!a.checkpoint.empty()) {
      save_checkpoint(a.checkpoint, m, s);
      std::printf("checkpoint:  %s\n", a.checkpoint.c_str());
    }
    std::printf("%s\n", run->result_line(m, s, rep).c_str());
    std::printf("%-12s %s\n", "scene kind:", scene->kind().c_str());
    for (const auto& [label, name] : run->files()) {
      const std::string l = label + ":";
      std::printf("%-12s %s/%s\n", l.c_str(), a.out.c_str(), name.c_str());
    }
    return 0;
  } catch (const BlowUpError& e) {
    std::fprintf(stderr, "%s: %s\n", tool, e.what());
    return 3;
  } catch (const InputError& e) {
    std::fprintf(stderr, "%s: error: %s\n", tool, e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", tool, e.what());
    return 1;
  }
}

}  // namespace rt

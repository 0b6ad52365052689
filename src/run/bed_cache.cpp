// Relax-once-and-cache beds (see bed_cache.hpp).
#include "regolith_twin/core/hold.hpp"
#include "regolith_twin/run/bed_cache.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "regolith_twin/core/hash.hpp"
#include "regolith_twin/run/series.hpp"
#include "regolith_twin/io/checkpoint.hpp"
#include "regolith_twin/run/scenario_kind.hpp"

namespace rt {
namespace {

// A cut (trim stage) removes grains: the model of the relaxed bed differs
// from the scenario's. Its grains and groups are kept beside the cached
// checkpoint ("<key>.grains") and put back into the scenario's model.
void save_grains(const std::string& path, const Scenario& sc) {
  std::ostringstream f;
  f.precision(17);
  const Model& m = sc.model;
  f << m.n_grains << ' ' << sc.groups.size() << '\n';
  for (int i = 0; i < m.n_grains; ++i)
    f << m.grain_radius[i] << ' ' << m.grain_material[i] << ' ' << int(held(m, i)) << '\n';
  for (const GrainGroup& g : sc.groups) f << g.name << ' ' << g.first << ' ' << g.count << '\n';
  write_file(path, f.str());
}

void load_grains(const std::string& path, Scenario& sc) {
  std::ifstream f(path);
  long n = -1, ng = -1;
  if (!(f >> n >> ng) || n < 0 || ng < 0 || n > 100000000 || ng > 100000)
    throw InputError(path + ": not a usable grain list of a cut bed");
  Model& m = sc.model;
  std::vector<double> r(n);
  std::vector<int> mat(n);
  std::vector<uint8_t> fixed(n);
  for (long i = 0; i < n; ++i) {
    int fx = 0;
    if (!(f >> r[i] >> mat[i] >> fx) || !(r[i] > 0) || mat[i] < 0 || mat[i] >= m.n_materials())
      throw InputError(path + ": not a usable grain list of a cut bed (grain " + std::to_string(i) + ")");
    fixed[i] = fx != 0 ? kHoldGlued : 0;
  }
  std::vector<GrainGroup> groups(ng);
  for (GrainGroup& g : groups)
    if (!(f >> g.name >> g.first >> g.count) || g.first < 0 || g.count < 0 || g.first + g.count > n)
      throw InputError(path + ": not a usable grain list of a cut bed (groups)");
  m.grain_radius = std::move(r);
  m.grain_material = std::move(mat);
  m.grain_hold = std::move(fixed);
  m.n_grains = int(n);
  finalize_model(m);
  sc.groups = std::move(groups);
}

}  // namespace

std::string bed_key(const Model& m, const State& s, const std::vector<int>& placed) {
  uint64_t h = kFnvOffset;
  h = fnv1a(m.grain_radius.data(), m.grain_radius.size() * sizeof(double), h);
  h = fnv1a(s.pos.data(), s.pos.size() * sizeof(Vec3), h);
  for (const auto& mat : m.materials) {
    const double v[] = {mat.density, mat.eps_n, mat.eps_t, mat.mu_s, mat.mu_r, mat.mu_t, mat.beta, mat.young};
    h = fnv1a(v, sizeof v, h);
    if (mat.kt_over_kn != Material().kt_over_kn || mat.ct_over_cn > 0) {  // (default laws keep their keys)
      const double t[] = {mat.kt_over_kn, mat.ct_over_cn};
      h = fnv1a(t, sizeof t, h);
    }
  }
  for (const auto& w : m.walls) {
    const double v[] = {w.origin.x(), w.origin.y(), w.origin.z(), w.axis.x(), w.axis.y(), w.axis.z(), w.radius, w.length};
    h = fnv1a(v, sizeof v, h);
  }
  for (size_t k = 0; k < m.bodies.size(); ++k) {
    if (std::find(placed.begin(), placed.end(), int(k)) != placed.end()) continue;
    const BodyModel& bm = m.bodies[k];
    const BodyState& bs = s.bodies[k];
    const double v[] = {bm.mass, bm.inertia.x(), bm.inertia.y(), bm.inertia.z(), double(bm.fixed), double(bm.material),
                        bs.pos.x(), bs.pos.y(), bs.pos.z(), bs.q.w(), bs.q.x(), bs.q.y(), bs.q.z()};
    h = fnv1a(v, sizeof v, h);
    for (const Shape& sh : bm.shapes) {
      const double w[] = {double(sh.type), sh.size.x(), sh.size.y(), sh.size.z(), sh.pos.x(), sh.pos.y(), sh.pos.z()};
      h = fnv1a(w, sizeof w, h);
    }
  }
  const double v[] = {m.gravity.x(), m.gravity.y(), m.gravity.z(), m.kn, m.dt, m.skin, double(m.partitions)};
  h = fnv1a(v, sizeof v, h);
  if (m.periodic.any()) {  // (beds without a periodic box keep their keys)
    const Periodic& p = m.periodic;
    const double w[] = {double(p.x), double(p.y), p.lo.x(), p.lo.y(), p.length.x(), p.length.y()};
    h = fnv1a(w, sizeof w, h);
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

RelaxedBed relax_bed(Scenario& sc, const State& s0, const std::vector<int>& placed, const SceneOptions& opt,
                     const std::string& label) {
  RelaxedBed out;
  const Model& m = sc.model;
  if (!opt.relaxed_bed.empty()) {  // --relaxed-bed: the caller's bed, as it is
    out.state = load_checkpoint(opt.relaxed_bed, m);
    out.cache = opt.relaxed_bed;
    out.from_cache = true;
    if (!opt.quiet) std::fprintf(stderr, "[%s] relaxed bed from %s\n", label.c_str(), out.cache.c_str());
    return out;
  }
  const std::string cache = opt.cache_dir.empty() ? default_cache_dir() : opt.cache_dir;
  make_dirs(cache + "/beds");
  std::string key = bed_key(m, s0, placed);
  // Stages that cut the bed make different beds from the same pour: their
  // cut heights and criteria join the key (beds without a cut keep theirs).
  bool trims = false;
  for (const Stage& st : sc.stages) trims = trims || st.trim;
  if (trims) {
    uint64_t h = kFnvOffset;
    for (const Stage& st : sc.stages) {
      const double v[] = {double(st.trim), st.trim_above, st.duration, st.until_rms_speed, st.until_max_speed,
                          st.check_every, st.quench_every, double(st.minimize)};
      h = fnv1a(v, sizeof v, h);
      if (st.trim_tops) h = fnv1a("tops", 4, h);  // beds trimmed by centre keep their keys
    }
    char buf[32];
    std::snprintf(buf, sizeof buf, "-c%016llx", static_cast<unsigned long long>(h));
    key += buf;
  }
  out.cache = cache + "/beds/" + key + ".ckpt";
  const std::string grains = cache + "/beds/" + key + ".grains";
  if (std::ifstream(out.cache).good() && (!trims || std::ifstream(grains).good())) {
    try {
      if (trims) load_grains(grains, sc);
      out.state = load_checkpoint(out.cache, m);
    } catch (const InputError& e) {
      throw InputError(std::string(e.what()) + "\n  this is a cached relaxed bed: delete it (rm " + out.cache +
                       (trims ? " " + grains : std::string()) + ") and the bed is relaxed again");
    }
    out.from_cache = true;
    if (!opt.quiet) std::fprintf(stderr, "[%s] relaxed bed from the cache: %s\n", label.c_str(), out.cache.c_str());
    return out;
  }
  if (sc.stages.empty()) throw InputError(sc.file + ": key 'stages': the bed relaxation stage is missing");
  if (!opt.quiet)
    std::fprintf(stderr, "[%s] relaxing the bed once (cached afterwards in %s)\n", label.c_str(), out.cache.c_str());
  out.state = s0;
  RunOptions ro;
  ro.out_dir = opt.relax_out;
  ro.progress_every = opt.quiet ? 0 : 5.0;
  ro.max_steps = opt.max_steps;
  // The relaxation runs on a copy of the scenario without sleeping or a
  // stiffness schedule: a bed is prepared by the same dynamics whatever the
  // scene later skips, and the stages' settings (gravity, stiffness scale) do not stay in the scene's
  // model, as they do not when the bed comes from the cache.
  // Fields (a gas) are off too: a bed settles by itself, the scene's gas acts on the settled bed.
  Scenario relax = sc;
  relax.model.sleep.enabled = false;
  relax.model.schedule.enabled = false;
  relax.model.fields.clear();
  const RunReport rr = run_scenario(relax, out.state, ro);
  if (rr.status != "ok") throw BlowUpError("bed relaxation: " + rr.message);
  if (!opt.quiet)
    std::fprintf(stderr, "[%s] bed relaxed in %.4g s simulated (%s)\n", label.c_str(), rr.sim_time,
                 rr.stages.empty() ? "" : rr.stages.back().reason.c_str());
  if (relax.model.n_grains != sc.model.n_grains) {  // a cut: the bed's grains replace the scenario's
    sc.model.grain_radius = relax.model.grain_radius;
    sc.model.grain_material = relax.model.grain_material;
    sc.model.grain_hold = relax.model.grain_hold;
    sc.model.n_grains = relax.model.n_grains;
    finalize_model(sc.model);
    sc.groups = relax.groups;
  }
  if (trims) save_grains(grains, sc);
  save_checkpoint(out.cache, sc.model, out.state);
  return out;
}

}  // namespace rt

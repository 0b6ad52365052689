// Binary checkpoints: header, sections, FNV-1a checksum.
#include "regolith_twin/io/checkpoint.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <tuple>
#include <utility>

#include "regolith_twin/core/hash.hpp"
#include "regolith_twin/core/neighbours.hpp"
#include "regolith_twin/io/data_file.hpp"

namespace rt {
namespace {

constexpr char kMagic[8] = {'R', 'G', 'T', 'W', 'C', 'K', 'P', 'T'};
// 9: the stiffness schedule's reference kinetic energy and raises by cause
// (docs/model.md §17); 8: the fields' evolving values (a gas field's anchoring plane, docs/model.md §10);
// 7: free flight (docs/model.md §18): the grains' reaches and the body poses
// of the last full build; 6 (ticks and the stiffness schedule's state, docs/model.md §17), 5 (sleep
// state, docs/model.md §16), 4 (history slots of grain–mesh contacts), 3
// (rigid bodies, no grain–mesh contacts) and 2 (grains only) are still read.
constexpr uint32_t kVersion = 9;

// Fingerprint of the static grain description a state belongs to.
uint64_t model_fingerprint(const Model& m) {
  uint64_t h = fnv1a(reinterpret_cast<const char*>(m.grain_radius.data()), m.grain_radius.size() * sizeof(double));
  h = fnv1a(reinterpret_cast<const char*>(m.grain_material.data()), m.grain_material.size() * sizeof(int), h);
  std::vector<uint8_t> held_now(m.grain_hold.size());  // held or free, whichever policy
  for (size_t i = 0; i < held_now.size(); ++i) held_now[i] = m.grain_hold[i] != 0;
  return fnv1a(reinterpret_cast<const char*>(held_now.data()), held_now.size(), h);
}

class Writer {
 public:
  template <class T>
  void pod(const T& v) {
    raw(&v, sizeof v);
  }
  template <class T>
  void vec(const std::vector<T>& v) {
    pod<uint64_t>(v.size());
    raw(v.data(), v.size() * sizeof(T));
  }
  void raw(const void* p, size_t n) { buf.append(static_cast<const char*>(p), n); }
  std::string buf;
};

// Body states copied field by field into zeroed storage: a BodyState has
// padding bytes (a Quat is 16-byte aligned), and equal states must give
// equal files.
std::vector<BodyState> zero_padded(const std::vector<BodyState>& in) {
  std::vector<BodyState> out(in.size());
  for (size_t k = 0; k < in.size(); ++k) {
    BodyState& o = out[k];
    const BodyState& b = in[k];
    std::memset(static_cast<void*>(&o), 0, sizeof o);
    o.pos = b.pos;
    o.q = b.q;
    o.vel = b.vel;
    o.omega = b.omega;
    o.vel_mid = b.vel_mid;
    o.omega_mid = b.omega_mid;
    o.ang_mom = b.ang_mom;
    o.force = b.force;
    o.torque = b.torque;
    o.pos_at_build = b.pos_at_build;
    o.q_at_build = b.q_at_build;
  }
  return out;
}

class Reader {
 public:
  Reader(const std::string& path, const std::string& data) : path_(path), data_(data) {}
  template <class T>
  T pod() {
    T v;
    raw(&v, sizeof v);
    return v;
  }
  template <class T>
  void vec(std::vector<T>& v, uint64_t expect = UINT64_MAX) {
    const uint64_t n = pod<uint64_t>();
    if (expect != UINT64_MAX && n != expect) fail("section length mismatch");
    if (n > (data_.size() - pos_) / sizeof(T)) fail("truncated file");
    v.resize(n);
    raw(v.data(), n * sizeof(T));
  }
  void raw(void* p, size_t n) {
    if (n > data_.size() - pos_) fail("truncated file");
    if (n == 0) return;  // an empty section: p may be null, which memcpy must not get
    std::memcpy(p, data_.data() + pos_, n);
    pos_ += n;
  }
  [[noreturn]] void fail(const std::string& what) const { throw InputError(path_ + ": not a usable checkpoint: " + what); }
  size_t pos() const { return pos_; }

 private:
  const std::string& path_;
  const std::string& data_;
  size_t pos_ = 0;
};

template <class List>
void put_springs(Writer& w, const List& l) {
  w.vec(l.spring_t);
  w.vec(l.spring_r);
  w.vec(l.spring_w);
  w.vec(l.touching);
}

template <class List>
void get_springs(Reader& r, List& l, uint64_t n) {
  r.vec(l.spring_t, n);
  r.vec(l.spring_r, n);
  r.vec(l.spring_w, n);
  r.vec(l.touching, n);
}

bool finite(const Vec3& v) { return v.allFinite(); }
bool finite(double v) { return std::isfinite(v); }
bool finite(const Quat& q) { return q.coeffs().allFinite(); }

// Every value a step reads is checked after the checksum: finite numbers,
// flags 0 or 1, lists sorted as the builders leave them with indices in
// range (docs/files.md, checkpoints). The checksum proves the file is
// the one written; this proves it holds a state the engine can step.
void check_state(Reader& r, const Model& m, const State& s) {
  const int n = m.n_grains;
  const auto where = [](const char* what, size_t k) { return std::string(what) + " " + std::to_string(k); };
  if (!(s.time >= 0 && s.time <= kMaxStateTime) || s.step < 0 || s.rebuilds < 0 || !(s.stats.max_disp2 >= 0) ||
      !std::isfinite(s.stats.max_disp2)) {
    char b[96];
    std::snprintf(b, sizeof b, "time %.6g s, allowed [0, 1e9]; step %lld", s.time, (long long)s.step);
    r.fail(std::string("clock or step counters are invalid (") + b + ")");
  }
  const std::pair<const char*, const std::vector<Vec3>*> grain_vecs[] = {
      {"position", &s.pos}, {"velocity", &s.vel}, {"angular velocity", &s.omega},
      {"force", &s.force},   {"torque", &s.torque}, {"position at the last list build", &s.pos_at_build}};
  for (const auto& [what, v] : grain_vecs)
    for (size_t i = 0; i < v->size(); ++i)
      if (!finite((*v)[i])) r.fail(std::string("grain ") + std::to_string(i) + " has a non-finite " + what);
  static_assert(kMaxStateTime == 1e9 && kMaxCoordinate == 1e6 && kMaxStateSpeed == 1e6,
                "the messages name these bounds");
  // Finite is not enough: a step, the neighbour grid and ROS time need values
  // of a physical size (core/types.hpp).
  const auto too_far = [](const Vec3& x) { return !(x.cwiseAbs().maxCoeff() <= kMaxCoordinate); };
  const auto too_fast = [](const Vec3& v) { return !(v.cwiseAbs().maxCoeff() <= kMaxStateSpeed); };
  for (size_t i = 0; i < s.pos.size() && i < s.vel.size() && i < s.omega.size(); ++i)
    if (too_far(s.pos[i]) || too_fast(s.vel[i]) || too_fast(s.omega[i]))
      r.fail("grain " + std::to_string(i) + " has a position beyond 1e6 m or a speed beyond 1e6 m/s (or rad/s)");
  // Grain pairs: rows of partners j > i, ascending; springs finite, flags 0/1.
  const PairList& pl = s.pairs;
  if (!pl.row_start.empty() || !pl.partner.empty()) {
    if (pl.row_start.size() != size_t(n) + 1 || pl.row_start[0] != 0 ||
        size_t(pl.row_start[n]) != pl.partner.size())
      r.fail("pair list rows do not match the grain count and the entries");
    for (int i = 0; i < n; ++i) {
      if (pl.row_start[i + 1] < pl.row_start[i]) r.fail("pair list rows are not in order (" + where("grain", i) + ")");
      int last = i;
      for (int k = pl.row_start[i]; k < pl.row_start[i + 1]; ++k) {
        if (pl.partner[k] <= last || pl.partner[k] >= n)
          r.fail("pair list refers to a grain that does not exist or is out of order (" + where("entry", k) + ")");
        last = pl.partner[k];
      }
    }
  }
  const auto springs = [&r, &where](const auto& l, const char* list) {
    for (size_t k = 0; k < l.spring_t.size(); ++k)
      if (!finite(l.spring_t[k]) || !finite(l.spring_r[k]) || !finite(l.spring_w[k]) || l.touching[k] > 1)
        r.fail(std::string(list) + " holds a non-finite spring or an invalid contact flag (" + where("entry", k) + ")");
  };
  springs(pl, "pair list");
  // Grain–wall entries sorted by (grain, wall) without repeats.
  const WallList& wl = s.wall_pairs;
  for (size_t k = 0; k < wl.grain.size(); ++k) {
    if (wl.grain[k] < 0 || wl.grain[k] >= n || wl.wall[k] < 0 || wl.wall[k] >= int(m.walls.size()))
      r.fail("wall list refers to a grain or wall that does not exist (" + where("entry", k) + ")");
    if (k > 0 && std::make_pair(wl.grain[k], wl.wall[k]) <= std::make_pair(wl.grain[k - 1], wl.wall[k - 1]))
      r.fail("wall list is not in order (" + where("entry", k) + ")");
  }
  springs(wl, "wall list");
  for (size_t w = 0; w < s.wall_on.size(); ++w)
    if (s.wall_on[w] > 1) r.fail("wall " + std::to_string(w) + " has an invalid on/off flag");
  // Bodies: finite states, unit orientations.
  for (size_t b = 0; b < s.bodies.size(); ++b) {
    const BodyState& x = s.bodies[b];
    const std::string name = "body " + std::to_string(b) + (b < m.bodies.size() ? " ('" + m.bodies[b].name + "')" : "");
    for (const Vec3* v : {&x.pos, &x.vel, &x.omega, &x.vel_mid, &x.omega_mid, &x.ang_mom, &x.force, &x.torque,
                          &x.pos_at_build})
      if (!finite(*v)) r.fail(name + " has a non-finite position, velocity, momentum or force");
    for (const Quat* q : {&x.q, &x.q_at_build})
      if (!finite(*q) || std::abs(q->norm() - 1) > 1e-6) r.fail(name + " has an orientation that is not a unit quaternion");
  }
  for (size_t b = 0; b < s.bodies.size(); ++b)
    if (too_far(s.bodies[b].pos) || too_fast(s.bodies[b].vel) || too_fast(s.bodies[b].omega))
      r.fail("body " + std::to_string(b) + " has a position beyond 1e6 m or a speed beyond 1e6 m/s (or rad/s)");
  if (!(s.body_list_grain_disp >= 0) || !std::isfinite(s.body_list_grain_disp) || s.body_rebuilds < 0)
    r.fail("grain–body list counters are invalid");
  const BodyGrainList& bl = s.body_grains;
  for (size_t k = 0; k < bl.grain.size(); ++k) {
    if (k > 0 && std::make_tuple(bl.grain[k], bl.body[k], bl.shape[k]) <=
                     std::make_tuple(bl.grain[k - 1], bl.body[k - 1], bl.shape[k - 1]))
      r.fail("grain–body list is not in order (" + where("entry", k) + ")");
    if (!(bl.sqrt_mstar[k] > 0) || !std::isfinite(bl.sqrt_mstar[k]))
      r.fail("grain–body list holds an invalid reduced mass (" + where("entry", k) + ")");
  }
  springs(bl, "grain–body list");
  for (size_t k = 0; k < bl.mesh_slots.size(); ++k) {
    const MeshSlot& q = bl.mesh_slots[k];
    if (!finite(q.normal) || !finite(q.spring_t) || !finite(q.spring_r) || !finite(q.spring_w) ||
        (q.touching != 0 && q.touching != 1))
      r.fail("grain–mesh contact history holds a non-finite value or an invalid flag (" + where("slot", k) + ")");
  }
  for (size_t k = 0; k < s.body_points.size(); ++k) {
    const BodyPointContact& c = s.body_points[k];
    if (c.a >= c.b || !finite(c.local_a) || !finite(c.local_b) || !finite(c.spring_t) || !finite(c.overlap) ||
        !finite(c.normal) || !finite(c.point) || !finite(c.force_a))
      r.fail("body contact " + std::to_string(k) + " holds a non-finite value or an invalid body pair");
  }
  // Sleep state.
  const SleepState& z = s.sleep;
  if (z.initialized) {
    if (!finite(z.lo) || !std::isfinite(z.cell) || !(z.d_mean > 0) || !std::isfinite(z.d_mean) ||
        !finite(z.gravity) || !std::isfinite(z.last_check) || z.next_check < 0)
      r.fail("sleep state is invalid");
    for (int i = 0; i < n; ++i)
      if (z.asleep[i] > 1 || !finite(z.f_ref[i]) || !finite(z.f_last[i]))
        r.fail("sleep state of grain " + std::to_string(i) + " is invalid");
    for (double q : z.quiet)
      if (!(q >= 0) || !std::isfinite(q)) r.fail("sleep state holds an invalid quiet time");
  }
  const ScheduleState& q = s.schedule;
  for (double v : {q.dt_min, q.dt_max, q.injected, q.max_injected_fraction, q.t_start, q.v_grains, q.released})
    if (!std::isfinite(v)) r.fail("stiffness schedule state is invalid");
}

}  // namespace

void save_checkpoint(const std::string& path, const Model& m, const State& s) {
  write_checkpoint_file(path, checkpoint_image(m, s));
}

State load_checkpoint(const std::string& path, const Model& m) {
  return state_from_checkpoint(path, read_checkpoint_file(path), m);
}

std::string checkpoint_image(const Model& m, const State& s) {
  Writer w;
  w.raw(kMagic, sizeof kMagic);
  w.pod(kVersion);
  w.pod<uint64_t>(m.n_grains);
  w.pod(model_fingerprint(m));
  w.pod(s.time);
  w.pod<int64_t>(s.step);
  w.pod<int64_t>(s.rebuilds);
  // Flags: bit 0 the lists and forces are live (loading continues without a
  // priming pass), bit 1 a list rebuild is pending (walls switched on or off).
  w.pod<uint8_t>(uint8_t((s.lists_valid && s.forces_valid ? 1 : 0) | (s.rebuild_requested ? 2 : 0)));
  w.pod(s.stats.max_disp2);
  for (const auto* v : {&s.pos, &s.vel, &s.omega, &s.force, &s.torque, &s.pos_at_build}) w.vec(*v);
  w.vec(s.pairs.row_start);
  w.vec(s.pairs.partner);
  put_springs(w, s.pairs);
  w.vec(s.wall_on);
  w.vec(s.wall_pairs.grain);
  w.vec(s.wall_pairs.wall);
  put_springs(w, s.wall_pairs);
  // Rigid bodies: states, grain–body list with history, body–body points.
  w.pod<uint64_t>(m.bodies.size());
  w.vec(zero_padded(s.bodies));
  w.pod(s.body_list_grain_disp);
  w.pod<int64_t>(s.body_rebuilds);
  w.vec(s.body_grains.grain);
  w.vec(s.body_grains.body);
  w.vec(s.body_grains.shape);
  w.vec(s.body_grains.sqrt_mstar);
  put_springs(w, s.body_grains);
  w.vec(s.body_grains.mesh_first);
  w.vec(s.body_grains.mesh_slots);
  w.vec(s.body_points);
  // Sleep state (model.md §16): flag, then the grid, per-grain and per-cell arrays, counters.
  const SleepState& z = s.sleep;
  w.pod<uint8_t>(z.initialized ? 1 : 0);
  if (z.initialized) {
    w.pod(z.lo);
    w.pod(z.cell);
    w.pod(z.d_mean);
    w.pod<int32_t>(z.nx);
    w.pod<int32_t>(z.ny);
    w.pod<int32_t>(z.nz);
    w.vec(z.asleep);
    w.vec(z.f_ref);
    w.vec(z.f_last);
    w.vec(z.quiet);
    w.pod(z.gravity);
    w.pod<int64_t>(z.next_check);
    w.pod(z.last_check);
    w.pod<uint8_t>(z.ref_pending ? 1 : 0);
    w.pod<int64_t>(z.fell_asleep);
    w.pod<int64_t>(z.woke);
    w.pod<int64_t>(z.checks);
    w.pod(z.awake_grain_steps);
    w.pod(z.discarded_energy);
    w.pod(z.discarded_max_speed);
  }
  // Ticks and the stiffness schedule (model.md §17).
  w.pod(s.ticks);
  w.pod(s.tick_len);
  const ScheduleState& q = s.schedule;
  for (double v :
       {q.scale, q.min_scale, q.dt_min, q.dt_max, q.injected, q.max_injected_fraction, q.t_start, q.v_grains, q.released})
    w.pod(v);
  w.pod<int64_t>(q.lowered);
  w.pod<int64_t>(q.raised);
  w.pod<uint8_t>(q.started ? 1 : 0);
  w.pod<int64_t>(q.low_since);
  // Free flight (model.md §18).
  w.pod<uint8_t>(s.reach.empty() ? 0 : 1);
  if (!s.reach.empty()) {
    w.vec(s.reach);
    w.pod(s.stats.max_free_disp2);
    w.pod(s.stats.free_margin);
    w.pod<int64_t>(s.free_grains);
    w.vec(s.body_pos_at_full);
    std::vector<double> q4;
    for (const Quat& q : s.body_q_at_full) q4.insert(q4.end(), {q.w(), q.x(), q.y(), q.z()});
    w.vec(q4);
  }
  w.pod<int64_t>(s.free_grains_max);
  w.vec(s.field_values);  // the fields' evolving values (model.md §10)
  w.vec(s.pairs.image);   // periodic boxes: the image of each pair entry's partner (model.md §11)
  w.pod(q.kinetic_ref);   // the schedule's reference energy and raises by cause (model.md §17)
  for (long c : {q.raised_grains, q.raised_body}) w.pod<int64_t>(c);
  const uint64_t sum = fnv1a(w.buf.data(), w.buf.size());
  w.pod(sum);
  return std::move(w.buf);
}

void write_checkpoint_file(const std::string& path, const std::string& image) {
  write_file_replacing(path, image, "checkpoint", /*sync=*/true);
}

std::string read_checkpoint_file(const std::string& path) {
  // Read to the end (a pipe or special file has no size to ask for), at most
  // the checkpoint limit (docs/files.md, "Loaded files").
  return read_file_limited(path, kMaxCheckpointBytes, "checkpoint");
}

State state_from_checkpoint(const std::string& path, const std::string& data, const Model& m) {
  Reader r(path, data);
  const size_t head = std::min(data.size(), sizeof kMagic);
  if (std::memcmp(data.data(), kMagic, head) != 0 || data.empty()) r.fail("wrong file type (no checkpoint header)");
  if (data.size() < sizeof kMagic + sizeof(uint32_t) + 8) r.fail("truncated file (shorter than the header)");
  uint64_t stored_sum;
  std::memcpy(&stored_sum, data.data() + data.size() - 8, 8);
  if (fnv1a(data.data(), data.size() - 8) != stored_sum) r.fail("checksum mismatch (truncated or corrupted file)");
  char magic[8];
  r.raw(magic, 8);
  const uint32_t version = r.pod<uint32_t>();
  if (version != kVersion && version != 8 && version != 7 && version != 6 && version != 5 && version != 4 && version != 3 && version != 2)
    r.fail("format version " + std::to_string(version) + ", this build reads version " + std::to_string(kVersion));
  const uint64_t n = r.pod<uint64_t>();
  if (n != uint64_t(m.n_grains))
    r.fail("it holds " + std::to_string(n) + " grains, the scenario has " + std::to_string(m.n_grains));
  if (r.pod<uint64_t>() != model_fingerprint(m)) r.fail("grain radii or materials differ from the scenario's");
  State s = make_state(m);
  s.time = r.pod<double>();
  s.step = r.pod<int64_t>();
  s.rebuilds = r.pod<int64_t>();
  const uint8_t flags = r.pod<uint8_t>();
  const bool live = (flags & 1) != 0;
  s.rebuild_requested = (flags & 2) != 0;
  s.stats.max_disp2 = r.pod<double>();
  for (auto* v : {&s.pos, &s.vel, &s.omega, &s.force, &s.torque, &s.pos_at_build}) r.vec(*v, n);
  r.vec(s.pairs.row_start);
  r.vec(s.pairs.partner);
  if (live && s.pairs.row_start.size() != n + 1) r.fail("pair list does not match the grain count");
  get_springs(r, s.pairs, s.pairs.partner.size());
  r.vec(s.wall_on, m.walls.size());
  r.vec(s.wall_pairs.grain);
  r.vec(s.wall_pairs.wall);
  get_springs(r, s.wall_pairs, s.wall_pairs.grain.size());
  if (version >= 3) {
    const uint64_t nb = r.pod<uint64_t>();
    if (nb != m.bodies.size())
      r.fail("it holds " + std::to_string(nb) + " bodies, the scenario has " + std::to_string(m.bodies.size()));
    r.vec(s.bodies, nb);
    s.body_list_grain_disp = r.pod<double>();
    s.body_rebuilds = r.pod<int64_t>();
    BodyGrainList& bl = s.body_grains;
    r.vec(bl.grain);
    r.vec(bl.body, bl.grain.size());
    r.vec(bl.shape, bl.grain.size());
    r.vec(bl.sqrt_mstar, bl.grain.size());
    get_springs(r, bl, bl.grain.size());
    if (version >= 4) {
      r.vec(bl.mesh_first, bl.grain.size());
      r.vec(bl.mesh_slots);
    } else {
      bl.mesh_first.assign(bl.grain.size(), -1);  // version 3 had no grain–mesh contacts
    }
    r.vec(s.body_points);
    int slots = 0;
    for (size_t k = 0; k < bl.grain.size(); ++k) {
      if (bl.grain[k] < 0 || bl.grain[k] >= m.n_grains || bl.body[k] < 0 || bl.body[k] >= int(nb) ||
          bl.shape[k] < 0 || bl.shape[k] >= int(m.bodies[bl.body[k]].shapes.size()))
        r.fail("grain–body list refers to a grain, body or shape that does not exist");
      const bool mesh = m.bodies[bl.body[k]].shapes[bl.shape[k]].type == ShapeType::Mesh;
      if (version < 4 && mesh) r.fail("format version 3 holds no grain–mesh contact history");
      if (bl.mesh_first[k] != (mesh ? slots : -1)) r.fail("grain–mesh contact history does not match the list");
      slots += mesh ? kMeshSlots : 0;
    }
    if (bl.mesh_slots.size() != size_t(slots)) r.fail("grain–mesh contact history does not match the list");
    for (const auto& pt : s.body_points)
      if (pt.a < 0 || pt.b < 0 || pt.a >= int(nb) || pt.b >= int(nb) || pt.shape_a < 0 || pt.shape_b < 0 ||
          pt.shape_a >= int(m.bodies[pt.a].shapes.size()) || pt.shape_b >= int(m.bodies[pt.b].shapes.size()))
        r.fail("body contact refers to a missing body or shape");
  } else if (!m.bodies.empty()) {
    r.fail("format version 2 holds no bodies, the scenario has " + std::to_string(m.bodies.size()));
  }
  if (version >= 5 && r.pod<uint8_t>() != 0) {
    SleepState& z = s.sleep;
    z.lo = r.pod<Vec3>();
    z.cell = r.pod<double>();
    z.d_mean = r.pod<double>();
    z.nx = r.pod<int32_t>();
    z.ny = r.pod<int32_t>();
    z.nz = r.pod<int32_t>();
    if (!(z.cell > 0) || z.nx <= 0 || z.ny <= 0 || z.nz <= 0 || double(z.nx) * z.ny * z.nz > 1e9)
      r.fail("sleep cell grid is invalid");
    const size_t cells = size_t(z.nx) * z.ny * z.nz;
    r.vec(z.asleep, n);
    r.vec(z.f_ref, n);
    r.vec(z.f_last, n);
    r.vec(z.quiet, cells);
    z.gravity = r.pod<Vec3>();
    z.next_check = r.pod<int64_t>();
    z.last_check = r.pod<double>();
    z.ref_pending = r.pod<uint8_t>() != 0;
    z.fell_asleep = r.pod<int64_t>();
    z.woke = r.pod<int64_t>();
    z.checks = r.pod<int64_t>();
    z.awake_grain_steps = r.pod<double>();
    z.discarded_energy = r.pod<double>();
    z.discarded_max_speed = r.pod<double>();
    z.cell_flags.assign(cells, 0);
    z.cell_sum.assign(cells, 0.0);
    z.cell_count.assign(cells, 0);
    z.cell_scratch.assign(n, -1);
    z.initialized = true;
  }
  s.ticks = double(s.step);
  if (version >= 6) {
    s.ticks = r.pod<double>();
    s.tick_len = r.pod<double>();
    ScheduleState& q = s.schedule;
    for (double* v : {&q.scale, &q.min_scale, &q.dt_min, &q.dt_max, &q.injected, &q.max_injected_fraction,
                      &q.t_start, &q.v_grains, &q.released})
      *v = r.pod<double>();
    q.lowered = r.pod<int64_t>();
    q.raised = r.pod<int64_t>();
    q.started = r.pod<uint8_t>() != 0;
    q.low_since = r.pod<int64_t>();
    if (!std::isfinite(s.ticks) || !(s.tick_len > 0) || !std::isfinite(s.tick_len) || !(q.scale > 0) ||
        !(q.scale <= 1) || !(q.min_scale > 0) || !(q.min_scale <= q.scale))
      r.fail("stiffness schedule state is invalid");
  }
  if (version >= 7) {
    if (r.pod<uint8_t>() != 0) {
      r.vec(s.reach, n);
      s.stats.max_free_disp2 = r.pod<double>();
      s.stats.free_margin = r.pod<double>();
      s.free_grains = r.pod<int64_t>();
      r.vec(s.body_pos_at_full, m.bodies.size());
      std::vector<double> q4;
      r.vec(q4, 4 * m.bodies.size());
      s.body_q_at_full.resize(m.bodies.size());
      for (size_t b = 0; b < m.bodies.size(); ++b)
        s.body_q_at_full[b] = Quat(q4[4 * b], q4[4 * b + 1], q4[4 * b + 2], q4[4 * b + 3]);
      long free = 0;
      for (double c : s.reach) {
        if (!(c >= 0) || !std::isfinite(c)) r.fail("free-flight reach is invalid");
        free += c > 0;
      }
      if (free != s.free_grains || !(s.stats.max_free_disp2 >= 0) || std::isnan(s.stats.free_margin))
        r.fail("free-flight state is invalid");
    }
    s.free_grains_max = r.pod<int64_t>();
  }
  if (version >= 8) {
    r.vec(s.field_values);
    if (s.field_values.size() > 64) r.fail("more than 64 field values");
    for (double v : s.field_values)
      if (!std::isfinite(v)) r.fail("a field value is not finite");
    r.vec(s.pairs.image);
  }
  if (version >= 9) {
    ScheduleState& q = s.schedule;
    q.kinetic_ref = r.pod<double>();
    q.raised_grains = r.pod<int64_t>();
    q.raised_body = r.pod<int64_t>();
    if (!(q.kinetic_ref >= 0) || !std::isfinite(q.kinetic_ref) || q.raised_grains < 0 || q.raised_body < 0 ||
        q.raised_grains + q.raised_body > q.raised)
      r.fail("stiffness schedule state is invalid");
  }
  if (s.pairs.image.size() != (m.periodic.any() ? s.pairs.partner.size() : 0))
    r.fail(m.periodic.any() ? "the pair list's periodic images do not match its entries (or the file was written "
                              "without periodic boundaries)"
                            : "the pair list has periodic images, the scenario has no periodic box");
  for (int8_t c : s.pairs.image) {
    const int sx = (c + 4) % 3 - 1, sy = (c - sx) / 3;
    if (c < -4 || c > 4 || (!m.periodic.x && sx != 0) || (!m.periodic.y && sy != 0))
      r.fail("a periodic image code is out of range");
  }
  if (r.pos() + 8 != data.size()) r.fail("unexpected trailing data");
  check_state(r, m, s);
  if (live) {
    partition_work(m, s);
    partition_body_list(m, s);
    s.lists_valid = s.forces_valid = true;
  }
  return s;
}

}  // namespace rt

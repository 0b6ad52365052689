// Editing grains during a run (core/edit.hpp): removing grains that touch
// nothing, or adding a far-away grain and removing it again, leaves the rest
// of the run bit-identical to a run without them (the contacts that stay keep
// their tangential, rolling and twisting springs, grain–grain, grain–wall and
// grain–body); removing a grain in a contact keeps every other contact's
// springs through the next list build.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <tuple>
#include <vector>

#include "regolith_twin/core/edit.hpp"
#include "regolith_twin/core/walls.hpp"
#include "regolith_twin/io/scenario.hpp"
#include "test_support.hpp"

namespace {

using rt::Vec3;

constexpr double kR = 0.005;  // grain radius, m

struct Scene {
  rt::Model m;
  rt::State s;
};

// A pile of 'moderate' grains (friction, rolling and twisting resistance) on
// a plane: a square pyramid of 4x4, 3x3, 2x2 and 1 grains, or (with_body) its
// two lower layers under a free box plate. Extra glued grains far away (not touching
// anything) are put first, in the middle and last of the grain order when
// `extras` is set. extra_index receives, for each grain, whether it is extra.
Scene make_scene(bool extras, bool with_body, std::vector<uint8_t>* extra_index = nullptr) {
  Scene sc;
  rt::Model& m = sc.m;
  EXPECT_TRUE(rt::test::preset_with_wall(m, "moderate"));
  m.walls.push_back(rt::make_plane(Vec3::Zero(), Vec3::UnitZ(), 1));

  const double d = 2.02 * kR, dz = d / std::sqrt(2.0);
  std::vector<Vec3> pile;
  const int layers = with_body ? 2 : 4;
  for (int l = 0; l < layers; ++l)
    for (int i = 0; i < 4 - l; ++i)
      for (int j = 0; j < 4 - l; ++j) pile.push_back(Vec3((i + 0.5 * l) * d, (j + 0.5 * l) * d, 1.01 * kR + l * dz));
  std::vector<Vec3> pos;
  std::vector<uint8_t> is_extra;
  int far = 0;
  auto add_extra = [&] {
    pos.push_back(Vec3(10.0 + 3 * d * far, -7.0, 5.0 + d * (far % 2)));
    is_extra.push_back(1);
    ++far;
  };
  for (size_t k = 0; k < pile.size(); ++k) {
    if (extras && (k == 0 || k == pile.size() / 2)) {
      add_extra();
      add_extra();
    }
    pos.push_back(pile[k]);
    is_extra.push_back(0);
  }
  if (extras) add_extra();
  for (size_t k = 0; k < pos.size(); ++k) rt::add_grain(m, kR, 0, is_extra[k] != 0);

  if (with_body) {
    rt::BodyModel b;
    b.name = "plate";
    b.mass = 0.05;
    const Vec3 half(0.02, 0.02, 0.004);
    b.inertia = Vec3(half.y() * half.y() + half.z() * half.z(), half.x() * half.x() + half.z() * half.z(),
                     half.x() * half.x() + half.y() * half.y()) *
                (b.mass / 3);
    b.material = 1;
    rt::Shape box;
    box.type = rt::ShapeType::Box;
    box.size = half;
    b.shapes = {box};
    m.bodies.push_back(b);
  }
  const double m_p = 4.0 / 3.0 * M_PI * std::pow(kR, 3) * m.materials[0].density;
  m.kn = rt::kn_rule(m_p, 1.0, 0.01 * kR);
  m.dt = rt::dt_rule(m_p, m.kn, 30);
  rt::finalize_model(m);
  sc.s = rt::make_state(m);
  for (size_t k = 0; k < pos.size(); ++k) sc.s.pos[k] = pos[k];
  if (with_body) {
    sc.s.bodies[0].pos = Vec3(1.5 * d, 1.5 * d, 2.01 * kR + dz + 0.004 + 1e-5);
    rt::set_body_velocity(m.bodies[0], sc.s.bodies[0], Vec3(0.02, 0.01, 0), Vec3(0, 0, 0.5));
  }
  if (extra_index) *extra_index = is_extra;
  return sc;
}

void run(Scene& sc, int steps) {
  for (int k = 0; k < steps; ++k) rt::step(sc.m, sc.s);
}

// Live contacts whose springs are not zero: (grain–grain, grain–wall, grain–body).
std::tuple<int, int, int> loaded_contacts(const rt::State& s) {
  auto count = [](const auto& l) {
    int c = 0;
    for (int k = 0; k < l.size(); ++k) c += l.touching[k] && l.spring_t[k].norm() > 0 && l.spring_r[k].norm() > 0;
    return c;
  };
  return {count(s.pairs), count(s.wall_pairs), count(s.body_grains)};
}

template <class List>
void expect_same_history(const List& a, const List& b, const char* what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (int k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a.spring_t[k], b.spring_t[k]) << what << " entry " << k;
    EXPECT_EQ(a.spring_r[k], b.spring_r[k]) << what << " entry " << k;
    EXPECT_EQ(a.spring_w[k], b.spring_w[k]) << what << " entry " << k;
    EXPECT_EQ(a.touching[k], b.touching[k]) << what << " entry " << k;
  }
}

// Bit-identical grains, bodies and contact lists with their springs.
void expect_same(const rt::State& a, const rt::State& b) {
  ASSERT_EQ(a.pos.size(), b.pos.size());
  for (size_t i = 0; i < a.pos.size(); ++i) {
    EXPECT_EQ(a.pos[i], b.pos[i]) << "grain " << i;
    EXPECT_EQ(a.vel[i], b.vel[i]) << "grain " << i;
    EXPECT_EQ(a.omega[i], b.omega[i]) << "grain " << i;
  }
  EXPECT_EQ(a.pairs.row_start, b.pairs.row_start);
  EXPECT_EQ(a.pairs.partner, b.pairs.partner);
  expect_same_history(a.pairs, b.pairs, "pair");
  EXPECT_EQ(a.wall_pairs.grain, b.wall_pairs.grain);
  EXPECT_EQ(a.wall_pairs.wall, b.wall_pairs.wall);
  expect_same_history(a.wall_pairs, b.wall_pairs, "wall");
  EXPECT_EQ(a.body_grains.grain, b.body_grains.grain);
  EXPECT_EQ(a.body_grains.shape, b.body_grains.shape);
  expect_same_history(a.body_grains, b.body_grains, "body");
  ASSERT_EQ(a.bodies.size(), b.bodies.size());
  for (size_t k = 0; k < a.bodies.size(); ++k) {
    EXPECT_EQ(a.bodies[k].pos, b.bodies[k].pos);
    EXPECT_EQ(a.bodies[k].q.coeffs(), b.bodies[k].q.coeffs());
    EXPECT_EQ(a.bodies[k].vel, b.bodies[k].vel);
    EXPECT_EQ(a.bodies[k].ang_mom, b.bodies[k].ang_mom);
  }
}

bool same_positions(const rt::State& a, const rt::State& b) {
  for (size_t i = 0; i < a.pos.size(); ++i)
    if (a.pos[i] != b.pos[i] || a.vel[i] != b.vel[i]) return false;
  for (size_t k = 0; k < a.bodies.size(); ++k)
    if (a.bodies[k].pos != b.bodies[k].pos) return false;
  return true;
}

// The reference run sees what an edit does to the state: lists rebuilt and
// forces recomputed by the next step.
void as_if_edited(rt::State& s) {
  s.rebuild_requested = true;
  s.forces_valid = false;
}

void zero_springs(rt::State& s) {
  auto zero = [](auto& l) {
    for (int k = 0; k < l.size(); ++k) {
      l.spring_t[k].setZero();
      l.spring_r[k].setZero();
      l.spring_w[k] = 0;
    }
  };
  zero(s.pairs);
  zero(s.wall_pairs);
  zero(s.body_grains);
}

// Settle a pile with and without far-away glued grains, remove them from the
// second, step both: they stay bit-identical (and differ if the springs were
// dropped at the removal).
void removal_keeps_run(bool with_body) {
  std::vector<uint8_t> extra;
  Scene a = make_scene(false, with_body);
  Scene b = make_scene(true, with_body, &extra);
  ASSERT_EQ(b.m.n_grains, a.m.n_grains + 5);
  const int settle = with_body ? 12000 : 4000;  // the plate comes to rest on a few grains
  run(a, settle);
  run(b, settle);
  const auto [pairs, walls, bodies] = loaded_contacts(a.s);
  EXPECT_GT(pairs, 10) << "grain–grain contacts with springs";
  EXPECT_GT(walls, 10) << "grain–wall contacts with springs";
  if (with_body) {
    EXPECT_GE(bodies, 2) << "grain–body contacts with springs";
  }

  std::vector<int> old_to_new;
  EXPECT_EQ(rt::remove_grains(b.m, b.s, extra, &old_to_new), 5);
  ASSERT_EQ(b.m.n_grains, a.m.n_grains);
  int next = 0;
  for (size_t i = 0; i < extra.size(); ++i) EXPECT_EQ(old_to_new[i], extra[i] ? -1 : next++);
  EXPECT_EQ(b.m.grain_hold, a.m.grain_hold);
  EXPECT_EQ(b.m.grain_inv_mass, a.m.grain_inv_mass);
  // Before any step the renumbered lists are the reference's lists.
  expect_same(a.s, b.s);

  rt::State dropped = b.s;  // the same edit, springs forgotten
  zero_springs(dropped);
  as_if_edited(a.s);
  Scene c{b.m, dropped};
  run(a, 3000);
  run(b, 3000);
  run(c, 3000);
  expect_same(a.s, b.s);
  EXPECT_GT(b.s.rebuilds, 0);
  EXPECT_FALSE(same_positions(a.s, c.s)) << "dropping the springs should change the run";
}

TEST(Edit, RemovingUntouchedGrainsKeepsGrainAndWallSprings) { removal_keeps_run(false); }

TEST(Edit, RemovingUntouchedGrainsKeepsBodySprings) { removal_keeps_run(true); }

// Add a far-away grain to a settled pile, run, remove it, run: the pile's
// run is bit-identical to one without the grain.
TEST(Edit, AddedThenRemovedGrainLeavesRunUnchanged) {
  Scene a = make_scene(false, false);
  run(a, 4000);
  Scene b = a;
  const int n = a.m.n_grains;
  const int id = rt::add_grain(b.m, b.s, 1.2 * kR, 0, Vec3(3, 4, 5), Vec3(0, 0, 0.01), Vec3(1, 2, 3));
  EXPECT_EQ(id, n);
  EXPECT_EQ(b.m.n_grains, n + 1);
  EXPECT_EQ(b.m.max_radius, 1.2 * kR);
  EXPECT_EQ(b.m.grain_mass[n], 4.0 / 3.0 * M_PI * std::pow(1.2 * kR, 3) * b.m.materials[0].density);
  as_if_edited(a.s);
  // The grain falls less than half a skin in these steps, so both runs
  // rebuild their lists at the same steps.
  run(a, 1000);
  run(b, 1000);
  EXPECT_EQ(a.s.rebuilds, b.s.rebuilds);
  EXPECT_NE(b.s.pos[n], Vec3(3, 4, 5));
  b.s.pos.pop_back();
  b.s.vel.pop_back();
  b.s.omega.pop_back();
  EXPECT_TRUE(same_positions(a.s, b.s)) << "the far grain touched the pile";
  b.s.pos.push_back(Vec3::Zero());
  b.s.vel.push_back(Vec3::Zero());
  b.s.omega.push_back(Vec3::Zero());

  std::vector<uint8_t> drop(n + 1, 0);
  drop[n] = 1;
  EXPECT_EQ(rt::remove_grains(b.m, b.s, drop), 1);
  EXPECT_EQ(b.m.max_radius, a.m.max_radius);
  as_if_edited(a.s);
  run(a, 2000);
  run(b, 2000);
  expect_same(a.s, b.s);
}

// A grain dropped onto the pile through add_grain meets it.
TEST(Edit, AddedGrainTakesPart) {
  Scene a = make_scene(false, false);
  run(a, 2000);
  const int n = a.m.n_grains;
  const Vec3 top = a.s.pos[n - 1];
  rt::add_grain(a.m, a.s, kR, 0, top + Vec3(0, 0, 2.2 * kR), Vec3(0, 0, -0.2), Vec3::Zero());
  run(a, 3000);
  bool met = false;
  for (int k = a.s.pairs.row_start[n - 1]; k < a.s.pairs.row_start[n]; ++k) met = met || a.s.pairs.partner[k] == n;
  EXPECT_TRUE(met) << "the new grain is not in the top grain's row";
  EXPECT_LT(a.s.vel[n].norm(), 0.2);
}

// Remove grains that do touch others (the top of the pyramid and a base
// grain): every other contact keeps its springs through the list build.
TEST(Edit, RemovingTouchingGrainsKeepsTheOtherContactsSprings) {
  Scene a = make_scene(false, false);
  run(a, 4000);
  const int n = a.m.n_grains;
  std::vector<uint8_t> drop(n, 0);
  drop[n - 1] = 1;  // the top grain
  drop[5] = 1;      // a base grain
  // Springs of every contact before the edit, by grain pair (-1 - wall for walls).
  std::map<std::pair<int, int>, std::tuple<Vec3, Vec3, double>> before;
  const rt::PairList& pl = a.s.pairs;
  for (int i = 0; i < n; ++i)
    for (int k = pl.row_start[i]; k < pl.row_start[i + 1]; ++k)
      if (pl.touching[k]) before[{i, pl.partner[k]}] = {pl.spring_t[k], pl.spring_r[k], pl.spring_w[k]};
  const rt::WallList& wl = a.s.wall_pairs;
  for (int k = 0; k < wl.size(); ++k)
    if (wl.touching[k]) before[{wl.grain[k], -1 - wl.wall[k]}] = {wl.spring_t[k], wl.spring_r[k], wl.spring_w[k]};
  int lost = 0;
  for (const auto& e : before) lost += drop[e.first.first] || (e.first.second >= 0 && drop[e.first.second]);
  EXPECT_GT(lost, 4);

  std::vector<int> to;
  EXPECT_EQ(rt::remove_grains(a.m, a.s, drop, &to), 2);
  EXPECT_TRUE(a.s.rebuild_requested);
  EXPECT_FALSE(a.s.forces_valid);
  rt::prime(a.m, a.s);  // lists rebuilt from the new positions; springs not advanced
  std::map<std::pair<int, int>, std::tuple<Vec3, Vec3, double>> after;
  for (int i = 0; i < a.m.n_grains; ++i)
    for (int k = pl.row_start[i]; k < pl.row_start[i + 1]; ++k)
      if (pl.touching[k]) after[{i, pl.partner[k]}] = {pl.spring_t[k], pl.spring_r[k], pl.spring_w[k]};
  for (int k = 0; k < wl.size(); ++k)
    if (wl.touching[k]) after[{wl.grain[k], -1 - wl.wall[k]}] = {wl.spring_t[k], wl.spring_r[k], wl.spring_w[k]};
  EXPECT_EQ(after.size(), before.size() - lost);
  int nonzero = 0;
  for (const auto& e : before) {
    const int i = to[e.first.first], j = e.first.second >= 0 ? to[e.first.second] : e.first.second;
    if (i < 0 || (e.first.second >= 0 && j < 0)) continue;
    const auto it = after.find({i, j});
    ASSERT_NE(it, after.end()) << "contact " << e.first.first << "-" << e.first.second << " lost";
    EXPECT_EQ(std::get<0>(it->second), std::get<0>(e.second));
    EXPECT_EQ(std::get<1>(it->second), std::get<1>(e.second));
    EXPECT_EQ(std::get<2>(it->second), std::get<2>(e.second));
    nonzero += std::get<0>(e.second).norm() > 0;
  }
  EXPECT_GT(nonzero, 20);
}

// The scenario wrapper shrinks the grain groups around the removed grains.
TEST(Edit, ScenarioRemovalShrinksGroups) {
  rt::Scenario sc = rt::parse_scenario_text(R"(name: groups
materials:
  grain: {preset: moderate}
contact: {model: linear, kn: rule, v_max: 0.19, x_max: 0.01, steps_per_contact: 30}
grains:
  - name: low
    material: grain
    radius: 0.01
    fill: {shape: box, lo: [0, 0, 0], hi: [0.2, 0.2, 0.1], count: 50}
  - name: high
    material: grain
    radius: 0.01
    fill: {shape: box, lo: [0, 0, 0.2], hi: [0.2, 0.2, 0.3], count: 30}
stages:
  - {name: rest, duration: 0.01}
)");
  ASSERT_EQ(sc.model.n_grains, 80);
  const rt::Scenario before = sc;
  rt::State s = sc.initial;
  std::vector<uint8_t> drop(80, 0);
  for (int i = 0; i < 80; i += 3) drop[i] = 1;  // 17 of the 50, 10 of the 30
  EXPECT_EQ(rt::remove_grains(sc, s, drop), 27);
  EXPECT_EQ(sc.model.n_grains, 53);
  ASSERT_NE(sc.group("low"), nullptr);
  EXPECT_EQ(sc.group("low")->first, 0);
  EXPECT_EQ(sc.group("low")->count, 33);
  EXPECT_EQ(sc.group("high")->first, 33);
  EXPECT_EQ(sc.group("high")->count, 20);
  int k = 0;
  for (int i = 0; i < 80; ++i)
    if (!drop[i]) {
      EXPECT_EQ(s.pos[k++], before.initial.pos[i]);
    }
}

}  // namespace

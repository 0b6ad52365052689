// Equal states give equal checkpoint files: a body state's padding bytes
// (whatever memory held before) do not reach the file.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <string>

#include "regolith_twin/io/checkpoint.hpp"
#include "test_support.hpp"

namespace {

std::string bytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

}  // namespace

TEST(CheckpointBytes, PaddingOfBodyStatesDoesNotReachTheFile) {
  rt::Model m;
  m.materials.push_back(rt::test::simple_material("g", 2500, 0.5, 0.5, 0.5));
  rt::add_grain(m, 0.01, 0);
  rt::BodyModel b;
  b.name = "box";
  b.mass = 1;
  b.inertia = rt::Vec3::Constant(1e-3);
  rt::Shape sh;
  sh.type = rt::ShapeType::Box;
  sh.size = rt::Vec3::Constant(0.05);
  b.shapes.push_back(sh);
  m.bodies.push_back(b);
  m.kn = 1e3;
  m.dt = 1e-4;
  rt::finalize_model(m);
  rt::State a = rt::make_state(m);
  a.bodies[0].pos = rt::Vec3(0.1, 0.2, 0.3);
  rt::State c = a;
  // The same body state in storage that held other bytes before.
  const rt::BodyState keep = a.bodies[0];
  std::memset(static_cast<void*>(&c.bodies[0]), 0xAB, sizeof(rt::BodyState));
  rt::BodyState& o = c.bodies[0];
  o.pos = keep.pos, o.q = keep.q, o.vel = keep.vel, o.omega = keep.omega, o.vel_mid = keep.vel_mid;
  o.omega_mid = keep.omega_mid, o.ang_mom = keep.ang_mom, o.force = keep.force, o.torque = keep.torque;
  o.pos_at_build = keep.pos_at_build, o.q_at_build = keep.q_at_build;
  const std::string pa = "/tmp/regolith_ckpt_bytes_a_" + std::to_string(::getpid());
  const std::string pc = "/tmp/regolith_ckpt_bytes_c_" + std::to_string(::getpid());
  rt::save_checkpoint(pa, m, a);
  rt::save_checkpoint(pc, m, c);
  EXPECT_EQ(bytes(pa), bytes(pc));
  std::remove(pa.c_str());
  std::remove(pc.c_str());
}

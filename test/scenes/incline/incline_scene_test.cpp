// The inclined-plane scene kind (docs/scenes.md C.2): the Bagnold fit gives
// back the amplitude of an exact Bagnold profile, and the inertial number
// of Bagnold's solution for a chosen I; bad input is refused.
#include <gtest/gtest.h>

#include <cmath>

#include "regolith_twin/core/model.hpp"
#include "regolith_twin/scenes/incline/incline_scene.hpp"

namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(Bagnold, FitAndInertialNumberOfAnExactProfile) {
  // Bagnold's profile for I = 0.3, d = 1 cm, h = 0.25 m, Phi = 0.58, theta = 25 deg:
  // v(z) = (2 I h^1.5 / (3 d)) sqrt(Phi g cos theta) [1 - (1 - z/h)^1.5].
  const double I = 0.3, d = 0.01, h = 0.25, phi = 0.58, g = 9.81, th = 25 * kPi / 180;
  const double a = 2 * I * std::pow(h, 1.5) / (3 * d) * std::sqrt(phi * g * std::cos(th));
  std::vector<double> z, v;
  for (int k = 0; k < 30; ++k) {  // 1 cm layers, some above the flow (v = 0 there, ignored)
    z.push_back((k + 0.5) * 0.01);
    v.push_back(z.back() < h ? a * (1 - std::pow(1 - z.back() / h, 1.5)) : 0.0);
  }
  double rms = 1;
  const double fit = rt::bagnold_amplitude(z, v, h, &rms);
  EXPECT_NEAR(fit, a, 1e-12 * a);
  EXPECT_LT(rms, 1e-12);
  EXPECT_NEAR(rt::bagnold_inertial_number(fit, d, h, phi, g, th), I, 1e-12);
  // A uniform profile is no Bagnold profile: the residual says so.
  std::vector<double> flat(z.size(), 1.0);
  rt::bagnold_amplitude(z, flat, h, &rms);
  EXPECT_GT(rms, 0.1);
}

TEST(InclineScene, BadInputIsRefused) {
  rt::SceneOptions o;
  o.quiet = true;
  o.cache_dir = ::testing::TempDir() + "/incline_cache";
  auto refused = [&o](const std::vector<std::string>& set, const std::string& what) {
    try {
      rt::load_scene("config/incline_moderate.yaml", set, o);
      ADD_FAILURE() << "accepted: " << what;
    } catch (const rt::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  refused({"incline.mode=tilt"}, "incline.mode");
  refused({"incline.angle_deg=95"}, "incline.angle_deg");
  refused({"incline.average=10"}, "incline.average");  // longer than the run
  refused({"periodic.y=null"}, "periodic");
}

}  // namespace

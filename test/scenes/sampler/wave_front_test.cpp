// The wave-attenuation fit stops at the wave front (docs/scenes.md B.4): a
// speed profile that follows a known power law out to a front and a slower
// precursor beyond it (flat, or falling off far more steeply) gives the known
// exponent from the bins up to the front only, with the front bin, the fitted
// range and the precursor's level recorded.
//
// Before the front was looked for, the fit ran from the first bin beyond the
// projectile to the last bin above the noise floor, i.e. through the
// precursor: on the profiles of WaveAttenuation.FitStopsAtTheFront it gave
// slopes of -4.43 (a flat precursor at 0.05 m/s after a d^-1.7 wave) and
// -6.05 (a d^-25 precursor after a d^-2.5 wave) from bins 3-35 and 3-29, and
// that test fails on it (checked against that code).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "regolith_twin/core/edit.hpp"
#include "regolith_twin/core/walls.hpp"
#include "regolith_twin/scenes/sampler/impact_observers.hpp"
#include "test_support.hpp"

namespace {

using rt::Vec3;

constexpr double kPi = 3.14159265358979323846;
constexpr double kBin = 2.5e-3;
constexpr double kDt = 1e-6;

double mid(int k) { return (k + 0.5) * kBin; }

std::vector<int> range(int a, int b) {
  std::vector<int> v;
  for (int k = a; k <= b; ++k) v.push_back(k);
  return v;
}

// Bed grains on a ray 30 deg from the downward vertical through the impact
// point, one at the middle distance of each bin, and the projectile touching a
// plane wall far above: one step makes the clock see the impact and leaves the
// bed where it was (as in impact_observers_test.cpp).
struct Ray {
  rt::Model m;
  rt::State s;
  int p = 0;
};

Ray ray(const Vec3& impact, int bins) {
  Ray y;
  y.m.materials.push_back(rt::test::simple_material("grain", 2430, 0.5, 0.5, 0.5));
  y.m.gravity.setZero();
  y.m.walls.push_back(rt::make_plane(Vec3(0, 0, 10), -Vec3::UnitZ(), 0));
  for (int k = 0; k < bins; ++k) rt::add_grain(y.m, 2e-4, 0);
  y.p = rt::add_grain(y.m, 4e-3, 0);
  y.m.kn = 1e5;
  y.m.dt = kDt;
  rt::finalize_model(y.m);
  y.s = rt::make_state(y.m);
  const Vec3 dir(std::sin(kPi / 6), 0, -std::cos(kPi / 6));
  for (int k = 0; k < bins; ++k) y.s.pos[k] = impact + mid(k) * dir;
  y.s.pos[y.p] = Vec3(5, 5, 10 - 4e-3 + 1e-6);
  rt::prime(y.m, y.s);
  return y;
}

void after(Ray& y, long step, double after_impact, const std::vector<rt::Observer*>& obs) {
  y.s.step = step;
  y.s.ticks = double(step);
  y.s.time = kDt + after_impact;
  for (rt::Observer* o : obs) o->after_step(y.m, y.s);
}

}  // namespace

// 40 bins; the projectile's far side 7 mm from the impact point (first bin
// beyond it: 3); bins 0-2 at 50 m/s; a power law A d^-n in bins 3-20 (bin 9
// below the floor of 10 x 1e-5 m/s, left out); beyond the front (bin 20) a
// precursor above the floor: at 12 us flat at 0.05 m/s in bins 21-35, at 62 us
// 0.3 v(front) (d/d_20)^-25 (above the floor in bins 21-29); the rest at 5e-5
// m/s, below the floor.
TEST(WaveAttenuation, FitStopsAtTheFront) {
  const Vec3 impact(0.01, 0.02, 0.0);
  const int bins = 40, front = 20;
  Ray y = ray(impact, bins);
  rt::ImpactClock c(y.p);
  rt::WaveOptions o;
  o.impact = impact;
  o.times = {1.2e-5, 6.2e-5};
  o.rest_rms = 1e-5;
  rt::WaveAttenuation wave(&c, o);
  const std::vector<rt::Observer*> obs{&c, &wave};
  for (rt::Observer* q : obs) q->start(y.m, y.s);
  rt::step(y.m, y.s);
  for (rt::Observer* q : obs) q->after_step(y.m, y.s);
  ASSERT_TRUE(c.hit());
  y.s.pos[y.p] = impact + Vec3(0, 0, -3e-3);  // far side 7 mm from the impact point

  const double As[] = {0.05, 2e-3}, ns[] = {1.7, 2.5};
  auto field = [&](int q) {
    const double vf = As[q] * std::pow(mid(front), -ns[q]);
    for (int k = 0; k < bins; ++k) {
      double v = 5e-5;
      if (k < 3)
        v = 50;
      else if (k <= front)
        v = k == 9 ? 5e-5 : As[q] * std::pow(mid(k), -ns[q]);
      else if (q == 0 && k <= 35)
        v = 0.05;
      else if (q == 1)
        v = std::max(5e-5, 0.3 * vf * std::pow(mid(k) / mid(front), -25.0));
      y.s.vel[k] = v * Vec3(0.6, 0, -0.8);
    }
  };
  field(0);
  after(y, 12, 1.2e-5, obs);
  field(1);
  after(y, 62, 6.2e-5, obs);
  ASSERT_EQ(wave.profiles().size(), 2u);

  const int signal_end[] = {35, 29};
  for (int q = 0; q < 2; ++q) {
    const rt::WaveProfile& w = wave.profiles()[q];
    std::vector<int> fitted = range(3, front);
    fitted.erase(fitted.begin() + (9 - 3));
    // The exponent of the wave, from its bins only.
    EXPECT_NEAR(w.slope, -ns[q], 1e-9) << q;
    EXPECT_NEAR(w.intercept, std::log(As[q]), 1e-8) << q;
    EXPECT_EQ(w.used, fitted) << q;
    EXPECT_EQ(w.first_bin, 3);
    EXPECT_EQ(w.last_bin, front) << q;
    // The front and the precursor beyond it.
    EXPECT_TRUE(w.front_found) << q;
    EXPECT_EQ(w.front_bin, front) << q;
    EXPECT_NEAR(w.front, (front + 1) * kBin, 1e-15) << q;
    EXPECT_NEAR(w.contact, 7e-3, 1e-12);
    EXPECT_EQ(w.signal_end, signal_end[q]) << q;
    EXPECT_EQ(w.precursor, range(front + 1, signal_end[q])) << q;
    const double vf = As[q] * std::pow(mid(front), -ns[q]);
    // Median of the precursor bins: 0.05 m/s flat; bin 25 of 21-29 falling off.
    const double median = q == 0 ? 0.05 : 0.3 * vf * std::pow(mid(25) / mid(front), -25.0);
    EXPECT_NEAR(w.precursor_median, median, 1e-12 * median) << q;
    EXPECT_NEAR(w.precursor_max, q == 0 ? 0.05 : 0.3 * vf * std::pow(mid(21) / mid(front), -25.0), 1e-12) << q;
    EXPECT_LT(w.break_ratio, 1e-20) << q;  // both pieces are exact
  }
}

// The front search on profiles alone (fit_wave_profile): one bin per entry,
// max speeds in m/s, the floor and the first bin given.
namespace {

rt::WaveProfile profile(const std::vector<double>& v, double floor, int first_bin) {
  rt::WaveProfile w;
  w.max_speed = v;
  w.grains.assign(v.size(), 1);
  w.floor = floor;
  w.first_bin = first_bin;
  rt::fit_wave_profile(w, kBin);
  return w;
}

// A fixed pattern of ±25 % (in the logarithm: about ±0.22) standing in for the
// scatter of the largest speed between neighbouring bins.
double scatter(int k) {
  static const double f[] = {0.22, -0.18, 0.05, -0.22, 0.14, -0.03, 0.19, -0.11, -0.2, 0.08, 0.12};
  return f[k % 11];
}

}  // namespace

// A d^-1.6 wave with scatter out to bin 45 and, beyond it, a precursor that
// falls off as exp(-(d - d_45)/4 mm) from a quarter of the wave's speed
// (a curved tail, not a power law) down to the floor: the front is bin 45 and
// the exponent within the scatter's error of 1.6.
TEST(WaveFront, NoisyWaveAndCurvedPrecursor) {
  const int front = 45, n = 100;
  std::vector<double> v(n, 1e-7);
  for (int k = 2; k <= front; ++k) v[k] = 20 * std::pow(mid(k) / mid(2), -1.6) * std::exp(scatter(k));
  const double vf = 20 * std::pow(mid(front) / mid(2), -1.6);
  for (int k = front + 1; k < n; ++k) v[k] = std::max(1e-7, 0.25 * vf * std::exp(-(mid(k) - mid(front)) / 4e-3));
  const rt::WaveProfile w = profile(v, 1e-6, 2);
  EXPECT_TRUE(w.front_found);
  EXPECT_EQ(w.front_bin, front);
  EXPECT_EQ(w.used, range(2, front));
  EXPECT_NEAR(w.slope, -1.6, 0.05);
  ASSERT_FALSE(w.precursor.empty());
  EXPECT_EQ(w.precursor.front(), front + 1);
  EXPECT_EQ(w.precursor.back(), w.signal_end);
  EXPECT_GT(w.signal_end, front + 10);
  EXPECT_LT(w.precursor_max, 0.25 * vf);
  // The same profile fitted through the precursor (the old range) is far steeper.
  std::vector<double> xs, ys;
  for (int k = 2; k <= w.signal_end; ++k) xs.push_back(std::log(mid(k))), ys.push_back(std::log(v[k]));
  const double mx = std::accumulate(xs.begin(), xs.end(), 0.0) / xs.size(),
               my = std::accumulate(ys.begin(), ys.end(), 0.0) / ys.size();
  double sxx = 0, sxy = 0;
  for (size_t q = 0; q < xs.size(); ++q) sxx += (xs[q] - mx) * (xs[q] - mx), sxy += (xs[q] - mx) * (ys[q] - my);
  EXPECT_LT(sxy / sxx, -3.0);
}

// No precursor: a power law down to the floor, exact or with scatter, is
// fitted whole (no break is taken for a front); the front is then the last
// bin above the floor.
TEST(WaveFront, PowerLawWithoutPrecursorIsNotCut) {
  const int n = 40;
  for (bool noisy : {false, true}) {
    std::vector<double> v(n, 1e-7);
    for (int k = 3; k < 34; ++k) v[k] = 100 * std::pow(mid(k) / mid(3), -2.0) * (noisy ? std::exp(scatter(k)) : 1.0);
    const rt::WaveProfile w = profile(v, 1e-6, 3);
    EXPECT_FALSE(w.front_found) << noisy;
    EXPECT_EQ(w.front_bin, 33) << noisy;
    EXPECT_EQ(w.signal_end, 33) << noisy;
    EXPECT_EQ(w.last_bin, 33) << noisy;
    EXPECT_EQ(w.used, range(3, 33)) << noisy;
    EXPECT_TRUE(w.precursor.empty()) << noisy;
    EXPECT_TRUE(std::isnan(w.precursor_median)) << noisy;
    EXPECT_NEAR(w.slope, -2.0, noisy ? 0.1 : 1e-10) << noisy;
    EXPECT_GE(w.break_ratio, 0.5) << noisy;
  }
}

// A precursor that is faster than the wave's speed at the front is no drop:
// the profile is fitted whole. Too few bins for two pieces of three: no
// front search. Nothing above the floor: no fit.
TEST(WaveFront, RisingTailShortProfilesAndSilence) {
  std::vector<double> v(30, 1e-7);
  for (int k = 3; k <= 15; ++k) v[k] = 50 * std::pow(mid(k) / mid(3), -2.0);
  for (int k = 16; k < 30; ++k) v[k] = 100;
  rt::WaveProfile w = profile(v, 1e-6, 3);
  EXPECT_FALSE(w.front_found);
  EXPECT_EQ(w.front_bin, 29);
  EXPECT_EQ(w.used, range(3, 29));

  std::vector<double> s(10, 1e-7);
  for (int k = 3; k <= 7; ++k) s[k] = 10 * std::pow(mid(k), -1.0);
  w = profile(s, 1e-6, 3);
  EXPECT_FALSE(w.front_found);
  EXPECT_EQ(w.front_bin, 7);
  EXPECT_EQ(w.used, range(3, 7));
  EXPECT_NEAR(w.slope, -1.0, 1e-10);
  EXPECT_TRUE(std::isnan(w.break_ratio));

  w = profile(std::vector<double>(10, 1e-7), 1e-6, 3);
  EXPECT_FALSE(w.front_found);
  EXPECT_EQ(w.signal_end, -1);
  EXPECT_EQ(w.front_bin, -1);
  EXPECT_TRUE(w.used.empty());
  EXPECT_TRUE(std::isnan(w.slope));
  EXPECT_TRUE(std::isnan(w.front));
}

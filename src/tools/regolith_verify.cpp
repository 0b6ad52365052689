// regolith_verify OUTDIR: analytic collision verification of the engine.
// regolith_verify --pair STEPS_PER_CONTACT EPS_N [PHASES]: the restitution of
//   one linear grain-grain and grain-wall collision at that resolution (t_c/dt),
//   over PHASES entry phases (default 50), as JSON on stdout.
// Writes CSV tables for scripts/plot_verification.py and prints a summary:
//   restitution_convergence.csv  linear law, eps_n measured over entry phases vs N
//   contact_duration.csv         linear law, measured vs analytic duration and max overlap
//   convergence_slopes.csv       fitted order of mean |error| vs N per eps_n
//   chung_ooi_test12.csv         Hertz tests 1-2: max overlap, max force, contact time
//   chung_ooi_test3.csv          e_out vs e_in (docs/model.md §3 prefactor and calibrated prefactor)
//   chung_ooi_test4.csv          oblique impacts: v_t'/v_t, omega R/v, rebound angles
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "regolith_twin/validate/collisions.hpp"

namespace rv = rt::validate;

namespace {

FILE* open_csv(const std::filesystem::path& dir, const char* name, const char* header) {
  const auto path = dir / name;
  FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw std::runtime_error("cannot write " + path.string());
  std::fprintf(f, "%s\n", header);
  return f;
}

double pct(double measured, double ref) { return 100.0 * (measured - ref) / ref; }

}  // namespace

// --pair: sweep_phases takes N of dt = pi sqrt(m_p / (2 k_n)) / N, so that
// t_c / dt = N sqrt(1 + ln^2(eps) / pi^2) for the linear law (docs/model.md §2).
int pair_at_resolution(int argc, char** argv) {
  if (argc < 4 || argc > 5) {
    std::fprintf(stderr, "usage: regolith_verify --pair STEPS_PER_CONTACT EPS_N [PHASES]\n");
    return 2;
  }
  const double spc = std::stod(argv[2]), eps = std::stod(argv[3]);
  const int phases = argc == 5 ? std::stoi(argv[4]) : 50;
  if (!(spc > 1) || !(eps > 0 && eps <= 1) || phases < 1) {
    std::fprintf(stderr, "regolith_verify --pair: need STEPS_PER_CONTACT > 1, 0 < EPS_N <= 1, PHASES >= 1\n");
    return 2;
  }
  const double l = std::log(eps) / M_PI;
  const double N = spc / std::sqrt(1 + l * l);
  std::printf("{\"steps_per_contact\": %.4f, \"eps_n\": %.4f, \"phases\": %d", spc, eps, phases);
  for (rv::PairKind kind : {rv::PairKind::GrainGrain, rv::PairKind::GrainWall}) {
    const rv::PhaseSweep ps = rv::sweep_phases(kind, eps, N, phases);
    std::printf(", \"%s\": {\"eps_mean\": %.6f, \"eps_min\": %.6f, \"eps_max\": %.6f, \"mean_error\": %.6f, "
                "\"worst_abs_error\": %.6f, \"max_overlap_over_xmax\": %.4f, \"all_ended\": %s}",
                rv::pair_kind_name(kind), ps.eps_mean, ps.eps_min, ps.eps_max, ps.mean_error, ps.worst_abs_error,
                ps.max_overlap_ratio, ps.all_ended ? "true" : "false");
  }
  std::printf("}\n");
  return 0;
}

int main(int argc, char** argv) {
  if (argc >= 2 && std::string(argv[1]) == "--pair") try {
      return pair_at_resolution(argc, argv);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "regolith_verify: %s\n", e.what());
      return 2;
    }
  if (argc != 2 || std::string(argv[1]) == "-h" || std::string(argv[1]) == "--help") {
    std::fprintf(stderr, "usage: regolith_verify OUTDIR | regolith_verify --pair STEPS_PER_CONTACT EPS_N [PHASES]\n");
    return argc == 2 ? 0 : 2;
  }
  try {
    const std::filesystem::path dir(argv[1]);
    std::filesystem::create_directories(dir);

    // --- 1. linear law: restitution convergence over entry phases ------------
    const int phases = 100;
    const std::vector<double> eps_list = {0.1, 0.3, 0.5, 0.7, 0.9, 1.0};
    const std::vector<double> Ns = rv::convergence_steps();
    FILE* fc = open_csv(dir, "restitution_convergence.csv",
                        "pair,eps_n,N,steps_per_contact,phases,eps_mean,eps_min,eps_max,"
                        "mean_error,mean_abs_error,worst_abs_error");
    FILE* fd = open_csv(dir, "contact_duration.csv",
                        "pair,eps_n,N,t_contact_s,dt_s,steps_per_contact,worst_duration_error_steps,"
                        "max_overlap_over_xmax");
    FILE* fs = open_csv(dir, "convergence_slopes.csv", "pair,eps_n,slope,mean_abs_error_N30");
    std::printf("linear law, %d entry phases per point (relative errors in %%)\n", phases);
    std::printf("%-11s %5s %6s | %9s %9s %9s | %9s %7s\n", "pair", "eps", "N", "mean err", "worst", "mean|err|",
                "dur/dt", "x/xmax");
    for (rv::PairKind kind : {rv::PairKind::GrainGrain, rv::PairKind::GrainWall})
      for (double eps : eps_list) {
        std::vector<double> errs;
        double err30 = 0;
        for (double N : Ns) {
          const rv::PhaseSweep ps = rv::sweep_phases(kind, eps, N, phases);
          std::fprintf(fc, "%s,%.2f,%g,%.4f,%d,%.10f,%.10f,%.10f,%.6e,%.6e,%.6e\n", rv::pair_kind_name(kind), eps, N,
                       ps.steps_per_contact, phases, ps.eps_mean, ps.eps_min, ps.eps_max, ps.mean_error,
                       ps.mean_abs_error, ps.worst_abs_error);
          std::fprintf(fd, "%s,%.2f,%g,%.6e,%.6e,%.4f,%.4f,%.6f\n", rv::pair_kind_name(kind), eps, N, ps.t_contact,
                       ps.dt, ps.steps_per_contact, ps.worst_duration_error, ps.max_overlap_ratio);
          errs.push_back(std::max(ps.mean_abs_error, rv::kRoundingLevel));
          if (N == 30) {
            err30 = ps.mean_abs_error;
            std::printf("%-11s %5.2f %6g | %9.4f %9.4f %9.4f | %9.3f %7.4f\n", rv::pair_kind_name(kind), eps, N,
                        100 * ps.mean_error, 100 * ps.worst_abs_error, 100 * ps.mean_abs_error,
                        ps.worst_duration_error, ps.max_overlap_ratio);
          }
        }
        const double slope = rv::loglog_slope(Ns, errs);
        std::fprintf(fs, "%s,%.2f,%.4f,%.6e\n", rv::pair_kind_name(kind), eps, slope, err30);
        std::printf("%-11s %5.2f  slope of mean |error| vs N over %g..%g: %.3f\n", rv::pair_kind_name(kind), eps,
                    Ns.front(), Ns.back(), slope);
      }
    std::fclose(fc);
    std::fclose(fd);
    std::fclose(fs);

    // --- 2. Chung & Ooi tests 1 and 2 ------------------------------------------
    FILE* f12 = open_csv(dir, "chung_ooi_test12.csv",
                         "test,material,quantity,analytic,measured,error_pct,steps_per_contact,dt");
    std::printf("\nChung & Ooi tests 1-2 (Hertz, elastic)\n");
    std::vector<rv::ElasticBenchmark> bench = {
        rv::chung_ooi_test1(rv::chung_ooi_glass()), rv::chung_ooi_test1(rv::chung_ooi_limestone()),
        rv::chung_ooi_test2(rv::chung_ooi_aluminium_alloy()), rv::chung_ooi_test2(rv::chung_ooi_magnesium_alloy())};
    for (const auto& b : bench) {
      const struct {
        const char* q;
        double a, m;
      } rows[] = {{"max_overlap_m", b.analytic.max_overlap, b.measured.max_overlap},
                  {"max_force_N", b.analytic.max_force, b.measured.max_force},
                  {"contact_time_s", b.analytic.contact_time, b.measured.t_measured}};
      for (const auto& r : rows) {
        std::fprintf(f12, "%s,%s,%s,%.8e,%.8e,%.4f,%.1f,%.6e\n", b.test.c_str(), b.material.c_str(), r.q, r.a, r.m,
                     pct(r.m, r.a), b.measured.steps_per_contact, b.measured.dt);
        std::printf("  %s %-16s %-15s analytic %.5e measured %.5e (%+.3f %%)\n", b.test.c_str(), b.material.c_str(),
                    r.q, r.a, r.m, pct(r.m, r.a));
      }
    }
    std::fclose(f12);

    // --- 3. Chung & Ooi test 3 ---------------------------------------------------
    FILE* f3 = open_csv(dir, "chung_ooi_test3.csv",
                        "e_in,alpha_model,e_ode_model,e_out_model,dev_model_pct,alpha_calibrated,e_out_calibrated,"
                        "dev_calibrated_pct,steps_per_contact");
    std::printf("\nChung & Ooi test 3 (aluminium oxide on a rigid plane, 3.9 m/s)\n");
    std::printf("  %5s | %8s %8s %8s %8s | %8s %8s %8s\n", "e_in", "a_model", "e_ode", "e_out", "dev%", "a_calib",
                "e_out", "dev%");
    for (int k = 2; k <= 10; ++k) {
      const double e = 0.1 * k;
      const rv::RestitutionRow r = rv::chung_ooi_test3(e);
      std::fprintf(f3, "%.2f,%.8f,%.8f,%.8f,%.4f,%.8f,%.8f,%.4f,%.1f\n", e, r.alpha_model, r.e_ode_model,
                   r.e_out_model, pct(r.e_out_model, e), r.alpha_calibrated, r.e_out_calibrated,
                   pct(r.e_out_calibrated, e), r.steps_per_contact);
      std::printf("  %5.2f | %8.5f %8.5f %8.5f %+8.3f | %8.5f %8.5f %+8.3f\n", e, r.alpha_model, r.e_ode_model,
                  r.e_out_model, pct(r.e_out_model, e), r.alpha_calibrated, r.e_out_calibrated,
                  pct(r.e_out_calibrated, e));
    }
    std::fclose(f3);

    // --- 4. Chung & Ooi test 4 ---------------------------------------------------
    FILE* f4 = open_csv(dir, "chung_ooi_test4.csv",
                        "angle_deg,vt_ratio,omega_r_over_v,rebound_deg,patch_rebound_deg,e_n,"
                        "vt_ratio_rigid,omega_r_over_v_rigid,rebound_deg_rigid,patch_rebound_deg_rigid,"
                        "gross_sliding_rigid,vt_ratio_sliding,omega_r_over_v_sliding,psi1,psi2,slid_throughout,"
                        "vt_ratio_fine,omega_r_over_v_fine,steps_per_contact");
    std::printf("\nChung & Ooi test 4 (aluminium oxide, 3.9 m/s, mu 0.092, e 0.98)\n");
    std::printf("  %5s | %8s %8s %8s | %8s %8s | %8s %8s | %s\n", "angle", "vt'/vt", "wR/v", "reb.deg", "slide",
                "slide", "rigid", "rigid", "slid");
    for (int a = 1; a <= 17; ++a) {
      const double ang = 5.0 * a;
      const rv::ObliqueRow r = rv::chung_ooi_test4(ang);
      const rv::ObliqueRow f = rv::chung_ooi_test4(ang, 4000);
      std::fprintf(f4, "%.1f,%.8f,%.8f,%.6f,%.6f,%.8f,%.8f,%.8f,%.6f,%.6f,%d,%.8f,%.8f,%.6f,%.6f,%d,%.8f,%.8f,%.1f\n",
                   ang, r.vt_ratio, r.omega_r_over_v, r.rebound_deg, r.patch_rebound_deg, r.e_n, r.vt_ratio_rigid,
                   r.omega_r_over_v_rigid, r.rebound_deg_rigid, r.patch_rebound_deg_rigid, int(r.gross_sliding_rigid),
                   r.vt_ratio_sliding, r.omega_r_over_v_sliding, r.psi1, r.psi2, int(r.slid_throughout), f.vt_ratio,
                   f.omega_r_over_v, r.steps_per_contact);
      std::printf("  %5.1f | %8.5f %8.5f %8.3f | %8.5f %8.5f | %8.5f %8.5f | %d\n", ang, r.vt_ratio,
                  r.omega_r_over_v, r.rebound_deg, r.vt_ratio_sliding, r.omega_r_over_v_sliding, r.vt_ratio_rigid,
                  r.omega_r_over_v_rigid, int(r.slid_throughout));
    }
    std::fclose(f4);
    std::printf("\nwrote CSV files to %s\n", dir.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "regolith_verify: %s\n", e.what());
    return 1;
  }
  return 0;
}

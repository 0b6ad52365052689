// Compute-bound OpenMP microbenchmark: how much floating-point throughput
// does this machine deliver at 1 thread and at 2 (or N) threads?
//
// Each thread works on its own small array (4 KiB, resident in L1) and
// applies a chain of 16 multiply-adds to every element per sweep, so the
// work is limited by the floating-point units, not by memory.  Every thread
// does the same amount of work (weak scaling): with T threads on T free
// cores the wall time stays constant and the throughput grows T-fold.
//
// Build and run (bench/peers.sh micro does this):
//   g++ -O2 -fopenmp bench/omp_micro.cpp -o omp_micro
//   ./omp_micro [seconds_at_1_thread=1.0] [max_threads=2]
//
// Output (machine-readable):
//   MICRO threads=1 seconds=... gflops=...
//   MICRO threads=2 seconds=... gflops=...
//   MICRO ratio_2_over_1=...
#include <omp.h>

#include <cstdio>
#include <cstdlib>
#include <vector>

namespace {

constexpr int kElems = 512;        // 512 doubles = 4 KiB per thread
constexpr int kChain = 16;         // multiply-adds per element per sweep
constexpr double kFlopsPerElem = 2.0 * kChain;

// One thread's work: `sweeps` passes over its private array.  The
// coefficients keep every value bounded (fixed point b / (1 - a)).
double run_private(long sweeps, int seed) {
  alignas(64) double buf[kElems];
  for (int i = 0; i < kElems; ++i) buf[i] = 1.0 + 1e-3 * ((i + seed) % 17);
  const double a = 0.9999993;
  const double b = 1.0e-7;
  for (long s = 0; s < sweeps; ++s) {
    for (int i = 0; i < kElems; ++i) {
      double v = buf[i];
      for (int k = 0; k < kChain; ++k) v = v * a + b;
      buf[i] = v;
    }
  }
  double sum = 0.0;
  for (int i = 0; i < kElems; ++i) sum += buf[i];
  return sum;
}

struct Timing {
  double seconds;
  double checksum;
};

// All `threads` threads run `sweeps` sweeps each, concurrently.
Timing run_team(int threads, long sweeps) {
  std::vector<double> sums(static_cast<size_t>(threads), 0.0);
  const double t0 = omp_get_wtime();
#pragma omp parallel num_threads(threads)
  {
    const int id = omp_get_thread_num();
    sums[static_cast<size_t>(id)] = run_private(sweeps, id);
  }
  const double t1 = omp_get_wtime();
  double total = 0.0;
  for (double s : sums) total += s;
  return {t1 - t0, total};
}

}  // namespace

int main(int argc, char** argv) {
  const double target = argc > 1 ? std::atof(argv[1]) : 1.0;
  const int max_threads = argc > 2 ? std::atoi(argv[2]) : 2;
  if (target <= 0.0 || max_threads < 1) {
    std::fprintf(stderr, "usage: %s [seconds_at_1_thread>0] [max_threads>=1]\n", argv[0]);
    return 2;
  }

  // Calibrate the number of sweeps so one thread runs for ~target seconds.
  long sweeps = 1000;
  for (;;) {
    const Timing t = run_team(1, sweeps);
    if (t.seconds > 0.05) {
      sweeps = static_cast<long>(static_cast<double>(sweeps) * target / t.seconds) + 1;
      break;
    }
    sweeps *= 4;
  }

  double gflops_1 = 0.0;
  double checksum = 0.0;
  for (int threads = 1; threads <= max_threads; ++threads) {
    if (threads != 1 && threads != 2 && threads != max_threads) continue;
    const Timing t = run_team(threads, sweeps);
    const double flops = kFlopsPerElem * kElems * static_cast<double>(sweeps) * threads;
    const double gflops = flops / t.seconds * 1e-9;
    if (threads == 1) gflops_1 = gflops;
    checksum += t.checksum;
    std::printf("MICRO threads=%d seconds=%.4f gflops=%.4f\n", threads, t.seconds, gflops);
    if (threads > 1) {
      std::printf("MICRO ratio_%d_over_1=%.4f\n", threads, gflops / gflops_1);
    }
  }
  // Printing the checksum keeps the compiler from discarding the work.
  std::printf("MICRO checksum=%.6f omp_max_threads=%d\n", checksum, omp_get_max_threads());
  return 0;
}

// One-core memory bandwidth at a given working set: what one thread can
// stream through the caches this machine gives it, to compare with the
// bytes a B1 step moves (docs/bench/b1_throughput.md, "Where the 1-thread time goes").
//
// Three arrays of doubles fill the working set; a[i] = b[i] + s c[i] is run
// repeatedly and the best pass counts (3 doubles moved per element, the
// write-allocate read of a not counted, as in STREAM).
//
// Build and run (bench/peers.sh triad does this):
//   g++ -O3 -march=native bench/mem_triad.cpp -o mem_triad
//   ./mem_triad [working_set_MB=18] [passes=30]
//
// Output (machine-readable):
//   TRIAD mb=18 gbps=...
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

int main(int argc, char** argv) {
  const double mb = argc > 1 ? std::atof(argv[1]) : 18.0;
  const int passes = argc > 2 ? std::atoi(argv[2]) : 30;
  if (!(mb > 0) || passes < 1) {
    std::fprintf(stderr, "usage: mem_triad [working_set_MB > 0] [passes >= 1]\n");
    return 2;
  }
  const size_t n = size_t(mb * 1024 * 1024 / (3 * sizeof(double)));
  std::vector<double> a(n, 1.0), b(n, 2.0), c(n, 3.0);
  double best = 0, check = 0;
  for (int p = 0; p < passes; ++p) {
    const double s = 1.0 + 1e-9 * p;
    const auto t0 = std::chrono::steady_clock::now();
    for (size_t i = 0; i < n; ++i) a[i] = b[i] + s * c[i];
    const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    best = std::max(best, 3.0 * sizeof(double) * double(n) / sec / 1e9);
    check += a[n / 2];
  }
  std::printf("TRIAD mb=%g gbps=%.1f checksum=%.6g\n", mb, best, check);
  return 0;
}

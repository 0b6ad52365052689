// regolith_land: the same command line as regolith_sim (run/cli.hpp), under
// the name the landing campaigns and docs use:
//   regolith_land LANDING.yaml [--out DIR] [--threads N] [--set key=value ...] [--cache DIR] [--quiet]
#include "regolith_twin/run/cli.hpp"

int main(int argc, char** argv) { return rt::run_cli(argc, argv, "regolith_land"); }

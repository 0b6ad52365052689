// regolith_sim: run any scene file headless (run/cli.hpp).
#include "regolith_twin/run/cli.hpp"

int main(int argc, char** argv) { return rt::run_cli(argc, argv, "regolith_sim"); }

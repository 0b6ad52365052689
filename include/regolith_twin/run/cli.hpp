// The command line of regolith_sim and regolith_land (one parser, one path):
//   TOOL SCENE.yaml [--out DIR] [--threads N] [--set key=value]... [--cache DIR]
//        [--snapshot F] [--checkpoint F] [--stage-snapshots] [--quiet]
// Any scene kind runs; exit codes: 0 done, 2 bad input, 3 numerical blow-up
// (outputs so far kept), 1 other error.
#pragma once

namespace rt {

int run_cli(int argc, char** argv, const char* tool);

}  // namespace rt

// The command line: `mcrt devices`, `mcrt render`, `mcrt bench` (DESIGN.md "Command line").
#pragma once

namespace mcrt {

// Runs the command; returns the exit status (0, 1 runtime failure, 2 bad usage or input).
int run_cli(int argc, char** argv);

}  // namespace mcrt

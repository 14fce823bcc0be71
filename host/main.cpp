#include "cli/cli.h"

int main(int argc, char** argv) { return mcrt::run_cli(argc, argv); }

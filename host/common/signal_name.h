// How a signal is named in messages: its number, abbreviation and description.
#pragma once

#include <string>

namespace mcrt {

// "signal 11 (SIGSEGV, Segmentation fault)"
std::string signal_name(int sig);

// "SIGTERM" (or "signal N" for one without an abbreviation)
std::string signal_abbreviation(int sig);

}  // namespace mcrt

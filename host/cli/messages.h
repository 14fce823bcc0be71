// What the commands print on stderr besides their one error line (printed by run_cli).
#pragma once

#include <string>

namespace mcrt {

// "mcrt: warning: MESSAGE" on stderr.
void print_warning(const std::string& message);

}  // namespace mcrt

#include "cli/messages.h"

#include <iostream>

namespace mcrt {

void print_warning(const std::string& message) {
    std::cerr << "mcrt: warning: " << message << std::endl;
}

}  // namespace mcrt

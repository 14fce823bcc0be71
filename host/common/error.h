// Error kinds; only main() turns them into exit statuses (DESIGN.md "Exit status").
#pragma once

#include <stdexcept>
#include <string>

namespace mcrt {

// Bad usage or bad input (unreadable or invalid scene, out-of-range value): exit 2.
struct InputError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// A runtime failure (no device, kernel build failure, device out of memory): exit 1.
struct RuntimeError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

}  // namespace mcrt

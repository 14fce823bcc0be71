// Error kinds; only main() turns them into exit statuses (DESIGN.md "Exit status").
#pragma once

#include <stdexcept>
#include <string>

namespace mcrt {

// Bad usage or bad input (unreadable or invalid scene, out-of-range value): exit 2.
struct InputError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// A render setting that the render library cannot honour, exit 2: `setting` names it as
// RenderSettings does (max_depth, light_select), `detail` says the value and why ("9: at most
// 1024"); what() is both. The command line reports it under its own flag (cli/messages.h).
struct SettingError : InputError {
    SettingError(const std::string& setting, const std::string& detail)
        : InputError(setting + " " + detail), setting(setting), detail(detail) {}
    std::string setting, detail;
};

// A runtime failure (no device, kernel build failure, device out of memory): exit 1.
struct RuntimeError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

}  // namespace mcrt

#include "common/activity.h"

#include <atomic>
#include <exception>

namespace mcrt {

namespace {

constexpr int kDepth = 16;
const char* g_stack[kDepth];
std::atomic<int> g_top{0};
// The innermost activity that an exception left: the one a handler up the stack should name.
std::atomic<const char*> g_unwound{nullptr};

}  // namespace

Activity::Activity(const char* what) : exceptions_(std::uncaught_exceptions()) {
    const int at = g_top.fetch_add(1);
    if (at < kDepth) g_stack[at] = what;
    g_unwound = nullptr;
}

Activity::~Activity() {
    const int at = g_top.fetch_sub(1) - 1;
    const char* expected = nullptr;
    if (std::uncaught_exceptions() > exceptions_ && at < kDepth)
        g_unwound.compare_exchange_strong(expected, g_stack[at]);
}

std::string current_activity() {
    const int top = g_top.load();
    if (top <= 0) {
        const char* unwound = g_unwound.load();
        return unwound ? unwound : "";
    }
    return g_stack[(top < kDepth ? top : kDepth) - 1];
}

}  // namespace mcrt

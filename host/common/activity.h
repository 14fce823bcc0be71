// What the process is doing, for the message of a resource that ran out on the way ("out of host
// memory while building the BVH"): a stack of static phrases, set by scopes on the main thread.
#pragma once

#include <string>

namespace mcrt {

// Names `what` ("loading the scene", a string literal: nothing is allocated, so a scope can be
// entered and left when memory is exhausted) as the current activity for its lifetime.
class Activity {
  public:
    explicit Activity(const char* what);
    ~Activity();
    Activity(const Activity&) = delete;
    Activity& operator=(const Activity&) = delete;

  private:
    int exceptions_;  // uncaught exceptions at entry: more at exit means it is left by one
};

// The innermost activity; outside every scope, the innermost one an exception left (so that the
// handler in run_cli can name it); else "".
std::string current_activity();

}  // namespace mcrt

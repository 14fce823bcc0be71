#include "common/signal_name.h"

#include <cstring>

namespace mcrt {

std::string signal_name(int sig) {
    const char* text = sigdescr_np(sig);
    const char* abbrev = sigabbrev_np(sig);
    return "signal " + std::to_string(sig) + (abbrev ? std::string(" (SIG") + abbrev : " (") +
           (text ? std::string(", ") + text : "") + ")";
}

std::string signal_abbreviation(int sig) {
    const char* abbrev = sigabbrev_np(sig);
    return abbrev ? std::string("SIG") + abbrev : "signal " + std::to_string(sig);
}

}  // namespace mcrt

// libFuzzer target: the bytes of an estimator file through mcrt's checker
// (host/render/user_source.h), as `mcrt render --estimator-file` reads one, without OpenCL.
// Refusing a file (InputError, one line "fuzz.cl:LINE: ...") is the expected outcome for most
// inputs; anything else escaping is a crash, and so is an accepted file that breaks what the
// compiler is handed: the same bytes and lines but for blanked `#include "api.cl"` directives,
// and a text the checker accepts again unchanged (no include left to blank).
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "common/error.h"
#include "render/user_source.h"

namespace {

void require(bool condition, const char* what) {
    if (condition) return;
    std::fprintf(stderr, "fuzz_user_source: accepted source breaks the contract: %s\n", what);
    std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    mcrt::UserSource out;
    try {
        out = mcrt::check_user_source("fuzz.cl", text, "estimate");
    } catch (const mcrt::InputError& e) {
        const std::string message = e.what();
        require(message.rfind("fuzz.cl:", 0) == 0, "a refusal names the file");
        require(message.find('\n') == std::string::npos, "a refusal is one line");
        return 0;
    }
    require(out.text.size() == text.size(), "same length");
    for (size_t i = 0; i < text.size(); ++i)
        require(out.text[i] == text[i] || out.text[i] == ' ', "only blanked bytes differ");
    for (size_t i = 0; i < text.size(); ++i)
        if (out.text[i] != text[i]) require(text[i] != '\n' && text[i] != '\r', "same lines");
    mcrt::UserSource again;
    try {
        again = mcrt::check_user_source("fuzz.cl", out.text, "estimate");
    } catch (const mcrt::InputError& e) {
        std::fprintf(stderr, "fuzz_user_source: refused after blanking: %s\n", e.what());
        std::abort();
    }
    require(again.text == out.text, "no active include left after blanking");
    require(again.defines_function == out.defines_function, "the same definitions");
    return 0;
}

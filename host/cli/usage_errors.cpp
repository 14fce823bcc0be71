#include "cli/usage_errors.h"

namespace mcrt {

std::string usage_error_message(const CLI::App& app, const CLI::ParseError& error, int argc,
                                char** argv) {
    if (argc >= 2 && argv[1][0] != '-') {
        const std::string word = argv[1];
        std::string names;
        bool known = false;
        for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
            names += (names.empty() ? "" : ", ") + sub->get_name();
            known = known || sub->get_name() == word;
        }
        if (!known) return "unknown subcommand '" + word + "' (expected " + names + ")";
    }
    return error.what();
}

}  // namespace mcrt

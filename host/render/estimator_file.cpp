#include "render/estimator_file.h"

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "common/error.h"
#include "render/user_source.h"
#include "render/variants.h"

namespace mcrt {

namespace {

// The first error the build log reports in `file`, as "FILE:LINE: message", from clang's
// "FILE:LINE:COLUMN: error: message" (PoCL prefixes "error: "); "" when the log names none.
std::string first_error_in(const std::string& log, const std::string& file) {
    std::istringstream in(log);
    std::string line;
    const std::string prefix = file + ":";
    while (std::getline(in, line)) {
        size_t at = line.find(prefix);
        if (at == std::string::npos || line.find("error") == std::string::npos) continue;
        size_t digits = at + prefix.size(), end = digits;
        while (end < line.size() && std::isdigit(static_cast<unsigned char>(line[end]))) ++end;
        if (end == digits) continue;
        // The message after "LINE:COLUMN: ".
        size_t message = line.find(": ", end);
        std::string text = message == std::string::npos ? line : line.substr(message + 2);
        if (text.rfind("error: ", 0) == 0) text = text.substr(7);
        return prefix + line.substr(digits, end - digits) + ": " + text;
    }
    return "";
}

// A build error that the log reports in mcrt's own files while the estimator file caused it (a
// name both define: PoCL prints "error: render.cl:13:13: conflicting types for 'render'" and no
// note naming the first definition): "FILE:LINE: mcrt's kernels already define 'render'
// (render.cl:13:13: conflicting types for 'render')" at the line where the file names it, else
// "FILE: ..." with mcrt's first error. "" when the log has no error line.
std::string error_caused_by(const std::string& log, const std::string& file,
                            const std::string& source) {
    std::istringstream in(log);
    std::string line, first;
    while (std::getline(in, line)) {
        // A note naming the file and line (clang's "note: previous definition is here").
        if (size_t at = line.find(file + ":");
            at != std::string::npos && line.find("note") != std::string::npos && !first.empty()) {
            size_t digits = at + file.size() + 1, end = digits;
            while (end < line.size() && std::isdigit(static_cast<unsigned char>(line[end]))) ++end;
            if (end > digits) {
                // "mcrt's kernels already define 'render' (render.cl:13:13: conflicting ...)",
                // as where no note names the line (below).
                const size_t open = first.find('\''), close = first.find('\'', open + 1);
                const std::string name =
                    close == std::string::npos
                        ? std::string()
                        : " '" + first.substr(open + 1, close - open - 1) + "'";
                return file + ":" + line.substr(digits, end - digits) +
                       ": mcrt's kernels already define" + (name.empty() ? " a name of it" : name) +
                       " (" + first + ")";
            }
        }
        if (first.empty() && line.find("error") != std::string::npos) {
            first = line.rfind("error: ", 0) == 0 ? line.substr(7) : line;
            // Intel's "render.cl:13:13: error: conflicting ..." reads as PoCL's.
            if (size_t e = first.find(": error: "); e != std::string::npos) first.erase(e + 2, 7);
        }
    }
    if (first.empty()) return "";
    std::map<std::string, int> names;
    try {
        names = check_user_source(file, source, kUserEstimatorFunction).file_scope_names;
    } catch (const InputError&) {
    }
    // The first 'name' the message quotes that the file also declares at file scope.
    for (size_t open = first.find('\''); open != std::string::npos;
         open = first.find('\'', open + 1)) {
        size_t close = first.find('\'', open + 1);
        if (close == std::string::npos) break;
        auto it = names.find(first.substr(open + 1, close - open - 1));
        if (it != names.end())
            return file + ":" + std::to_string(it->second) + ": mcrt's kernels already define '" +
                   it->first + "' (" + first + ")";
        open = close;
    }
    return file + ": mcrt's kernels fail to build with this estimator file (" + first + ")";
}

}  // namespace

std::string estimator_build_error(const std::string& log, const std::string& file,
                                  const std::string& source) {
    const std::string error = first_error_in(log, file);
    if (error.empty()) return error_caused_by(log, file, source);
    // environment_radiance gained the direction with environment maps: a file written for
    // environment_radiance(scene) is told what the call is now.
    const size_t digits = file.size() + 1;
    const size_t line_number = std::strtoul(error.c_str() + digits, nullptr, 10);
    std::istringstream lines(source);
    std::string line;
    for (size_t k = 0; k < line_number && std::getline(lines, line); ++k) {
    }
    if (error.find("too few arguments") != std::string::npos &&
        line.find("environment_radiance") != std::string::npos)
        return file + ":" + std::to_string(line_number) +
               ": environment_radiance takes (scene, direction): the unit world direction the ray "
               "left the scene along, which an environment map (--env) needs "
               "(docs/ESTIMATORS.md) (" +
               error.substr(error.find(": ", digits) + 2) + ")";
    return error;
}

std::string read_estimator_file(const std::string& path) {
    std::error_code ec;
    auto status = std::filesystem::status(path, ec);
    if (ec || !std::filesystem::exists(status))
        throw SettingError("estimator_file", path + ": no such file");
    if (!std::filesystem::is_regular_file(status))
        throw SettingError("estimator_file", path + ": not a regular file");
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    if (!in) throw SettingError("estimator_file", path + ": cannot read");
    return check_estimator_source(path, text.str());
}

std::string check_estimator_source(const std::string& path, const std::string& source) {
    // Checked before any compiler sees it: includes, #line, NUL bytes, kernels, recursion,
    // private arrays (user_source.h); the text to compile has `#include "api.cl"` blanked.
    UserSource checked = check_user_source(path, source, kUserEstimatorFunction);
    // The kernel calls the user's function by name: say so before a compiler would, in mcrt's
    // own source, that it is missing.
    if (!checked.defines_function)
        throw SettingError("estimator_file", path + ": defines no function float3 " +
                                                 kUserEstimatorFunction +
                                                 "(const SceneView*, const SurfacePoint*, "
                                                 "const SampleStream*, uint*) "
                                                 "(docs/ESTIMATORS.md)");
    return checked.text;
}

}  // namespace mcrt

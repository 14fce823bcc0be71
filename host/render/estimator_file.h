// A user's estimator file (--estimator-file, or its text from the Python module): its checks
// before any compiler sees it, and what its build errors mean in the user's words.
#pragma once

#include <string>

namespace mcrt {

// The text of a user's estimator file; throws InputError when it is not a readable regular file
// or defines no `estimate` function.
std::string read_estimator_file(const std::string& path);

// The same for an estimator's text (`path` names it in messages and build errors): the text to
// compile, or InputError / SettingError("estimator_file", ...) as read_estimator_file throws.
std::string check_estimator_source(const std::string& path, const std::string& source);

// The first line of a build error that `file` (whose checked text is `source`) caused, from the
// build log: "FILE:LINE: message" where the compiler names the file, else the line of the file
// that defines a name mcrt's kernels define too, else "FILE: mcrt's kernels fail to build with
// this estimator file (...)"; "" when the log has no error line.
std::string estimator_build_error(const std::string& log, const std::string& file,
                                  const std::string& source);

}  // namespace mcrt

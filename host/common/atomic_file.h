// Outputs appear complete or not at all (DESIGN.md "Nothing is written to --out unless ...").
#pragma once

#include <functional>
#include <string>

namespace mcrt {

// Calls write(temporary_path) for a temporary file in the directory of `path`, then puts it in
// place of `path` by rename(2). Where the file system supports O_TMPFILE the temporary has no
// name while it is written (/proc/self/fd/N is passed), so nothing can remain if the process
// dies; it is linked as `.NAME.tmp-PID-N` only for the instant before the rename. Elsewhere it is
// that named sibling throughout, and stale ones whose PID is no longer alive are swept by the
// next write of the same target. If write throws, the temporary is removed and the exception
// propagates. An existing `path` that is not a regular file is never replaced (InputError).
void write_atomically(const std::string& path, const std::function<void(const std::string&)>& write);

// Removes `.NAME.tmp-PID-N` siblings of `path` left by processes that no longer exist; returns
// how many were removed.
int sweep_stale_temporaries(const std::string& path);

}  // namespace mcrt

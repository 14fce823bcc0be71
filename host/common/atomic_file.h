// Outputs appear complete or not at all (DESIGN.md "Nothing is written to --out unless ..."),
// and the outputs of one command together or not at all (ROBUSTNESS.md "Outputs that destroy").
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace mcrt {

// The files one command writes, landing together. add() each output, prepare() before any work
// (it resolves symbolic links, checks every output and creates every temporary: an output that
// cannot be written is refused then), write each output's temporary(), then commit(): under an
// exclusive flock(2) on each distinct target directory, taken in path order, every temporary is
// renamed onto its target. An OutputSet destroyed before its commit removes its temporaries and
// leaves every target as it was.
//
// Temporaries live beside the final target of each output (symbolic links followed, relative
// ones against the link's directory), so rename(2) stays within one file system and replaces
// the target, never the link. Where the file system supports O_TMPFILE the temporary has no
// name while it is written (/proc/self/fd/N is handed out), so nothing can remain if the process
// dies; it is linked as `.NAME.tmp-PID-N` only for the commit. Elsewhere it is that named sibling
// throughout, and stale ones whose PID is no longer alive are swept by prepare().
class OutputSet {
  public:
    OutputSet();
    ~OutputSet();
    OutputSet(const OutputSet&) = delete;
    OutputSet& operator=(const OutputSet&) = delete;

    // `option` names the output in messages ("--out"); an empty `path` is not requested.
    void add(const std::string& option, const std::string& path);

    // Throws InputError naming the option and the reason when an output's directory does not
    // exist, an existing output (after its links) is not a regular file, two outputs are the same
    // file, an output is one of `inputs`, a link chain does not end, or no file can be created in
    // the output's directory (read-only, /proc, no permission).
    void prepare(const std::vector<std::string>& inputs);

    // The checks of prepare() against `inputs` again (files read while loading).
    void check_inputs(const std::vector<std::string>& inputs) const;

    // Where the writer of output `path` (as added) writes: a path it opens and truncates.
    const std::string& temporary(const std::string& path) const;

    // Renames every temporary onto its target. Throws RuntimeError (temporaries removed, no
    // target changed) when a temporary cannot be linked or a target became something else than
    // a regular file; a rename that fails after others succeeded is reported the same way.
    void commit();

    // Removes the temporaries now; the set can no longer be committed.
    void discard() noexcept;

    struct Output;

  private:
    std::vector<std::unique_ptr<Output>> outputs_;
    bool prepared_ = false;
};

// Calls write(temporary_path) for a temporary beside `path`'s final target, then renames it onto
// that target: an OutputSet of one. If write throws, the temporary is removed and the exception
// propagates. An existing `path` that is not a regular file is never replaced (InputError).
void write_atomically(const std::string& path,
                      const std::function<void(const std::string&)>& write);

// Removes `.NAME.tmp-PID-N` siblings of `path` left by processes that no longer exist; returns
// how many were removed.
int sweep_stale_temporaries(const std::string& path);

}  // namespace mcrt

// Checks on the files a command will write, made before any work (ROBUSTNESS.md "Outputs that
// destroy"): nothing is replaced unless it is a regular file that no other output and no input
// names, and a symbolic link is followed to the file it names, never replaced itself.
#pragma once

#include <string>
#include <vector>

namespace mcrt {

struct OutputFile {
    std::string option;  // "--out", for messages
    std::string path;    // empty: not requested
    std::string target;  // the file `path` names after its symbolic links (resolve_output)
};

// The file that writing `path` must replace: `path` itself, or, when it is a symbolic link, what
// the chain of links ends at (relative links resolved against the link's directory; a dangling
// link's target is the file to create). Throws InputError naming `option` when the chain does
// not end (ELOOP), the target's directory does not exist or is not a directory, or the target
// exists and is not a regular file: /dev/stdout on a pipe or terminal is "a FIFO" or "a
// character device" and refused.
std::string resolve_output(const std::string& option, const std::string& path);

// Fills each output's `target` and throws InputError naming the option and the reason when
// resolve_output does, two outputs are the same file, or an output is one of `inputs`. "The same
// file": equal device and inode where both exist (hard and symbolic links included), else equal
// normalized absolute paths of the targets.
void check_outputs(std::vector<OutputFile>& outputs, const std::vector<std::string>& inputs);

}  // namespace mcrt

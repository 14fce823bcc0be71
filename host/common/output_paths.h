// Checks on the files a command will write, made before any work (ROBUSTNESS.md "Outputs that
// destroy"): nothing is replaced unless it is a regular file that no other output and no input
// names.
#pragma once

#include <string>
#include <vector>

namespace mcrt {

struct OutputFile {
    std::string option;  // "--out", for messages
    std::string path;    // empty: not requested
};

// Throws InputError naming the option and the reason when an output's directory does not exist,
// an existing output is not a regular file (directory, device, FIFO, socket), two outputs are the
// same file, or an output is one of `inputs`. "The same file": equal device and inode where both
// exist (hard and symbolic links included), else equal normalized absolute paths.
void check_outputs(const std::vector<OutputFile>& outputs, const std::vector<std::string>& inputs);

}  // namespace mcrt

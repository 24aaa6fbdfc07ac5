// Checks of an output path given on the command line, made before any long work (loading, rendering,
// training) so a typo fails in milliseconds, and so nothing the user gave as input is ever overwritten.
#pragma once
#include <string>
#include <vector>

namespace nbvh::app {

// Throws nbvh::Error (one line) when `out` (the value of `option`, e.g. "--out") is a directory, lies in a
// directory that does not exist, or is the same file as one of `inputs` (empty entries are ignored).
// An existing file that is not an input may be replaced: the user named it.
void check_output_path(const std::string& out, const char* option, const std::vector<std::string>& inputs);

// Writes `text` to `path` through a temporary file renamed into place (never a truncated file).
void write_text_atomically(const std::string& path, const std::string& text);

} // namespace nbvh::app

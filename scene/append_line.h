// scene/append_line.h: appending one line to a journal (a sweep's results.jsonl, a path's frames)
// so that a finished line survives a kill or a power loss.
#pragma once

#include <filesystem>
#include <string>

namespace shadowlab::scene {

// Appends `line` and a newline with one write() and forces it to disk before returning: a kill
// tears at most the last line. Throws InputError when the file cannot be opened or written.
void appendLine(const std::filesystem::path& file, const std::string& line);

}  // namespace shadowlab::scene

// scene/append_line.h: appending one line to a journal (a sweep's results.jsonl, a path's frames)
// so that a finished line survives a kill or a power loss, and reading those lines back.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace shadowlab::scene {

// Appends `line` and a newline with one write() and forces it to disk before returning: a kill
// tears at most the last line. Throws InputError when the file cannot be opened or written.
void appendLine(const std::filesystem::path& file, const std::string& line);

// One non-empty line of a journal: its text, its 1-based line number, and whether it is a last
// line without its newline (`torn`: what a kill in the middle of appendLine leaves).
struct JournalLine {
    std::string text;
    int number = 0;
    bool torn = false;
};

// Every non-empty line of `file`, read through the one input opener (a regular file, at most
// kMaxJournalFileBytes); none when the file does not exist. Callers decide what a line means.
std::vector<JournalLine> readJournalLines(const std::filesystem::path& file);

}  // namespace shadowlab::scene

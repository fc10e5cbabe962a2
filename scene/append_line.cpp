// scene/append_line.cpp: the journal append, one write() and an fsync per line.
#include "scene/append_line.h"

#include <fcntl.h>
#include <unistd.h>

#include "scene/error.h"
#include "scene/input_file.h"

namespace shadowlab::scene {

void appendLine(const std::filesystem::path& file, const std::string& line) {
    const int fd = ::open(file.c_str(), O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) throw InputError(file.string() + ": cannot open for appending");
    const std::string text = line + "\n";
    const ssize_t written = ::write(fd, text.data(), text.size());
    const bool ok = written == ssize_t(text.size()) && ::fsync(fd) == 0;
    ::close(fd);
    if (!ok) throw InputError(file.string() + ": write failed (disk full?)");
}

std::vector<JournalLine> readJournalLines(const std::filesystem::path& file) {
    std::vector<JournalLine> lines;
    std::error_code ec;
    if (!std::filesystem::exists(file, ec)) return lines;
    const std::string text = readInputFile(file, kMaxJournalFileBytes);
    std::size_t begin = 0;
    for (int number = 1; begin < text.size(); ++number) {
        const std::size_t end = text.find('\n', begin);
        const bool torn = end == std::string::npos;
        std::string line = text.substr(begin, torn ? std::string::npos : end - begin);
        begin = torn ? text.size() : end + 1;
        if (!line.empty()) lines.push_back({std::move(line), number, torn});
    }
    return lines;
}

}  // namespace shadowlab::scene

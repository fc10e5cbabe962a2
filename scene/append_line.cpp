// scene/append_line.cpp: the journal append, one write() and an fsync per line.
#include "scene/append_line.h"

#include <fcntl.h>
#include <unistd.h>

#include "scene/error.h"

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

}  // namespace shadowlab::scene

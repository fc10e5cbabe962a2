// scene/input_file.cpp: regular files only, of a known and bounded size (see input_file.h).
#include "scene/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <cctype>
#include <cerrno>
#include <cstring>

#include "scene/memory.h"

namespace shadowlab::scene {

namespace {

namespace fs = std::filesystem;

std::string mib(std::uint64_t bytes) {
    return bytes >= kMiB ? std::to_string(bytes / kMiB) + " MiB" : std::to_string(bytes) + " bytes";
}

// What a non-regular file is, for the message.
std::string notRegular(mode_t mode) {
    if (S_ISDIR(mode)) return "is a folder, not a file";
    if (S_ISFIFO(mode)) return "is a named pipe (FIFO), not a regular file (reading it could wait forever)";
    if (S_ISCHR(mode)) return "is a character device (such as /dev/zero), not a regular file";
    if (S_ISBLK(mode)) return "is a block device, not a regular file";
    if (S_ISSOCK(mode)) return "is a socket, not a regular file";
    return "is not a regular file";
}

std::string errnoProblem(int error) {
    if (error == ENOENT || error == ENOTDIR) return "no such file";
    if (error == EACCES) return "cannot read: permission denied";
    if (error == ELOOP) return "cannot read: too many levels of symbolic links";
    return std::string("cannot read: ") + std::strerror(error);
}

// The checks every input gets, on a stat() result.
void checkStat(const fs::path& file, const struct stat& st, std::uint64_t maxBytes) {
    if (!S_ISREG(st.st_mode)) throw InputFileError(file, notRegular(st.st_mode));
    const auto size = std::uint64_t(st.st_size);
    if (size > maxBytes)
        throw InputFileError(file,
                             "is " + mib(size) + ", more than the " + mib(maxBytes) + " an input of this kind may be");
    // Reading it must fit beside what the program already holds (0: unknown, not checked).
    if (const std::uint64_t available = availableMemoryBytes(); available != 0 && size > available)
        throw InputFileError(
            file, "is " + mib(size) + ", more than the " + mib(available) + " of memory available to read it");
}

class Descriptor {
public:
    explicit Descriptor(int fd) : fd_(fd) {}
    ~Descriptor() {
        if (fd_ >= 0) ::close(fd_);
    }
    Descriptor(const Descriptor&) = delete;
    Descriptor& operator=(const Descriptor&) = delete;
    int get() const { return fd_; }

private:
    int fd_;
};

}  // namespace

std::string lowercaseExtension(const fs::path& file) {
    std::string ext = file.extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

std::uint64_t checkInputFile(const fs::path& file, std::uint64_t maxBytes) {
    struct stat st {};
    if (::stat(file.c_str(), &st) != 0) throw InputFileError(file, errnoProblem(errno));
    checkStat(file, st, maxBytes);
    return std::uint64_t(st.st_size);
}

std::string readInputFile(const fs::path& file, std::uint64_t maxBytes) {
    struct stat before {};
    if (::stat(file.c_str(), &before) != 0) throw InputFileError(file, errnoProblem(errno));
    checkStat(file, before, maxBytes);
    // O_NONBLOCK: should the path have become a FIFO since stat(), open() returns at once
    // instead of waiting for a writer; the fstat() below then refuses it.
    const Descriptor fd(::open(file.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK));
    if (fd.get() < 0) throw InputFileError(file, errnoProblem(errno));
    struct stat st {};
    if (::fstat(fd.get(), &st) != 0) throw InputFileError(file, errnoProblem(errno));
    checkStat(file, st, maxBytes);
    if (st.st_dev != before.st_dev || st.st_ino != before.st_ino)
        throw InputFileError(file, "changed while it was being opened");
    std::string bytes(std::size_t(st.st_size), '\0');
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::read(fd.get(), bytes.data() + done, bytes.size() - done);
        if (n < 0) {
            if (errno == EINTR) continue;
            throw InputFileError(file, errnoProblem(errno));
        }
        if (n == 0) break;  // shrank while read: what is there is what we have
        done += std::size_t(n);
    }
    bytes.resize(done);
    return bytes;
}

bool inputFileExists(const fs::path& file) {
    struct stat st {};
    return ::stat(file.c_str(), &st) == 0;
}

}  // namespace shadowlab::scene

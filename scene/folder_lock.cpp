// scene/folder_lock.cpp: the output folder's lock and its set replacement (see folder_lock.h).
#include "scene/folder_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <system_error>

#include "scene/error.h"
#include "scene/interrupt.h"

namespace shadowlab::scene {

namespace fs = std::filesystem;

FolderLock::FolderLock(const fs::path& dir, const std::string& what) : file_(dir / kLockFileName) {
    for (int attempt = 0; attempt < 100; ++attempt) {
        const int fd = ::open(file_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
        if (fd < 0) throw InputError(dir.string() + ": cannot lock the folder (" + std::strerror(errno) + ")");
        if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
            const int error = errno;
            char holder[256] = {};
            const ssize_t n = ::pread(fd, holder, sizeof holder - 1, 0);
            ::close(fd);
            if (error != EWOULDBLOCK)
                throw InputError(dir.string() + ": cannot lock the folder (" + std::strerror(error) + ")");
            std::string who = n > 0 ? std::string(holder, std::size_t(n)) : std::string("unknown");
            while (!who.empty() && (who.back() == '\n' || who.back() == ' ')) who.pop_back();
            throw InputError(dir.string() + ": another shadowlab is writing this folder (PID " + excerpt(who, 120) +
                             "); wait for it to finish or choose another folder");
        }
        // The holder before us may have removed the file between our open and our lock: then
        // we locked a file nobody else will see, and try again.
        struct stat held {
        }, named{};
        if (::fstat(fd, &held) == 0 && ::lstat(file_.c_str(), &named) == 0 && held.st_ino == named.st_ino &&
            held.st_dev == named.st_dev) {
            const std::string text = std::to_string(::getpid()) + " " + what + "\n";
            if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, text.data(), text.size(), 0) != ssize_t(text.size())) {
                // The PID is only for the message: a lock without it is still a lock.
            }
            fd_ = fd;
            noteLockOnInterrupt(fd_, file_);
            return;
        }
        ::close(fd);
    }
    throw InputError(dir.string() + ": cannot lock the folder (its lock file keeps changing)");
}

FolderLock::~FolderLock() {
    if (fd_ < 0) return;
    forgetLockOnInterrupt(fd_);
    struct stat held {
    }, named{};
    if (::fstat(fd_, &held) == 0 && ::lstat(file_.c_str(), &named) == 0 && held.st_ino == named.st_ino)
        ::unlink(file_.c_str());
    ::close(fd_);
}

namespace {

// A copy of `from` at `to` made of hard links: folders are recreated, files and symlinks linked.
void linkTree(const fs::path& from, const fs::path& to) {
    const fs::file_status st = fs::symlink_status(from);
    if (fs::is_directory(st)) {
        fs::create_directory(to);
        for (const auto& e : fs::directory_iterator(from)) linkTree(e.path(), to / e.path().filename());
    } else {
        fs::create_hard_link(from, to);
    }
}

bool sameFile(const fs::path& a, const fs::path& b) {
    std::error_code ec;
    return fs::equivalent(a, b, ec);
}

bool isMountPoint(const fs::path& dir) {
    struct stat self {
    }, parent{};
    return ::stat(dir.c_str(), &self) == 0 && ::stat((dir / "..").c_str(), &parent) == 0 &&
           self.st_dev != parent.st_dev;
}

}  // namespace

void replaceFolderContents(const fs::path& fresh, const fs::path& target,
                           const std::function<bool(const std::string&)>& carry) {
    if (!fs::exists(target)) {
        fs::rename(fresh, target);
        return;
    }
    std::vector<std::string> carried;
    for (const auto& e : fs::directory_iterator(target)) {
        const std::string name = e.path().filename().string();
        if (carry(name) && !fs::exists(fs::symlink_status(fresh / name))) carried.push_back(name);
    }
    const bool exchange = !sameFile(target, fs::current_path()) && !isMountPoint(target);
    if (exchange) {
        for (const std::string& name : carried) linkTree(target / name, fresh / name);
        if (::renameat2(AT_FDCWD, fresh.c_str(), AT_FDCWD, target.c_str(), RENAME_EXCHANGE) == 0) {
            fs::remove_all(fresh);  // now the old folder; what was carried lives on in its links
            return;
        }
        if (errno != EINVAL && errno != EXDEV && errno != EBUSY && errno != ENOSYS)
            throw std::system_error(errno, std::generic_category(),
                                    "cannot put " + fresh.string() + " in place of " + target.string());
        for (const std::string& name : carried) fs::remove_all(fresh / name);
    }
    // One by one: the old entries that are not carried go, then the new ones are renamed in.
    for (const auto& e : fs::directory_iterator(target)) {
        const std::string name = e.path().filename().string();
        if (!carry(name) && !fs::exists(fs::symlink_status(fresh / name))) fs::remove_all(e.path());
    }
    for (const auto& e : fs::directory_iterator(fresh)) {
        const fs::path dest = target / e.path().filename();
        if (fs::is_directory(fs::symlink_status(e.path())) && fs::exists(dest)) fs::remove_all(dest);
        fs::rename(e.path(), dest);
    }
    fs::remove(fresh);
}

}  // namespace shadowlab::scene

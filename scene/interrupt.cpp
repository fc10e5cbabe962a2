// scene/interrupt.cpp: see interrupt.h. A signal handler may only call async-signal-safe
// functions, and walking folders is not one: the handler starts find(1) over the noted folders,
// whose paths were copied into fixed buffers beforehand, and waits for it.
#include "scene/interrupt.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <random>
#include <string>

namespace shadowlab::scene {
namespace {

constexpr std::size_t kFolders = 48;
constexpr std::size_t kPathBytes = 4096;

std::array<std::array<char, kPathBytes>, kFolders> folders{};
std::atomic<std::size_t> folderCount{0};  // slots below it are complete (release/acquire)
std::mutex noting;
char pattern[64] = {};  // ".*.tmp-PID-TOKEN-*"

struct LockSlot {
    std::atomic<int> fd{-1};  // set after path (release), -1 when free
    std::array<char, kPathBytes> path{};
};
std::array<LockSlot, 8> locks;

void removeLocks() {
    for (LockSlot& slot : locks) {
        const int fd = slot.fd.load(std::memory_order_acquire);
        struct stat held {
        }, named{};
        if (fd >= 0 && ::fstat(fd, &held) == 0 && ::lstat(slot.path.data(), &named) == 0 &&
            held.st_ino == named.st_ino && held.st_dev == named.st_dev)
            ::unlink(slot.path.data());
    }
}

std::array<std::array<char, kPathBytes>, 4> created{};
std::atomic<std::size_t> createdCount{0};

// Copies `path`, made absolute (so that no folder name is taken for one of find's options), into
// the next free slot for the handler to read; a path already there, too long or past the last
// slot is left out (removeStaleTemporaries on the next run is the fallback).
template <std::size_t N>
void notePath(std::array<std::array<char, kPathBytes>, N>& slots, std::atomic<std::size_t>& count,
              const std::filesystem::path& path) {
    std::error_code ec;
    const std::string text = std::filesystem::absolute(path, ec).string();
    if (ec || text.size() >= kPathBytes) return;
    const std::lock_guard<std::mutex> guard(noting);
    const std::size_t n = count.load(std::memory_order_relaxed);
    for (std::size_t i = 0; i < n; ++i)
        if (text == slots[i].data()) return;
    if (n == N) return;
    std::memcpy(slots[n].data(), text.c_str(), text.size() + 1);
    count.store(n + 1, std::memory_order_release);
}

void say(const char* text) { [[maybe_unused]] const ssize_t n = ::write(2, text, std::strlen(text)); }

extern "C" void onInterrupt(int sig) {
    // Any second signal ends the process at once, even during the removal.
    struct sigaction plain {};
    plain.sa_handler = SIG_DFL;
    for (const int other : {SIGINT, SIGTERM, SIGHUP}) ::sigaction(other, &plain, nullptr);
    const std::size_t count = folderCount.load(std::memory_order_acquire);
    if (count > 0) {
        say("\nshadowlab: interrupted; removing this run's unfinished output (what was in place stays)\n");
        // find F1 F2 ... -mindepth 1 -maxdepth 1 -name PATTERN -exec rm -rf -- {} +
        std::array<const char*, kFolders + 16> argv{};
        std::size_t a = 0;
        argv[a++] = "find";
        for (std::size_t i = 0; i < count; ++i) argv[a++] = folders[i].data();
        for (const char* s : {"-mindepth", "1", "-maxdepth", "1", "-name", static_cast<const char*>(pattern), "-exec",
                              "rm", "-rf", "--", "{}", "+"})
            argv[a++] = s;
        argv[a] = nullptr;
        const pid_t child = ::_Fork();
        if (child == 0) {
            const int null = ::open("/dev/null", O_WRONLY);  // a folder removed with its parent is no error
            if (null >= 0) ::dup2(null, 2);
            ::execv("/usr/bin/find", const_cast<char* const*>(argv.data()));
            ::_exit(127);
        }
        if (child > 0) {
            int status = 0;
            while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
            }
        }
    }
    removeLocks();
    for (std::size_t i = 0; i < createdCount.load(std::memory_order_acquire); ++i) ::rmdir(created[i].data());
    // The default action is back: the process ends by the signal it got.
    ::raise(sig);
}

}  // namespace

std::string temporaryTag() {
    static const unsigned token = std::random_device{}();
    char tag[48];
    std::snprintf(tag, sizeof tag, "%ld-%08x-", static_cast<long>(::getpid()), token);
    return tag;
}

void removeTemporariesOnInterrupt() {
    std::snprintf(pattern, sizeof pattern, ".*.tmp-%s*", temporaryTag().c_str());
    struct sigaction action {};
    action.sa_handler = onInterrupt;
    action.sa_flags = SA_NODEFER;  // the handler puts the default actions back first
    sigemptyset(&action.sa_mask);
    for (const int sig : {SIGINT, SIGTERM, SIGHUP}) ::sigaction(sig, &action, nullptr);
}

void noteTemporaryFolder(const std::filesystem::path& folder) {
    notePath(folders, folderCount, folder.empty() ? std::filesystem::path(".") : folder);
}

void noteCreatedFolderOnInterrupt(const std::filesystem::path& folder) { notePath(created, createdCount, folder); }

void noteLockOnInterrupt(int fd, const std::filesystem::path& file) {
    const std::string path = file.string();
    if (fd < 0 || path.size() >= kPathBytes) return;
    const std::lock_guard<std::mutex> guard(noting);
    for (LockSlot& slot : locks)
        if (slot.fd.load(std::memory_order_relaxed) < 0) {
            std::memcpy(slot.path.data(), path.c_str(), path.size() + 1);
            slot.fd.store(fd, std::memory_order_release);
            return;
        }
}

void forgetLockOnInterrupt(int fd) {
    const std::lock_guard<std::mutex> guard(noting);
    for (LockSlot& slot : locks)
        if (slot.fd.load(std::memory_order_relaxed) == fd) slot.fd.store(-1, std::memory_order_release);
}

}  // namespace shadowlab::scene

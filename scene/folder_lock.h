// scene/folder_lock.h: one writer per output folder, and a folder's files replaced as a set.
#pragma once

#include <filesystem>
#include <functional>
#include <string>

namespace shadowlab::scene {

// Holds `dir/.shadowlab.lock` (flock, exclusive) while alive, with this process's PID and what
// it does written in it. A second writer gets InputError naming the holder's PID. The kernel
// drops the lock of a process that dies however it dies, so the file a killed writer leaves is
// taken over. The file is removed when the lock is released.
class FolderLock {
public:
    FolderLock(const std::filesystem::path& dir, const std::string& what);
    ~FolderLock();
    FolderLock(const FolderLock&) = delete;
    FolderLock& operator=(const FolderLock&) = delete;

    const std::filesystem::path& file() const { return file_; }

private:
    std::filesystem::path file_;
    int fd_ = -1;
};

// The lock file's name inside a locked folder.
inline constexpr const char* kLockFileName = ".shadowlab.lock";

// Puts the folder `fresh` in place of the folder `target` in one step (renameat2 with
// RENAME_EXCHANGE), so a reader sees every file of the old set or every file of the new one.
// Entries of the old folder for which `carry(name)` is true (a user's own files; the lock) are
// hard-linked into `fresh` first (folders recreated, their files linked), so they survive the
// swap whatever kills the process; the old folder is then removed. Where the exchange is not
// possible (`target` is the current folder or a mount point, or the file system cannot) the
// files are renamed into `target` one by one instead, and the set is not atomic.
void replaceFolderContents(const std::filesystem::path& fresh, const std::filesystem::path& target,
                           const std::function<bool(const std::string&)>& carry);

}  // namespace shadowlab::scene

// scene/interrupt.h: an interrupted program (Ctrl-C, SIGTERM, a closed terminal) removes the
// temporaries it was writing instead of leaving them for the next run to find.
#pragma once

#include <filesystem>
#include <string>

namespace shadowlab::scene {

// Installs handlers for SIGINT, SIGTERM and SIGHUP that remove this process's temporaries
// (temporarySibling's ".name.tmp-PID-TOKEN-N" files and folders) from every folder noted with
// noteTemporaryFolder and the lock files noted with noteLockOnInterrupt, then end the process by the same signal (so a shell sees 130 for Ctrl-C).
// A second signal during the removal ends it at once. Outputs already renamed into place stay.
void removeTemporariesOnInterrupt();

// Records that temporaries of this process may appear in `folder` (temporarySibling calls it).
// Thread-safe; at most a few dozen folders are kept, later ones are left to
// removeStaleTemporaries on the next run.
void noteTemporaryFolder(const std::filesystem::path& folder);

// What every temporary name of this process holds after ".tmp-": "PID-TOKEN-", TOKEN eight hex
// digits drawn once per process. The PID lets a later run tell a dead writer's leftovers; the
// token keeps an interrupted process from taking another host's live temporaries for its own
// in a shared folder, where PIDs repeat (containers on a farm all start near PID 1).
std::string temporaryTag();

// A FolderLock's file, removed on an interrupt as its destructor removes it (only while `file`
// is still the file `fd` holds): at most eight at a time.
void noteLockOnInterrupt(int fd, const std::filesystem::path& file);
void forgetLockOnInterrupt(int fd);

// An output folder this process created: removed on an interrupt if it is then empty (rmdir), so a
// first run stopped early leaves no empty folder behind. At most four.
void noteCreatedFolderOnInterrupt(const std::filesystem::path& folder);

}  // namespace shadowlab::scene

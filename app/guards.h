// app/guards.h: the checks every command makes at its edges: inputs read under one catch that
// turns any standard exception into bad input naming the file, outputs checked before any work.
#pragma once

#include <filesystem>
#include <new>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "scene/error.h"

namespace shadowlab::app {

// Runs `read` (loading the input `name`). The project's own errors pass through; any other
// standard exception thrown while reading (bad_alloc, length_error, filesystem_error...) is an
// input the readers did not foresee, so it becomes InputError("NAME: cannot read: ...") and
// exit 2, rather than a bare message and exit 1.
template <typename Read>
auto readingInput(const std::string& name, Read&& read) -> decltype(read()) {
    try {
        return read();
    } catch (const scene::SceneError&) {
        throw;
    } catch (const scene::InputError&) {
        throw;
    } catch (const std::bad_alloc&) {
        throw scene::InputError(name + ": cannot read: it needs more memory than there is (std::bad_alloc)");
    } catch (const std::filesystem::filesystem_error& e) {
        throw scene::InputError(name + ": cannot read: " + e.code().message() +
                                (e.path1().empty() ? "" : " (" + e.path1().string() + ")"));
    } catch (const std::exception& e) {
        throw scene::InputError(name + ": cannot read: " + e.what());
    }
}

// An output file (`-o FILE`): not an existing folder, and its nearest existing parent a folder
// this process may write in. Throws InputError naming `option` and the path.
void checkOutputFile(const std::filesystem::path& file, const std::string& option = "-o");

// An output folder (`-o DIR`): a folder or nothing yet, and its nearest existing parent a
// writable folder.
void checkOutputFolder(const std::filesystem::path& dir, const std::string& option = "-o");

// `render -o` into a missing folder: created once the input is known to be good, and the user is
// told on stderr (docs/decisions.md, "Output paths"); checkOutputFile has refused what cannot be
// used. The folders it made are removed again, if still empty, when it goes out of scope: a
// command that fails late (out of device memory, a full disk) leaves nothing behind.
class CreatedFolders {
public:
    explicit CreatedFolders(const std::filesystem::path& output);
    CreatedFolders(const CreatedFolders&) = delete;
    CreatedFolders& operator=(const CreatedFolders&) = delete;
    ~CreatedFolders();

private:
    std::vector<std::filesystem::path> made_;  // deepest first
};

// A folder a command replaces as a whole (`check -o DIR`): checkOutputFolder's rules, and it must
// not be the working folder or hold it, nor hold any of `inputs`, and an existing folder with
// entries must hold the file `marker` with `signature` in it (what an earlier run of the command
// wrote: another tool's junit.xml, or a sweep's shard.json, is not that), so that no folder of
// the user's own is replaced. Throws InputError naming `option`, the folder and the reason.
void checkReplacedFolder(const std::filesystem::path& dir, const std::vector<std::filesystem::path>& inputs,
                         const std::string& marker, const std::string& signature, const std::string& option = "-o");

// Flushes standard output and returns `status`, or prints why the write failed (a full disk,
// a closed pipe) and returns 1: results that did not reach their reader are a failure.
int finishStandardOutput(int status);

}  // namespace shadowlab::app

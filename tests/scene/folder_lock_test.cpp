// tests/scene/folder_lock_test.cpp: one writer per output folder (a second one is refused naming
// the first's PID, a killed writer's lock is taken over) and a folder's files replaced as a set.
#include "scene/folder_lock.h"

#include <sys/wait.h>
#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "scene/error.h"
#include "tests/scene/test_files.h"

namespace shadowlab {
namespace {

namespace fs = std::filesystem;

std::string read(const fs::path& p) {
    std::ifstream in(p);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(FolderLock, ASecondWriterIsRefusedNamingTheHolder) {
    test::TempDir dir;
    const scene::FolderLock first(dir.path(), "sweep");
    try {
        const scene::FolderLock second(dir.path(), "run");
        FAIL() << "two writers held one folder";
    } catch (const scene::InputError& e) {
        EXPECT_NE(std::string(e.what()).find("another shadowlab is writing this folder (PID " +
                                             std::to_string(::getpid()) + " sweep)"),
                  std::string::npos)
            << e.what();
    }
}

TEST(FolderLock, AKilledWritersLockIsTakenOverAndAReleasedOneRemoved) {
    test::TempDir dir;
    // A child takes the lock and is killed holding it: the kernel drops the lock, the file stays.
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        const scene::FolderLock lock(dir.path(), "killed");
        ::kill(::getpid(), SIGKILL);
    }
    int status = 0;
    ::waitpid(child, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status));
    const fs::path file = dir.path() / scene::kLockFileName;
    ASSERT_TRUE(fs::exists(file));
    EXPECT_NE(read(file).find(std::to_string(child)), std::string::npos);
    {
        const scene::FolderLock lock(dir.path(), "next");
        EXPECT_EQ(read(file), std::to_string(::getpid()) + " next\n");
    }
    EXPECT_FALSE(fs::exists(file));
}

TEST(ReplaceFolder, TheNewSetReplacesTheOldAndCarriedFilesStay) {
    test::TempDir dir;
    const fs::path target = dir.path() / "out", fresh = dir.path() / ".out.tmp-1";
    fs::create_directories(target / "sweep");
    dir.write("out/report.html", "old report");
    dir.write("out/raster.exr", "old raster, not made by the new run");
    dir.write("out/sweep/old.csv", "old");
    dir.write("out/notes.txt", "the user's");
    dir.write("out/mine/deep.txt", "the user's too");
    fs::create_directories(fresh / "sweep");
    dir.write(".out.tmp-1/report.html", "new report");
    dir.write(".out.tmp-1/sweep/new.csv", "new");
    const scene::FolderLock lock(target, "run");
    auto isOutput = [](const std::string& n) { return n == "report.html" || n == "raster.exr" || n == "sweep"; };
    scene::replaceFolderContents(fresh, target, [&](const std::string& n) { return !isOutput(n); });
    EXPECT_FALSE(fs::exists(fresh));
    EXPECT_EQ(read(target / "report.html"), "new report");
    EXPECT_FALSE(fs::exists(target / "raster.exr"));
    EXPECT_FALSE(fs::exists(target / "sweep" / "old.csv"));
    EXPECT_EQ(read(target / "sweep" / "new.csv"), "new");
    EXPECT_EQ(read(target / "notes.txt"), "the user's");
    EXPECT_EQ(read(target / "mine" / "deep.txt"), "the user's too");
    // The lock moved with the folder: it is still this process's, still held.
    EXPECT_TRUE(fs::exists(target / scene::kLockFileName));
    EXPECT_THROW(scene::FolderLock(target, "second"), scene::InputError);
}

}  // namespace
}  // namespace shadowlab

// tests/app/outputs_test.cpp: where outputs go: `run -o` naming a file, `render -o` into a missing
// folder, a model format shadowlab does not read, a run folder left from an earlier run, and the
// folders `check` replaces as a whole.
#include <fcntl.h>
#include <spawn.h>
#include <unistd.h>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/guards.h"
#include "tests/app/cli.h"
#include "tests/app/subprocess.h"

namespace shadowlab {
namespace {

namespace fs = std::filesystem;
using test::runShadowlab;
using test::TempDir;

TEST(Outputs, RunIntoAFileExitsTwoWithAClearMessageAndLeavesTheFile) {
    TempDir dir;
    const auto file = dir.write("report.txt", "mine");
    const auto r = runShadowlab({"run", "seed", "-o", file.string(), "--no-raster", "--no-sweep"});
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find("is a file, not a folder"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("filesystem error"), std::string::npos) << r.err;
    EXPECT_EQ(test::slurpFile(file), "mine");
    EXPECT_EQ(dir.fileCount(), 1u);
}

// Runs shadowlab with its standard output (and its standard error, unless `errFile` is given) on
// a pipe whose reading end is closed before the program starts: every write to it fails, as
// when a reader (`| head`) has quit. The exit status, or -1 for a signal.
int runIntoClosedPipe(const std::vector<std::string>& args, const fs::path* errFile) {
    int fds[2];
    if (::pipe(fds) != 0) return -2;
    ::close(fds[0]);
    const pid_t pid = test::spawnShadowlab(args, [&](posix_spawn_file_actions_t& actions) {
        posix_spawn_file_actions_adddup2(&actions, fds[1], 1);
        if (errFile)
            posix_spawn_file_actions_addopen(&actions, 2, errFile->c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        else
            posix_spawn_file_actions_adddup2(&actions, fds[1], 2);
    });
    ::close(fds[1]);
    return pid > 0 ? test::waitFor(pid) : -2;
}

TEST(Outputs, AReaderThatQuitsEarlyDoesNotStopTheRenderWritingItsFile) {
    // The render must still finish and write its file: exit 0 where only the progress lines were
    // lost, 1 where the --json answer the caller asked for was (stderr says so).
    TempDir dir;
    const auto a = dir.path() / "a.png", b = dir.path() / "b.png", err = dir.path() / "err.txt";
    EXPECT_EQ(runIntoClosedPipe({"render", "seed", "--resolution", "32x18", "-o", a.string()}, nullptr), 0);
    EXPECT_TRUE(fs::is_regular_file(a));
    EXPECT_EQ(runIntoClosedPipe({"render", "seed", "--resolution", "32x18", "--json", "-o", b.string()}, &err), 1);
    EXPECT_TRUE(fs::is_regular_file(b));
    EXPECT_NE(test::slurpFile(err).find("writing to standard output failed: Broken pipe"), std::string::npos)
        << test::slurpFile(err);
    EXPECT_EQ(dir.fileCount(), 3u);  // no temporary left beside them
}

TEST(Outputs, RenderIntoAMissingFolderCreatesItAndSaysSo) {
    TempDir dir;
    const auto out = dir.path() / "new" / "deeper" / "x.png";
    const auto r = runShadowlab({"render", "seed", "--resolution", "32x18", "-o", out.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_TRUE(fs::is_regular_file(out));
    EXPECT_NE(r.err.find("created the folder " + out.parent_path().string()), std::string::npos) << r.err;
}

TEST(Outputs, RenderUnderAFileOrOntoAFolderIsBadInput) {
    TempDir dir;
    const auto file = dir.write("plain", "x");
    const auto under = runShadowlab({"render", "seed", "--resolution", "32x18", "-o", (file / "x.png").string()});
    EXPECT_EQ(under.exitCode, 2);
    EXPECT_NE(under.err.find("is a file, not a folder"), std::string::npos) << under.err;
    fs::create_directories(dir.path() / "folder.png");
    const auto onto =
        runShadowlab({"render", "seed", "--resolution", "32x18", "-o", (dir.path() / "folder.png").string()});
    EXPECT_EQ(onto.exitCode, 2);
    EXPECT_NE(onto.err.find("is a folder"), std::string::npos) << onto.err;
}

TEST(Outputs, AnStlModelIsAnUnsupportedFormatNotAJsonError) {
    TempDir dir;
    const auto stl = dir.write("bunny.stl", "solid bunny\nendsolid bunny\n");
    const auto r = runShadowlab({"render", stl.string(), "-o", (dir.path() / "x.png").string()});
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find("unsupported format '.stl'"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("JSON"), std::string::npos) << r.err;
    // Named as a mesh in a JSON scene, the same words, with the scene's JSON path.
    const auto scene = dir.write("s.json", R"({"camera": {"position": [0, 1, 5], "look_at": [0, 0, 0]},
        "materials": {"m": {}}, "lights": [{"type": "directional", "direction": [0, -1, 0]}],
        "objects": [{"type": "mesh", "file": "bunny.stl", "material": "m"}]})");
    const auto m = runShadowlab({"render", scene.string(), "-o", (dir.path() / "x.png").string()});
    EXPECT_EQ(m.exitCode, 2);
    EXPECT_NE(m.err.find("unsupported format '.stl'"), std::string::npos) << m.err;
    EXPECT_NE(m.err.find("objects[0].file"), std::string::npos) << m.err;
    EXPECT_FALSE(fs::exists(dir.path() / "x.png"));
}

TEST(Outputs, APlyPointCloudIsRefusedAsAModelWithNoFaces) {
    TempDir dir;
    const auto ply = dir.write("cloud.ply",
                               "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                               "property float y\nproperty float z\nend_header\n0 0 0\n");
    const auto r = runShadowlab({"render", ply.string(), "-o", (dir.path() / "x.png").string()});
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find(ply.string()), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("has no faces"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir.path() / "x.png"));
}

TEST(Outputs, ARunRemovesWhatTheEarlierRunWroteAndThisOneDoesNotButNothingElse) {
    TempDir dir;
    const auto out = dir.path() / "run";
    // An earlier run's folder: its manifest lists raster outputs and a sweep this run will not
    // write; notes.txt is the user's; raster-cascades.png is not in the manifest but is a name run
    // writes (a folder from before manifests), so it is the earlier run's too.
    dir.write("run/raster.exr", "old");
    dir.write("run/diff-raster.png", "old");
    dir.write("run/sweep/results.csv", "old");
    dir.write("run/notes.txt", "mine");
    dir.write("run/raster-cascades.png", "not listed");
    dir.write("run/.shadowlab-run.json",
              R"({"files": ["raster.exr", "diff-raster.png", "sweep/", "reference.exr", "../outside.txt"]})");
    dir.write("outside.txt", "mine too");
    const auto r =
        runShadowlab({"run", "seed", "-o", out.string(), "--no-raster", "--no-sweep", "--resolution", "32x18"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_FALSE(fs::exists(out / "raster.exr"));
    EXPECT_FALSE(fs::exists(out / "diff-raster.png"));
    EXPECT_FALSE(fs::exists(out / "sweep"));
    EXPECT_TRUE(fs::is_regular_file(out / "reference.exr"));  // written again
    EXPECT_EQ(test::slurpFile(out / "notes.txt"), "mine");
    EXPECT_FALSE(fs::exists(out / "raster-cascades.png"));
    EXPECT_EQ(test::slurpFile(dir.path() / "outside.txt"), "mine too");
    const auto manifest = nlohmann::json::parse(test::slurpFile(out / ".shadowlab-run.json"));
    std::vector<std::string> files = manifest.at("files");
    std::sort(files.begin(), files.end());
    EXPECT_EQ(files, (std::vector<std::string>{"diff-raytrace.png", "heat-raytrace.png", "metrics.json", "raytrace.exr",
                                               "raytrace.png", "reference.exr", "reference.png", "report.html"}));
}

TEST(Outputs, FoldersMadeForAnOutputAreRemovedAgainWhenNothingWasWrittenIntoThem) {
    TempDir dir;
    const fs::path out = dir.path() / "a" / "b" / "x.png";
    {
        const app::CreatedFolders made(out);
        EXPECT_TRUE(fs::is_directory(out.parent_path()));
    }  // the command failed before writing x.png
    EXPECT_FALSE(fs::exists(dir.path() / "a"));
    {
        const app::CreatedFolders made(out);
        std::ofstream(out) << "png";
    }
    EXPECT_TRUE(fs::exists(out));
    // A folder that existed is never removed, even empty.
    fs::remove(out);
    { const app::CreatedFolders made(out); }
    EXPECT_TRUE(fs::is_directory(out.parent_path()));
}

TEST(Outputs, CheckReplacesOnlyAFolderOfItsOwnAndRefusesBeforeRunning) {
    TempDir dir;
    const fs::path suite = dir.write("suites/suite.json", R"({"resolution": "48x27", "cases": [
        {"name": "a", "scene": "seed", "backend": "raytrace", "settings": {"ray_bias": "robust"}}]})");
    const fs::path mine = dir.write("mine.txt", "mine");
    const fs::path foreign = dir.write("notes/todo.txt", "keep");
    auto refused = [&](const fs::path& out, const std::string& why, const std::vector<std::string>& extra = {}) {
        std::vector<std::string> args = {"check", suite.string(), "-o", out.string()};
        args.insert(args.end(), extra.begin(), extra.end());
        const std::size_t before = dir.fileCount();
        const auto r = runShadowlab(args);
        EXPECT_EQ(r.exitCode, 2) << out << ": " << r.err;
        EXPECT_NE(r.err.find(why), std::string::npos) << r.err;
        EXPECT_EQ(r.err.find("[1/1]"), std::string::npos) << "ran a case first: " << r.err;
        EXPECT_EQ(dir.fileCount(), before) << out;
    };
    refused(mine, "is a file, not a folder");
    refused(suite.parent_path(), "holds the input " + suite.string());
    refused(dir.path(), "holds the input");
    refused(foreign.parent_path(), "holds files that no earlier run of this command wrote (no junit.xml of its own)");
    // Another tool's junit.xml does not make a folder check's own.
    const fs::path otherTool = dir.write("ci/junit.xml", "<testsuites name=\"pytest\"></testsuites>");
    refused(otherTool.parent_path(), "(no junit.xml of its own)");
    refused(dir.path() / "out", "--update-baseline " + (mine / "b.json").string(),
            {"--update-baseline", "--baseline", (mine / "b.json").string()});
    EXPECT_EQ(test::slurpFile(mine), "mine");
    EXPECT_EQ(test::slurpFile(foreign), "keep");
    // A folder of its own: written, then replaced by the next run.
    const fs::path out = dir.path() / "out";
    ASSERT_EQ(runShadowlab({"check", suite.string(), "-o", out.string()}).exitCode, 0);
    ASSERT_TRUE(fs::exists(out / "junit.xml"));
    const auto again = runShadowlab({"check", suite.string(), "-o", out.string()});
    EXPECT_EQ(again.exitCode, 0) << again.err;
    // The working folder, or one that holds it, is never replaced (checked without running check
    // there, so that a broken guard cannot empty the test's own folder).
    const std::string mark = "<testsuites name=\"shadowlab check\"";
    EXPECT_THROW(app::checkReplacedFolder(fs::current_path(), {}, "junit.xml", mark), scene::InputError);
    EXPECT_THROW(app::checkReplacedFolder(fs::current_path().parent_path(), {}, "junit.xml", mark), scene::InputError);
    EXPECT_NO_THROW(app::checkReplacedFolder(out, {suite}, "junit.xml", mark));
}

}  // namespace
}  // namespace shadowlab

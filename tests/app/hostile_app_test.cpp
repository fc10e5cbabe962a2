// tests/app/hostile_app_test.cpp: the program's edges under hostile use: outputs that cannot be
// written fail before any work with exit 2, results that cannot reach stdout are an error, a
// second writer of a folder is refused naming the first, a run replaces the previous run's
// files as a set and keeps the user's, and unforeseen standard exceptions on inputs are bad input.
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <csignal>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/guards.h"
#include "scene/folder_lock.h"
#include "tests/scene/test_files.h"

namespace shadowlab {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

struct Outcome {
    int exitCode = -1;
    std::string err;
};

// Runs shadowlab with `args`, stdout to `out` (a file or a device), stderr captured.
Outcome run(const std::string& args, const std::string& out = "/dev/null") {
    TempDir io;
    const fs::path err = io.path() / "err";
    const std::string cmd = std::string(SHADOWLAB_EXE) + " " + args + " >" + out + " 2>" + err.string();
    const int status = std::system(cmd.c_str());
    std::ifstream in(err);
    std::ostringstream s;
    s << in.rdbuf();
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, s.str()};
}

TEST(HostileApp, AnOutputThatIsAFolderFailsBeforeAnyRendering) {
    TempDir dir;
    fs::create_directory(dir.path() / "frame.exr");
    const Outcome r = run("render seed -o " + (dir.path() / "frame.exr").string());
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_NE(r.err.find("frame.exr: is a folder"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("rendering"), std::string::npos) << "it rendered first: " << r.err;
    std::ofstream(dir.path() / "file") << "x";
    const Outcome f = run("run seed --no-raster -o " + (dir.path() / "file").string());
    EXPECT_EQ(f.exitCode, 2) << f.err;
    EXPECT_NE(f.err.find("is a file, not a folder"), std::string::npos) << f.err;
}

TEST(HostileApp, JsonResultsThatCannotBeWrittenAreAnError) {
    TempDir dir;
    const std::string frame = (dir.path() / "a.exr").string();
    const Outcome r = run("render seed --resolution 32x18 --json -o " + frame, "/dev/full");
    EXPECT_EQ(r.exitCode, 1) << r.err;
    EXPECT_NE(r.err.find("writing to standard output failed: No space left on device"), std::string::npos) << r.err;
    EXPECT_EQ(run("render seed --resolution 32x18 --json -o " + frame).exitCode, 0);
}

TEST(HostileApp, AFifoGivenToCompareIsRefusedNotWaitedOn) {
    ::alarm(60);
    TempDir dir;
    ASSERT_EQ(::mkfifo((dir.path() / "pipe.exr").c_str(), 0600), 0);
    const Outcome r = run("compare " + (dir.path() / "pipe.exr").string() + " " + (dir.path() / "pipe.exr").string() +
                          " -o " + (dir.path() / "d.png").string());
    ::alarm(0);
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_NE(r.err.find("pipe.exr: is a named pipe"), std::string::npos) << r.err;
}

TEST(HostileApp, AFifoOrAFolderWhereCheckMergeOrAResumeReadsJsonIsRefusedNotWaitedOn) {
    ::alarm(120);
    TempDir dir;
    const fs::path pipe = dir.path() / "pipe.json";
    ASSERT_EQ(::mkfifo(pipe.c_str(), 0600), 0);
    std::ofstream(dir.path() / "suite.json")
        << R"({"baseline": "pipe.json", "cases": [{"name": "a", "scene": "seed", "backend": "raytrace"}]})";
    // A check shard folder whose shard.json is a FIFO, and a path folder whose path.json is one.
    fs::create_directories(dir.path() / "shards" / "shard-0-of-2");
    ASSERT_EQ(::mkfifo((dir.path() / "shards" / "shard-0-of-2" / "shard.json").c_str(), 0600), 0);
    fs::create_directories(dir.path() / "p");
    std::ofstream(dir.path() / "p" / "frames.jsonl") << "";
    ASSERT_EQ(::mkfifo((dir.path() / "p" / "path.json").c_str(), 0600), 0);
    const std::string out = " -o " + (dir.path() / "out").string();
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"check " + pipe.string() + out, "pipe.json: is a named pipe"},
        {"check " + (dir.path() / "suite.json").string() + out, "pipe.json: is a named pipe"},
        {"check " + (dir.path() / "suite.json").string() + " --baseline " + dir.path().string() + out,
         ": is a folder, not a file"},
        {"merge " + (dir.path() / "shards").string(), "shard.json: is a named pipe"},
        {"path seed --resolution 16x9 --frames 2 --resume -o " + (dir.path() / "p").string(),
         "path.json: is a named pipe"},
    };
    for (const auto& [command, says] : cases) {
        const Outcome r = run(command);
        EXPECT_EQ(r.exitCode, 2) << command << ": " << r.err;
        EXPECT_NE(r.err.find(says), std::string::npos) << command << ": " << r.err;
    }
    ::alarm(0);
    EXPECT_FALSE(fs::exists(dir.path() / "out"));
}

TEST(HostileApp, ASecondWriterOfAFolderIsRefusedNamingTheFirst) {
    TempDir dir;
    const scene::FolderLock held(dir.path(), "test");
    for (const char* command : {"sweep seed --quick --resolution 32x18", "run seed --no-raster --resolution 32x18"}) {
        const Outcome r = run(std::string(command) + " -o " + dir.path().string());
        EXPECT_EQ(r.exitCode, 2) << command << ": " << r.err;
        EXPECT_NE(r.err.find("another shadowlab is writing this folder (PID " + std::to_string(::getpid()) + " test)"),
                  std::string::npos)
            << r.err;
    }
    EXPECT_FALSE(fs::exists(dir.path() / "results.jsonl"));
    EXPECT_FALSE(fs::exists(dir.path() / "report.html"));
}

TEST(HostileApp, ARunReplacesThePreviousRunsFilesAsASetAndKeepsTheUsers) {
    TempDir dir;
    const fs::path out = dir.path() / "out";
    ASSERT_EQ(run("run seed --no-raster --no-sweep --resolution 32x18 -o " + out.string()).exitCode, 0);
    // What an earlier run with the raster backend left, and a file of the user's.
    std::ofstream(out / "raster.exr") << "stale";
    std::ofstream(out / "diff-raster.png") << "stale";
    std::ofstream(out / "notes.txt") << "mine";
    const Outcome r = run("run seed --no-raster --no-sweep --resolution 32x18 -o " + out.string());
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_FALSE(fs::exists(out / "raster.exr"));
    EXPECT_FALSE(fs::exists(out / "diff-raster.png"));
    EXPECT_TRUE(fs::exists(out / "reference.exr"));
    EXPECT_TRUE(fs::exists(out / "report.html"));
    std::ifstream notes(out / "notes.txt");
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(notes), {}), "mine");
    EXPECT_FALSE(fs::exists(out / scene::kLockFileName));
    for (const auto& e : fs::directory_iterator(dir.path()))  // no staging folder left beside it
        EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
}

TEST(HostileApp, TheMemoryEstimateCountsTheSceneItself) {
    // 200000 glTF nodes placing one triangle each: the file's parsed tree, the nodes and their
    // placements cost far more than their triangles, which were all the estimate counted.
    TempDir dir;
    std::string nodes, roots;
    for (int i = 0; i < 200000; ++i) {
        if (i) {
            nodes += ',';
            roots += ',';
        }
        nodes += R"({"mesh":0,"translation":[)" + std::to_string(i % 500) + ",0," + std::to_string(i / 500) + "]}";
        roots += std::to_string(i);
    }
    // One triangle (0,0,0), (1,0,0), (0,1,0) as 9 little-endian floats, base64.
    const std::string gltf = R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[)" + roots + R"(]}],"nodes":[)" + nodes +
                             R"(],"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
        "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}],
        "bufferViews":[{"buffer":0,"byteLength":36}],
        "buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}]})";
    const fs::path file = dir.path() / "nodes.gltf";
    std::ofstream(file) << gltf;
    const std::string frame = (dir.path() / "n.exr").string();
    TempDir io;
    const Outcome r =
        run("render " + file.string() + " --resolution 16x9 --json -o " + frame, (io.path() / "out.json").string());
    ASSERT_EQ(r.exitCode, 0) << r.err;
    std::ifstream out(io.path() / "out.json");
    const auto memory = nlohmann::json::parse(out).at("memory");
#ifndef __SANITIZE_ADDRESS__  // AddressSanitizer's shadow memory and quarantine are not in the estimate
    EXPECT_LE(memory.at("peak_mib").get<double>(), memory.at("estimate_mib").get<double>()) << memory.dump();
#endif
    // Under a limit below the estimate it is refused before rendering.
    const std::string limit = std::to_string(memory.at("estimate_mib").get<int>() - 10);
    ::setenv("SHADOWLAB_MEMORY_LIMIT_MB", limit.c_str(), 1);
    const Outcome small = run("render " + file.string() + " --resolution 16x9 -o " + frame + ".2.exr");
    ::unsetenv("SHADOWLAB_MEMORY_LIMIT_MB");
    EXPECT_EQ(small.exitCode, 2) << small.err;
    EXPECT_NE(small.err.find("needs about"), std::string::npos) << small.err;
    EXPECT_FALSE(fs::exists(frame + ".2.exr"));
}

TEST(HostileApp, StandardExceptionsWhileReadingAnInputBecomeBadInputNamingIt) {
    auto messageOf = [](auto&& f) {
        try {
            app::readingInput("scene.json", f);
        } catch (const scene::InputError& e) {
            return std::string(e.what());
        }
        return std::string("no InputError");
    };
    EXPECT_EQ(messageOf([]() -> int { throw std::length_error("vector::_M_default_append"); }),
              "scene.json: cannot read: vector::_M_default_append");
    EXPECT_NE(messageOf([]() -> int { throw std::bad_alloc(); }).find("scene.json: cannot read: it needs more memory"),
              std::string::npos);
    EXPECT_NE(messageOf([]() -> int {
                  throw fs::filesystem_error("x", "a/b", std::make_error_code(std::errc::permission_denied));
              }).find("scene.json: cannot read: Permission denied"),
              std::string::npos);
    // The project's own errors pass as they are.
    EXPECT_THROW(app::readingInput("x", []() -> int { throw scene::SceneError("f", {}, "bad"); }), scene::SceneError);
}

}  // namespace
}  // namespace shadowlab

namespace shadowlab {
namespace {

TEST(HostileApp, ABadAlphaTextureIsBadInputNamingTheFileAndKeyAndWritesNothing) {
    // The shipped foliage scene with its leaf texture renamed away, then with a text file as the image.
    TempDir dir;
    std::ifstream in(std::string(SHADOWLAB_SOURCE_DIR) + "/scenes/foliage.json");
    std::ostringstream text;
    text << in.rdbuf();
    const fs::path scene = dir.write("foliage.json", text.str());
    const fs::path frame = dir.path() / "frame.png";
    Outcome r = run("render " + scene.string() + " -o " + frame.string());
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_NE(r.err.find(scene.string() + ": materials.leaf.texture: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("leaf.png: no such file"), std::string::npos) << r.err;
    dir.write("foliage/leaf.png", "not an image");
    r = run("render " + scene.string() + " -o " + frame.string());
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_NE(r.err.find("not a readable image"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(frame));
}

}  // namespace
}  // namespace shadowlab

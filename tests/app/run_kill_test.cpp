// tests/app/run_kill_test.cpp: `shadowlab run` killed with SIGKILL at random moments leaves every
// output file either as the earlier run wrote it or as a complete new one, never torn or missing,
// and the next run cleans up what the killed ones left behind; Ctrl-C (SIGINT) leaves nothing to
// clean up.
#include <chrono>
#include <csignal>
#include <fstream>
#include <iterator>
#include <random>
#include <set>
#include <thread>
#include <vector>

#include <sys/wait.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "scene/error.h"
#include "scene/frame_io.h"
#include "tests/app/subprocess.h"
#include "tests/scene/test_files.h"

namespace shadowlab {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

std::string bytesOf(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

bool endsWith(const std::string& s, const std::string& tail) {
    return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// Output files (relative paths), temporaries left out.
std::set<std::string> outputs(const fs::path& dir) {
    std::set<std::string> files;
    for (const auto& e : fs::recursive_directory_iterator(dir))
        if (e.is_regular_file() && e.path().string().find(".tmp-") == std::string::npos)
            files.insert(fs::relative(e.path(), dir).string());
    return files;
}

// A complete file of its kind, judged by its own format's end marker or a full parse, with a
// frame width that one of the runs asked for.
::testing::AssertionResult complete(const fs::path& file, const std::set<int>& widths) {
    const std::string ext = file.extension().string();
    const std::string bytes = bytesOf(file);
    if (ext == ".exr") {
        try {
            const scene::Frame f = scene::readFrame(file);
            if (!widths.count(f.width)) return ::testing::AssertionFailure() << "unexpected width " << f.width;
        } catch (const scene::InputError& e) {
            return ::testing::AssertionFailure() << e.what();
        }
    } else if (ext == ".png") {  // a PNG ends with its IEND chunk and that chunk's CRC
        if (!endsWith(bytes, std::string("IEND\xAE\x42\x60\x82", 8))) return ::testing::AssertionFailure() << "no IEND";
    } else if (ext == ".html") {
        if (bytes.find("</html>") == std::string::npos) return ::testing::AssertionFailure() << "no </html>";
    } else if (ext == ".svg") {
        if (bytes.find("</svg>") == std::string::npos) return ::testing::AssertionFailure() << "no </svg>";
    } else if (ext == ".json") {
        if (!Json::accept(bytes)) return ::testing::AssertionFailure() << "not JSON";
    } else if (ext == ".jsonl") {
        std::istringstream lines(bytes);
        for (std::string line; std::getline(lines, line);)
            if (!Json::accept(line)) return ::testing::AssertionFailure() << "torn line: " << line;
    } else if (ext == ".csv") {
        if (!endsWith(bytes, "\n")) return ::testing::AssertionFailure() << "no final newline";
    }
    return ::testing::AssertionSuccess();
}

TEST(RunKill, KilledAtRandomMomentsEveryOutputIsTheOldOrACompleteNewFile) {
    test::TempDir dir;
    const fs::path out = dir.path() / "run";
    auto args = [&](int width) {
        return std::vector<std::string>{"run",
                                        "seed",
                                        "-o",
                                        out.string(),
                                        "--resolution",
                                        std::to_string(width) + "x" + std::to_string(width * 9 / 16),
                                        "--shadow-map-size",
                                        "256"};
    };
    // A complete run first: these are the "old" files, and its duration spaces the kills.
    const auto start = std::chrono::steady_clock::now();
    const pid_t first = test::spawnShadowlab(args(64));
    ASSERT_GT(first, 0);
    ASSERT_EQ(test::waitFor(first), 0);
    const double fullMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    const std::set<std::string> expected = outputs(out);
    ASSERT_TRUE(expected.count("report.html") && expected.count("raster.exr") && expected.count("sweep/results.jsonl"))
        << "the first run did not write what `run` writes";

    const unsigned seed = std::random_device{}();
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> when(0.0, 1.1 * fullMs);
    for (int kill = 0; kill < 6; ++kill) {
        const double afterMs = when(rng);
        SCOPED_TRACE("seed " + std::to_string(seed) + ", kill " + std::to_string(kill) + " after " +
                     std::to_string(afterMs) + " ms of " + std::to_string(fullMs));
        const pid_t pid = test::spawnShadowlab(args(kill % 2 ? 64 : 48));
        ASSERT_GT(pid, 0);
        std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(afterMs));
        ::kill(pid, SIGKILL);
        test::waitFor(pid);
        const std::set<std::string> now = outputs(out);
        for (const std::string& name : expected) {
            ASSERT_TRUE(now.count(name)) << name << " is gone";
            EXPECT_TRUE(complete(out / name, {24, 32, 48, 64})) << name;  // (the sweep's frames are half size)
        }
    }
    // The next complete run removes the temporaries the killed ones left.
    const pid_t last = test::spawnShadowlab(args(64));
    ASSERT_GT(last, 0);
    ASSERT_EQ(test::waitFor(last), 0);
    for (const auto& e : fs::recursive_directory_iterator(out))
        EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
    EXPECT_EQ(outputs(out), expected);
}

// The temporaries under `dir`, at any depth.
std::vector<fs::path> temporaries(const fs::path& dir) {
    std::vector<fs::path> found;
    for (const auto& e : fs::recursive_directory_iterator(dir))
        if (e.path().filename().string().find(".tmp-") != std::string::npos) found.push_back(e.path());
    return found;
}

TEST(RunKill, CtrlCInTheMiddleRemovesTheStagingFolderAndKeepsTheEarlierRun) {
    test::TempDir dir;
    const fs::path out = dir.path() / "run";
    auto args = [&](const std::string& resolution) {
        return std::vector<std::string>{"run", "seed", "-o", out.string(), "--resolution", resolution};
    };
    const pid_t first = test::spawnShadowlab(args("64x36"));
    ASSERT_GT(first, 0);
    ASSERT_EQ(test::waitFor(first), 0);
    const std::set<std::string> expected = outputs(out);
    const std::string report = bytesOf(out / "report.html");

    // A longer run into `folder`, interrupted once its staging folder holds files: its exit status.
    auto interrupted = [&](const fs::path& folder) {
        const pid_t pid = test::spawnShadowlab({"run", "seed", "-o", folder.string(), "--resolution", "640x360"});
        EXPECT_GT(pid, 0);
        std::string staging = ".";  // (appended piece by piece: GCC 12 warns falsely, -Wrestrict, on a chain of +)
        staging += folder.filename().string();
        staging += ".tmp-";
        staging += std::to_string(pid);
        staging += '-';
        bool staged = false;
        for (int wait = 0; wait < 600 && !staged; ++wait) {
            std::this_thread::sleep_for(std::chrono::milliseconds(50));
            for (const auto& e : fs::directory_iterator(dir.path()))
                if (e.path().filename().string().rfind(staging, 0) == 0 && !fs::is_empty(e.path())) staged = true;
        }
        ::kill(pid, SIGINT);
        int status = 0;
        ::waitpid(pid, &status, 0);
        EXPECT_TRUE(staged) << "the run never staged a file";
        return status;
    };
    const int status = interrupted(out);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGINT) << "status " << status;
    EXPECT_TRUE(temporaries(dir.path()).empty()) << temporaries(dir.path()).front();
    EXPECT_EQ(outputs(out), expected);
    EXPECT_EQ(bytesOf(out / "report.html"), report);
    // A first run into a folder it made leaves no empty folder behind.
    const fs::path fresh = dir.path() / "fresh";
    interrupted(fresh);
    EXPECT_FALSE(fs::exists(fresh));
    EXPECT_TRUE(temporaries(dir.path()).empty()) << temporaries(dir.path()).front();
}

}  // namespace
}  // namespace shadowlab

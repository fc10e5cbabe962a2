// tests/scene/fuzz_regression_test.cpp: replays every input the fuzzers ever crashed on
// (tests/scene/fuzz_regressions/TARGET/) and their seed corpus (fuzz/corpus/TARGET/) through the
// same readers. A finding is bad input and must be refused with the project's own error naming the
// file; a seed may load or be refused so; a crash, a sanitizer report or any other exception fails.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fuzz/targets.h"
#include "tests/scene/test_files.h"

namespace shadowlab {
namespace {

namespace fs = std::filesystem;

struct Replay {
    std::string target;
    fs::path input;
    bool finding = false;  // a kept crasher: bad input, so it must be refused
};

std::vector<Replay> replays() {
    std::vector<Replay> all;
    for (const char* target : {"scene_json", "obj", "ply", "gltf", "exr"})
        for (const bool finding : {true, false}) {
            const fs::path root =
                fs::path(SHADOWLAB_SOURCE_DIR) / (finding ? "tests/scene/fuzz_regressions" : "fuzz/corpus") / target;
            if (fs::is_directory(root))
                for (const auto& entry : fs::directory_iterator(root))
                    if (entry.is_regular_file()) all.push_back({target, entry.path(), finding});
        }
    return all;
}

std::string bytesOf(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(FuzzRegression, EveryKeptInputLoadsOrGetsAClearError) {
    const std::vector<Replay> all = replays();
    ASSERT_GE(all.size(), 10u) << "the seed corpus under fuzz/corpus/ is missing";
    for (const Replay& r : all) {
        SCOPED_TRACE(r.target + ": " + r.input.string());
        // Laid out as the fuzzers lay it out: shipped models reachable as models/ and ../models/.
        test::TempDir dir;
        const fs::path scenes = SHADOWLAB_SOURCE_DIR "/scenes";
        fs::create_directories(dir.path() / "case");
        fs::create_directory_symlink(scenes / "models", dir.path() / "models");
        fs::create_directory_symlink(scenes / "extreme" / "models", dir.path() / "case" / "models");
        fuzz::makeIndirectFiles(dir.path() / "case");
        const std::string bytes = bytesOf(r.input);
        const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data());
        const fs::path file = dir.write("case/" + fuzz::inputName(r.target, data, bytes.size()), bytes);
        try {
            fuzz::readAs(r.target, file);
            EXPECT_FALSE(r.finding) << "a kept finding loaded without an error";
        } catch (const scene::SceneError& e) {
            EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
        } catch (const scene::InputError& e) {
            EXPECT_NE(std::string(e.what()).find(file.filename().string()), std::string::npos) << e.what();
        } catch (const std::exception& e) {
            ADD_FAILURE() << "unexpected exception: " << e.what();
        }
    }
}

}  // namespace
}  // namespace shadowlab

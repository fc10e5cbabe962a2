// tests/tree/format_test.cpp: every tracked C++ file is laid out as .clang-format says, checked
// with clang-format 14 (Debian 12's; other versions break lines differently, so they skip).
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

namespace {

struct Result {
    int status = -1;
    std::string output;
};

// Runs a shell command, stderr folded into the output.
Result run(const std::string& command) {
    Result result;
    FILE* pipe = popen((command + " 2>&1").c_str(), "r");
    if (!pipe) return result;
    std::array<char, 4096> buffer{};
    while (size_t n = fread(buffer.data(), 1, buffer.size(), pipe)) result.output.append(buffer.data(), n);
    const int status = pclose(pipe);
    result.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return result;
}

// The clang-format 14 binary's name, or empty when none is installed.
std::string clangFormat14() {
    for (const char* name : {"clang-format-14", "clang-format"}) {
        const Result version = run(std::string(name) + " --version");
        if (version.status == 0 && version.output.find("version 14.") != std::string::npos) return name;
    }
    return {};
}

const std::string kSource = SHADOWLAB_SOURCE_DIR;

}  // namespace

TEST(Format, EveryTrackedCppFilePassesClangFormat) {
    const std::string tool = clangFormat14();
    if (tool.empty()) GTEST_SKIP() << "clang-format 14 is not installed (tools/debian-packages.txt lists it)";
    if (!std::filesystem::exists(kSource + "/.git")) GTEST_SKIP() << "not a git checkout: no file list";
    // A checkout git will not read (another owner without safe.directory, say) has no list either.
    const Result files = run("git -C '" + kSource + "' ls-files '*.cpp' '*.h'");
    if (files.status != 0) GTEST_SKIP() << "git ls-files failed: " << files.output;
    ASSERT_NE(files.output.find(".cpp"), std::string::npos) << "no C++ file listed";
    const Result result = run("cd '" + kSource + "' && git ls-files -z '*.cpp' '*.h' | xargs -0 " + tool +
                              " --dry-run --Werror --style=file");
    EXPECT_EQ(result.status, 0) << "run `clang-format -i` on the files below:\n" << result.output;
}

// The check above can fail: a line that breaks the layout (two statements, no spaces) is refused.
TEST(Format, AMisformattedFileIsRefused) {
    const std::string tool = clangFormat14();
    if (tool.empty()) GTEST_SKIP() << "clang-format 14 is not installed";
    const Result result = run("cd '" + kSource + "' && printf 'int f(){int a=1;return a;}\\n' | " + tool +
                              " --dry-run --Werror --style=file --assume-filename=raster/x.cpp");
    EXPECT_NE(result.status, 0) << result.output;
    EXPECT_NE(result.output.find("code should be clang-formatted"), std::string::npos) << result.output;
}

// tests/app/cli.h: runs the `shadowlab` program with arguments and captures its exit code,
// stdout and stderr (for test files that need no process control; see subprocess.h for that).
#pragma once

#include <sys/wait.h>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/scene/test_files.h"

namespace shadowlab::test {

struct CliResult {
    int exitCode = -1;
    std::string out;
    std::string err;
};

inline std::string slurpFile(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

// `s` as one word for /bin/sh: in single quotes, each ' written as '\''.
inline std::string shellQuote(const std::string& s) {
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

inline CliResult runShadowlab(const std::vector<std::string>& args) {
    TempDir io;
    std::string cmd = shellQuote(SHADOWLAB_EXE);
    // (appended piece by piece: GCC 12 warns falsely, -Wrestrict, on " " + std::string)
    for (const auto& a : args) {
        cmd += ' ';
        cmd += shellQuote(a);
    }
    cmd += " >";
    cmd += shellQuote((io.path() / "out").string());
    cmd += " 2>";
    cmd += shellQuote((io.path() / "err").string());
    const int status = std::system(cmd.c_str());
    CliResult r;
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = slurpFile(io.path() / "out");
    r.err = slurpFile(io.path() / "err");
    return r;
}

}  // namespace shadowlab::test

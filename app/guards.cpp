// app/guards.cpp: input, output and standard-output checks (see guards.h).
#include "app/guards.h"

#include <unistd.h>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>

#include "scene/input_file.h"

namespace shadowlab::app {

namespace {

namespace fs = std::filesystem;

// The nearest ancestor of `p` that exists must be a folder we may create entries in.
void checkParent(const fs::path& p, const std::string& option) {
    fs::path parent = fs::absolute(p).parent_path();
    std::error_code ec;
    while (!parent.empty() && !fs::exists(parent, ec) && parent != parent.root_path()) parent = parent.parent_path();
    if (!fs::is_directory(parent, ec))
        throw scene::InputError(option + " " + p.string() + ": " + parent.string() +
                                " is a file, not a folder, so nothing can be written under it");
    if (::access(parent.c_str(), W_OK | X_OK) != 0)
        throw scene::InputError(option + " " + p.string() + ": cannot write in " + parent.string() + " (" +
                                std::strerror(errno) + ")");
}

}  // namespace

void checkOutputFile(const fs::path& file, const std::string& option) {
    std::error_code ec;
    if (fs::is_directory(file, ec))
        throw scene::InputError(option + " " + file.string() + ": is a folder; name the file to write");
    if (fs::exists(file, ec) && !fs::is_regular_file(file, ec))
        throw scene::InputError(option + " " + file.string() + ": exists and is not a regular file");
    checkParent(file, option);
}

void checkOutputFolder(const fs::path& dir, const std::string& option) {
    std::error_code ec;
    if (fs::exists(dir, ec)) {
        if (!fs::is_directory(dir, ec))
            throw scene::InputError(option + " " + dir.string() +
                                    ": is a file, not a folder; this command writes a "
                                    "folder of outputs, so " +
                                    option + " must name a folder");
        if (::access(dir.c_str(), W_OK | X_OK) != 0)
            throw scene::InputError(option + " " + dir.string() + ": cannot write in it (" + std::strerror(errno) +
                                    ")");
        return;
    }
    checkParent(dir, option);
}

CreatedFolders::CreatedFolders(const fs::path& output) {
    if (!output.has_parent_path()) return;
    std::error_code ec;
    if (fs::is_directory(output.parent_path(), ec)) return;
    for (fs::path p = output.parent_path(); !p.empty() && !fs::exists(p, ec); p = p.parent_path()) made_.push_back(p);
    fs::create_directories(output.parent_path());
    std::cerr << "shadowlab: created the folder " << output.parent_path().string() << " for "
              << output.filename().string() << "\n";
}

CreatedFolders::~CreatedFolders() {
    std::error_code ec;
    for (const fs::path& p : made_)  // a folder that holds the output (or anything) stays
        if (fs::is_directory(p, ec) && fs::is_empty(p, ec)) fs::remove(p, ec);
}

void checkReplacedFolder(const fs::path& dir, const std::vector<fs::path>& inputs, const std::string& marker,
                         const std::string& signature, const std::string& option) {
    checkOutputFolder(dir, option);
    std::error_code ec;
    const fs::path target = fs::weakly_canonical(fs::absolute(dir), ec);
    // Is `p` the target or inside it? (Both canonical, compared part by part.)
    auto within = [&](const fs::path& p) {
        const fs::path q = fs::weakly_canonical(fs::absolute(p), ec);
        auto t = target.begin(), e = target.end();
        auto i = q.begin();
        for (; t != e && i != q.end(); ++t, ++i)
            if (*t != *i) return false;
        return t == e;
    };
    const std::string why = ": this command replaces its output folder as a whole, so name a folder of its own";
    if (within(fs::current_path(ec)))
        throw scene::InputError(option + " " + dir.string() + ": is the working folder or holds it" + why);
    for (const fs::path& input : inputs)
        if (!input.empty() && within(input))
            throw scene::InputError(option + " " + dir.string() + ": holds the input " + input.string() + why);
    if (!fs::is_directory(dir, ec) || fs::is_empty(dir, ec)) return;
    std::string text;
    try {
        text = scene::readInputFile(dir / marker, 1 << 20);
    } catch (const std::exception&) {
        text.clear();  // absent, not a file, or too large: not what this command writes
    }
    if (text.find(signature) == std::string::npos)
        throw scene::InputError(option + " " + dir.string() +
                                ": holds files that no earlier run of this command wrote (no " + marker +
                                " of its own)" + why + ", or empty this one");
}

int finishStandardOutput(int status) {
    errno = 0;
    std::cout.flush();
    if (std::cout.good() && std::fflush(stdout) == 0) return status;
    const int error = errno;
    std::cerr << "shadowlab: error: writing to standard output failed"
              << (error ? std::string(": ") + std::strerror(error) : std::string()) << "\n";
    return status == 0 ? 1 : status;
}

}  // namespace shadowlab::app

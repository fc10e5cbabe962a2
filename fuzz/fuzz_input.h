// fuzz/fuzz_input.h: how a libFuzzer target turns bytes into a file and judges the outcome. Each
// input is written to a file in a private folder under /dev/shm (models/ links there let scene inputs
// name the shipped meshes), and the loader is called on it. A SceneError or InputError is the
// answer bad input must get; any other exception escaping a loader is a finding, so it aborts.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "fuzz/targets.h"
#include "scene/error.h"

namespace shadowlab::fuzz {

// The folder inputs are written to: <tmp>/shadowlab-fuzz-<pid>/case, with case/models linked to
// scenes/extreme/models and ../models to scenes/models, as the shipped scene files expect.
inline const std::filesystem::path& caseDirectory() {
    static const std::filesystem::path dir = [] {
        namespace fs = std::filesystem;
        const fs::path shm = fs::exists("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path();
        const fs::path root = shm / ("shadowlab-fuzz-" + std::to_string(::getpid()));
        const fs::path scenes = SHADOWLAB_SCENES_DIR;
        fs::create_directories(root / "case");
        std::error_code ignored;
        fs::create_directory_symlink(scenes / "models", root / "models", ignored);
        fs::create_directory_symlink(scenes / "extreme" / "models", root / "case" / "models", ignored);
        makeIndirectFiles(root / "case");
        // Leave nothing behind in /dev/shm when the fuzzer exits normally. The handler runs after
        // static destructors, so it owns a copy of the path that is never destroyed.
        static const fs::path* const leftover = new fs::path(root);
        std::atexit([] {
            std::error_code e;
            std::filesystem::remove_all(*leftover, e);
        });
        return root / "case";
    }();
    return dir;
}

inline std::filesystem::path writeInput(const std::uint8_t* data, std::size_t size, const std::string& name) {
    const std::filesystem::path file = caseDirectory() / name;
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    out.close();
    if (!out) {
        std::fprintf(stderr, "fuzz: cannot write %s\n", file.c_str());
        std::abort();
    }
    return file;
}

// Runs `load`; the project's own error types are the expected outcome of bad input.
template <class Load>
void expectCleanOutcome(Load&& load) {
    try {
        load();
    } catch (const scene::SceneError&) {
    } catch (const scene::InputError&) {
    } catch (const std::exception& e) {
        std::fprintf(stderr, "fuzz: a loader let an unexpected exception escape: %s\n", e.what());
        std::abort();
    }
}

}  // namespace shadowlab::fuzz

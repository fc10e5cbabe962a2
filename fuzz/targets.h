// fuzz/targets.h: what each fuzz target feeds its input to, shared by the libFuzzer targets and
// the FuzzRegression tests that replay their findings. Each input is a file (the loaders read
// files); its name decides how it is read.
#pragma once

#include <sys/stat.h>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include <glm/glm.hpp>

#include "scene/error.h"
#include "scene/frame_io.h"
#include "scene/loader.h"
#include "scene/mesh_loader.h"

namespace shadowlab::fuzz {

// The file name an input of `target` is written under ("scene_json", "obj", "ply", "gltf", "exr").
inline std::string inputName(std::string_view target, const std::uint8_t* data, std::size_t size) {
    if (target == "scene_json") return "scene.json";
    if (target == "obj") return "mesh.obj";
    if (target == "ply") return "mesh.ply";
    if (target == "gltf")  // GLB when it starts with the binary container's magic
        return size >= 4 && std::memcmp(data, "glTF", 4) == 0 ? "model.glb" : "model.gltf";
    return "frame.exr";
}

// Files an input may name indirectly (a mesh, an OBJ's mtllib, a glTF buffer or image URI),
// laid out beside the input in `dir` so seeds and mutations reach every kind the one input
// opener must refuse: FIFOs (which would block), links to /dev/zero (which never ends),
// folders, and a good one of each ("tri.*"). The seeds in fuzz/corpus name them.
inline void makeIndirectFiles(const std::filesystem::path& dir) {
    namespace fs = std::filesystem;
    std::error_code ignored;
    for (const char* ext : {"bin", "mtl", "obj", "png", "gltf", "json"}) {
        const std::string e = ext;
        ::mkfifo((dir / ("pipe." + e)).c_str(), 0600);
        fs::create_symlink("/dev/zero", dir / ("zero." + e), ignored);
        fs::create_directory(dir / ("dir." + e), ignored);
    }
    const float triangle[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    std::ofstream(dir / "tri.bin", std::ios::binary).write(reinterpret_cast<const char*>(triangle), sizeof triangle);
    std::ofstream(dir / "tri.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    std::ofstream(dir / "tri.mtl") << "newmtl m\nKd 1 1 1\n";
}

// Reads `file` the way the program reads input of `target`. Bad input throws SceneError or
// InputError; anything else escaping is a defect.
inline void readAs(std::string_view target, const std::filesystem::path& file) {
    if (target == "scene_json" || target == "gltf") {  // a .gltf/.glb is a scene of its own
        (void)scene::loadScene(file);
    } else if (target == "obj" || target == "ply") {
        (void)scene::loadMesh(file, glm::dmat4(1.0), file.parent_path() / "scene.json",
                              scene::JsonPath() / "objects" / 0 / "file");
    } else {
        (void)scene::readFrame(file);
    }
}

}  // namespace shadowlab::fuzz

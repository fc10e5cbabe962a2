// scene/gltf_extensions.h: the glTF extensions that change how a model's geometry or alpha is
// read (docs/scene-format.md, "glTF extensions"): which ones a file may require, meshopt and
// Draco geometry decoded into plain buffers before the accessors are read, and the
// KHR_texture_transform of an alpha texture. Used by scene/mesh_loader.cpp only.
#pragma once

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <tiny_gltf.h>

#include "scene/scene.h"

namespace shadowlab::scene {

// What is wrong, starting with the JSON path at fault; the loader adds the file's name.
struct GltfExtensionError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Buffers without data that EXT/KHR_meshopt_compression files declare for their uncompressed
// views (index → declared byteLength); tinygltf 2.7 cannot load them, so they are swapped for
// a one-byte buffer before it parses the file.
using MeshoptPlaceholders = std::map<int, std::uint64_t>;

// What the loader learns from the file's JSON before tinygltf parses it: a file that requires
// an extension shadowlab does not read is refused here, with that extension's name (before
// tinygltf stumbles over the data such an extension may leave out). A JSON tinygltf would not
// parse is left for tinygltf to report.
struct GltfPrepared {
    MeshoptPlaceholders placeholders;
    // Index accessors of Draco primitives, which have no buffer view; tinygltf 2.7 refuses
    // those, so each borrows its primitive's compressed view until tinygltf has parsed the file.
    std::vector<int> borrowedViews;
    std::string rewritten;           // the file with its placeholder buffers swapped; empty: read it as it is
    std::vector<std::string> notes;  // extensions used but not read, for the user to see
};
GltfPrepared prepareGltf(const std::string& bytes, bool binary);

// Decodes every EXT/KHR_meshopt_compression buffer view and every KHR_draco_mesh_compression
// triangle primitive into new buffers of `model` and points the views and accessors at them,
// so the accessors then read as uncompressed ones. Counts and sizes are checked against the
// file and the available memory before anything is allocated. Returns the bytes decoded.
std::uint64_t decodeCompressedGeometry(tinygltf::Model& model, const GltfPrepared& prepared);

// KHR_texture_transform of a texture reference (glTF: uv' = T · R · S · uv, offset, rotation,
// scale); `texCoord` is the set it reads, the extension's override or the reference's own.
struct UvTransform {
    double m[6] = {1, 0, 0, 0, 1, 0};  // u' = m0 u + m1 v + m2, v' = m3 u + m4 v + m5
    bool identity = true;
    Vec2 apply(const Vec2& uv) const {
        return identity ? uv : Vec2(m[0] * uv.x + m[1] * uv.y + m[2], m[3] * uv.x + m[4] * uv.y + m[5]);
    }
};
// Reads `info`'s KHR_texture_transform (identity without one); `at` is the reference's JSON
// path. texCoord starts as the reference's own and is overridden by the extension's.
UvTransform readTextureTransform(const tinygltf::TextureInfo& info, const std::string& at, int& texCoord);

// The JSON of a .gltf file, or of a GLB's first chunk (GLB header: magic, version, length; then
// chunk length and type "JSON"); empty when the header is not a GLB's (tinygltf then says what
// is wrong).
std::string_view gltfJsonChunk(const std::string& bytes, bool binary);

// What is wrong with a GLB container's sizes (glTF 2.0, 4.4): the header's length must lie in
// the file, and each chunk within that length; empty when they do, or when the bytes are not a
// GLB at all (tinygltf says so). tinygltf 2.7 copies a BIN chunk of the length its header
// declares, past the end of a file cut short.
std::string glbLayoutProblem(const std::string& bytes);

}  // namespace shadowlab::scene

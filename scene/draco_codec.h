// scene/draco_codec.h: the Draco mesh codec behind a small interface of standard types, built
// as its own shared library (shadowlab_draco). Debian's libdraco carries copies of tinygltf and
// stb_image of other versions; linked into the program, their symbols stood in for libtinygltf's
// and crashed it. This library links Draco's static archive with every archive symbol hidden
// (-Wl,--exclude-libs,ALL), so the program sees only the functions below.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace shadowlab::scene {

class DracoMesh {
public:
    // Decodes a Draco-compressed triangle mesh; null with `error` set (Draco's own words) when
    // the data is not one. Draco checks its declared counts against the data's size.
    static std::unique_ptr<DracoMesh> decode(const unsigned char* data, std::size_t size, std::string& error);
    ~DracoMesh();

    std::uint32_t points() const;
    std::uint32_t faces() const;
    bool hasAttribute(int uniqueId) const;
    // The attribute's value at every point as `components` values of glTF component type
    // `componentType` (5120..5126) into `out` (points() × components × its size bytes); false
    // with `badPoint` set where a value does not convert to that type.
    bool readAttribute(int uniqueId, int componentType, int components, unsigned char* out,
                       std::uint32_t& badPoint) const;
    // The triangles' point indices, 3 a face (faces() × 3 values).
    void readIndices(std::uint32_t* out) const;

private:
    struct Impl;
    explicit DracoMesh(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

// Encodes triangles (9 floats each: 3 corners' x, y, z) as a Draco mesh with POSITION quantized
// to `positionBits` bits, Draco's default settings otherwise; `positionId` receives the
// attribute's id. For tests and tools that make compressed files.
std::vector<unsigned char> encodeDracoTriangles(const std::vector<float>& corners, int positionBits, int& positionId);

}  // namespace shadowlab::scene

// scene/draco_codec.cpp: see draco_codec.h.
#include "scene/draco_codec.h"

#include <cstring>

#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/triangle_soup_mesh_builder.h>

namespace shadowlab::scene {

struct DracoMesh::Impl {
    std::unique_ptr<draco::Mesh> mesh;
};

DracoMesh::DracoMesh(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
DracoMesh::~DracoMesh() = default;

std::unique_ptr<DracoMesh> DracoMesh::decode(const unsigned char* data, std::size_t size, std::string& error) {
    draco::DecoderBuffer input;
    input.Init(reinterpret_cast<const char*>(data), size);
    draco::Decoder decoder;
    auto result = decoder.DecodeMeshFromBuffer(&input);
    if (!result.ok()) {
        error = result.status().error_msg_string();
        return nullptr;
    }
    auto impl = std::make_unique<Impl>();
    impl->mesh = std::move(result).value();
    if (!impl->mesh) {
        error = "no mesh in the data";
        return nullptr;
    }
    return std::unique_ptr<DracoMesh>(new DracoMesh(std::move(impl)));
}

std::uint32_t DracoMesh::points() const { return impl_->mesh->num_points(); }
std::uint32_t DracoMesh::faces() const { return impl_->mesh->num_faces(); }
bool DracoMesh::hasAttribute(int uniqueId) const {
    return uniqueId >= 0 && impl_->mesh->GetAttributeByUniqueId(std::uint32_t(uniqueId)) != nullptr;
}

namespace {
template <typename T>
bool convertAll(const draco::PointAttribute& att, std::uint32_t points, int components, unsigned char* out,
                std::uint32_t& badPoint) {
    T value[16];
    if (components < 1 || components > 16) return false;
    for (std::uint32_t p = 0; p < points; ++p) {
        if (!att.ConvertValue<T>(att.mapped_index(draco::PointIndex(p)), std::int8_t(components), value)) {
            badPoint = p;
            return false;
        }
        std::memcpy(out + std::size_t(p) * sizeof(T) * std::size_t(components), value,
                    sizeof(T) * std::size_t(components));
    }
    return true;
}
}  // namespace

bool DracoMesh::readAttribute(int uniqueId, int componentType, int components, unsigned char* out,
                              std::uint32_t& badPoint) const {
    badPoint = 0;
    const draco::PointAttribute* att = impl_->mesh->GetAttributeByUniqueId(std::uint32_t(uniqueId));
    if (!att) return false;
    const std::uint32_t n = points();
    switch (componentType) {
        case 5120: return convertAll<std::int8_t>(*att, n, components, out, badPoint);
        case 5121: return convertAll<std::uint8_t>(*att, n, components, out, badPoint);
        case 5122: return convertAll<std::int16_t>(*att, n, components, out, badPoint);
        case 5123: return convertAll<std::uint16_t>(*att, n, components, out, badPoint);
        case 5125: return convertAll<std::uint32_t>(*att, n, components, out, badPoint);
        case 5126: return convertAll<float>(*att, n, components, out, badPoint);
        default: return false;
    }
}

void DracoMesh::readIndices(std::uint32_t* out) const {
    const std::uint32_t n = faces();
    for (std::uint32_t f = 0; f < n; ++f) {
        const draco::Mesh::Face& face = impl_->mesh->face(draco::FaceIndex(f));
        for (int k = 0; k < 3; ++k) out[std::size_t(f) * 3 + std::size_t(k)] = face[k].value();
    }
}

std::vector<unsigned char> encodeDracoTriangles(const std::vector<float>& corners, int positionBits, int& positionId) {
    const std::size_t triangles = corners.size() / 9;
    draco::TriangleSoupMeshBuilder builder;
    builder.Start(int(triangles));
    const int pos = builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
    for (std::size_t f = 0; f < triangles; ++f)
        builder.SetAttributeValuesForFace(pos, draco::FaceIndex(std::uint32_t(f)), &corners[9 * f], &corners[9 * f + 3],
                                          &corners[9 * f + 6]);
    std::unique_ptr<draco::Mesh> mesh = builder.Finalize();
    if (!mesh) return {};
    draco::Encoder encoder;
    encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, positionBits);
    draco::EncoderBuffer out;
    if (!encoder.EncodeMeshToBuffer(*mesh, &out).ok()) return {};
    positionId = int(mesh->attribute(pos)->unique_id());
    return std::vector<unsigned char>(out.data(), out.data() + out.size());
}

}  // namespace shadowlab::scene

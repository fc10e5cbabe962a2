// scene/gltf_extensions.cpp: required-extension check, meshopt and Draco decoding into plain
// buffers, KHR_texture_transform (see gltf_extensions.h).
#include "scene/gltf_extensions.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <new>
#include <set>

#include <meshoptimizer.h>
#include <nlohmann/json.hpp>

#include "scene/draco_codec.h"
#include "scene/error.h"
#include "scene/memory.h"

namespace shadowlab::scene {

namespace {

[[noreturn]] void bad(const std::string& at, const std::string& what) { throw GltfExtensionError(at + ": " + what); }

bool addChecked(std::uint64_t a, std::uint64_t b, std::uint64_t& out) { return !__builtin_add_overflow(a, b, &out); }
bool mulChecked(std::uint64_t a, std::uint64_t b, std::uint64_t& out) { return !__builtin_mul_overflow(a, b, &out); }

// Extensions read (each changes geometry, alpha or lights, and is implemented), and those that
// may be required although they are not read, because they change neither the triangles nor
// where a surface is cut out or lets light through: material shading (the KHR_materials_* but
// specular-glossiness, whose diffuse alpha replaces the base colour's, and the transmissive
// ones, whose surfaces pass light that shadowlab would block), texture image formats (an alpha
// texture stored only in one shadowlab cannot decode is refused where it is read) and metadata.
const std::set<std::string, std::less<>> kRead = {"KHR_mesh_quantization",   "KHR_draco_mesh_compression",
                                                  "EXT_meshopt_compression", "KHR_meshopt_compression",
                                                  "KHR_texture_transform",   "KHR_lights_punctual"};
const std::set<std::string, std::less<>> kHarmless = {"KHR_texture_basisu", "EXT_texture_webp", "EXT_texture_avif",
                                                      "KHR_xmp_json_ld", "KHR_xmp"};
const std::set<std::string, std::less<>> kTransmissive = {"KHR_materials_transmission", "KHR_materials_volume",
                                                          "KHR_materials_diffuse_transmission"};
bool harmless(const std::string& name) {
    return kHarmless.count(name) || (name.rfind("KHR_materials_", 0) == 0 &&
                                     name != "KHR_materials_pbrSpecularGlossiness" && !kTransmissive.count(name));
}

// Why a required extension is refused, where shadowlab knows it.
std::string refusal(const std::string& name) {
    if (name == "KHR_materials_pbrSpecularGlossiness")
        return "its diffuse alpha, not the base colour's, decides what MASK and BLEND materials cut out";
    if (kTransmissive.count(name)) return "its surfaces let light through, where shadowlab's would cast a full shadow";
    if (name == "EXT_mesh_gpu_instancing") return "it places a mesh many times, which shadowlab would draw once";
    if (name == "KHR_node_visibility") return "it hides nodes, which shadowlab would draw";
    return "it may change the geometry or alpha that shadows depend on";
}

std::uint32_t readU32(const std::string& bytes, std::size_t at) {
    std::uint32_t v = 0;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
}
void appendU32(std::string& out, std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); }

// A whole number >= 0 (at most 2^53, exact in a double) at `key` of extension object `ext`;
// `fallback` where the key is absent and not `required`.
std::uint64_t wholeNumber(const tinygltf::Value& ext, const char* key, const std::string& at, bool required,
                          std::uint64_t fallback = 0) {
    if (!ext.Has(key)) {
        if (required) bad(at, "has no \"" + std::string(key) + "\", which it needs");
        return fallback;
    }
    const tinygltf::Value& v = ext.Get(key);
    const double d = v.IsNumber() || v.IsInt() ? v.GetNumberAsDouble() : -1.0;
    if (!(d >= 0 && d <= 9007199254740992.0 && d == std::floor(d))) bad(at + "." + key, "must be a whole number >= 0");
    return std::uint64_t(d);
}

std::string stringField(const tinygltf::Value& ext, const char* key, const std::string& at, const char* fallback) {
    if (!ext.Has(key)) {
        if (!fallback) bad(at, "has no \"" + std::string(key) + "\", which it needs");
        return fallback;
    }
    const tinygltf::Value& v = ext.Get(key);
    if (!v.IsString()) bad(at + "." + key, "must be a string");
    return v.Get<std::string>();
}

void checkMemoryFor(std::uint64_t total, const std::string& at) {
    if (const std::uint64_t available = availableMemoryBytes(); available != 0 && total > available)
        bad(at, "decoding needs " + std::to_string(total / kMiB) + " MiB, more than the " +
                    std::to_string(available / kMiB) + " MiB available");
}

// A new buffer of `model` holding `data`; its index.
int addBuffer(tinygltf::Model& model, std::vector<unsigned char> data) {
    tinygltf::Buffer b;
    b.data = std::move(data);
    model.buffers.push_back(std::move(b));
    return int(model.buffers.size() - 1);
}

// ---- EXT_meshopt_compression / KHR_meshopt_compression -----------------------------------

// The attribute codec packs 16 elements a group with 2 header bits a group per byte of an
// element, so a block of up to 256 elements costs at least stride × 4 bytes (all deltas zero):
// no stream decodes to more than 64 times its size (the bitstream in the extension's
// Appendix A), which bounds what a file can make us allocate before the decoder reads it.
constexpr std::uint64_t kMaxAttributeExpansion = 64;

void decodeMeshoptView(tinygltf::Model& model, std::size_t viewIndex, const std::string& name,
                       const MeshoptPlaceholders& placeholders, std::uint64_t& total) {
    tinygltf::BufferView& view = model.bufferViews[viewIndex];
    const std::string at = "bufferViews[" + std::to_string(viewIndex) + "].extensions." + name;
    const tinygltf::Value ext = view.extensions.at(name);
    if (!ext.IsObject()) bad(at, "must be an object");
    const std::uint64_t bufferIndex = wholeNumber(ext, "buffer", at, true);
    const std::uint64_t offset = wholeNumber(ext, "byteOffset", at, false, 0);
    const std::uint64_t length = wholeNumber(ext, "byteLength", at, true);
    const std::uint64_t stride = wholeNumber(ext, "byteStride", at, true);
    const std::uint64_t count = wholeNumber(ext, "count", at, true);
    const std::string mode = stringField(ext, "mode", at, nullptr);
    const std::string filter = stringField(ext, "filter", at, "NONE");
    if (bufferIndex >= model.buffers.size())
        bad(at + ".buffer", "names buffer " + std::to_string(bufferIndex) + ", which does not exist (" +
                                std::to_string(model.buffers.size()) + " buffers)");
    if (placeholders.count(int(bufferIndex)))
        bad(at + ".buffer", "names buffer " + std::to_string(bufferIndex) +
                                ", a fallback buffer without data, where the compressed data must be");
    const auto& source = model.buffers[bufferIndex].data;
    std::uint64_t end = 0;
    if (!addChecked(offset, length, end) || end > source.size())
        bad(at, "byteOffset " + std::to_string(offset) + " + byteLength " + std::to_string(length) +
                    " reaches past the end of buffer " + std::to_string(bufferIndex) + " (" +
                    std::to_string(source.size()) + " bytes)");
    // The extension's rules (its "JSON schema updates" list), each checked before the decoder,
    // which asserts some of them.
    const bool attributes = mode == "ATTRIBUTES", triangles = mode == "TRIANGLES", indices = mode == "INDICES";
    if (!attributes && !triangles && !indices)
        bad(at + ".mode", "must be ATTRIBUTES, TRIANGLES or INDICES, got '" + excerpt(mode) + "'");
    if (attributes && (stride < 4 || stride > 256 || stride % 4 != 0))
        bad(at + ".byteStride", "must be a multiple of 4 in 4..256 for ATTRIBUTES, got " + std::to_string(stride));
    if (!attributes && stride != 2 && stride != 4)
        bad(at + ".byteStride", "must be 2 or 4 for " + mode + ", got " + std::to_string(stride));
    if (triangles && count % 3 != 0)
        bad(at + ".count", "must be a multiple of 3 for TRIANGLES, got " + std::to_string(count));
    if (filter != "NONE" && !attributes) bad(at + ".filter", "must be NONE for " + mode);
    if (filter == "OCTAHEDRAL" && stride != 4 && stride != 8) bad(at + ".filter", "OCTAHEDRAL needs byteStride 4 or 8");
    if (filter == "QUATERNION" && stride != 8) bad(at + ".filter", "QUATERNION needs byteStride 8");
    if (filter == "COLOR")
        bad(at + ".filter", "COLOR (colours, which shadows do not use) is not decoded by the meshoptimizer " +
                                std::to_string(MESHOPTIMIZER_VERSION / 1000) + "." +
                                std::to_string(MESHOPTIMIZER_VERSION % 1000 / 10) + " that shadowlab links");
    if (filter != "NONE" && filter != "OCTAHEDRAL" && filter != "QUATERNION" && filter != "EXPONENTIAL")
        bad(at + ".filter", "must be NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL, got '" + excerpt(filter) + "'");
    std::uint64_t decoded = 0;
    if (!mulChecked(stride, count, decoded) || decoded != view.byteLength)
        bad(at, "byteStride " + std::to_string(stride) + " x count " + std::to_string(count) +
                    " must equal the buffer view's byteLength " + std::to_string(view.byteLength));
    // What each codec needs at least to hold `count` elements (Appendix A): an attribute stream
    // a 64th of its output, a triangle one byte a triangle, an index sequence one byte an index.
    std::uint64_t needed = 0;
    if (attributes) needed = decoded / kMaxAttributeExpansion;
    if (triangles) needed = count / 3;
    if (indices) needed = count;
    if (count > 0 && length < needed)
        bad(at, "byteLength " + std::to_string(length) + " is too short to hold " + std::to_string(count) +
                    " elements of " + std::to_string(stride) + " bytes (at least " + std::to_string(needed) +
                    " bytes): the compressed data is cut short or the count is wrong");
    if (!addChecked(total, decoded, total)) bad(at, "the decoded sizes overflow");
    checkMemoryFor(total, at);
    const unsigned char* data = source.data() + offset;
    if (attributes && length > 0 && (data[0] & 0xf0) == 0xa0 && (data[0] & 0x0f) > 0)
        bad(at, "the attribute stream is of version " + std::to_string(data[0] & 0x0f) +
                    " (KHR_meshopt_compression's v1 format), which the meshoptimizer " +
                    std::to_string(MESHOPTIMIZER_VERSION / 1000) + "." +
                    std::to_string(MESHOPTIMIZER_VERSION % 1000 / 10) +
                    " that shadowlab links does not decode; write the file with version 0 (gltfpack -ce ext)");
    std::vector<unsigned char> out(std::max<std::uint64_t>(decoded, 1));
    int rc = 0;
    if (count > 0) {
        if (attributes)
            rc = meshopt_decodeVertexBuffer(out.data(), count, stride, data, length);
        else if (triangles)
            rc = meshopt_decodeIndexBuffer(out.data(), count, stride, data, length);
        else
            rc = meshopt_decodeIndexSequence(out.data(), count, stride, data, length);
    }
    if (rc != 0)
        bad(at, "the compressed data does not decode to " + std::to_string(count) + " elements of " +
                    std::to_string(stride) + " bytes (meshoptimizer error " + std::to_string(rc) +
                    (rc == -2 ? ": the data is cut short" : ": not a valid " + mode + " stream of this size") + ")");
    if (count > 0) {
        if (filter == "OCTAHEDRAL") meshopt_decodeFilterOct(out.data(), count, stride);
        if (filter == "QUATERNION") meshopt_decodeFilterQuat(out.data(), count, stride);
        if (filter == "EXPONENTIAL") meshopt_decodeFilterExp(out.data(), count, stride);
    }
    out.resize(decoded);
    view.buffer = addBuffer(model, std::move(out));
    view.byteOffset = 0;
    view.extensions.erase(name);
}

// ---- KHR_draco_mesh_compression ---------------------------------------------------------

// One primitive's compressed data, and the accessors it decodes (to tell a shared accessor
// decoded twice the same way from two primitives claiming one accessor).
struct DracoSource {
    int bufferView = -1;
    int attributeId = -1;  // -1: the indices
    bool operator==(const DracoSource&) const = default;
};

void decodeDracoPrimitive(tinygltf::Model& model, std::size_t meshIndex, std::size_t primIndex,
                          std::map<int, DracoSource>& decodedAccessors, std::uint64_t& total) {
    tinygltf::Primitive& prim = model.meshes[meshIndex].primitives[primIndex];
    const std::string primAt =
        "meshes[" + std::to_string(meshIndex) + "].primitives[" + std::to_string(primIndex) + "]";
    const std::string at = primAt + ".extensions.KHR_draco_mesh_compression";
    const tinygltf::Value& ext = prim.extensions.at("KHR_draco_mesh_compression");
    if (!ext.IsObject()) bad(at, "must be an object");
    const std::uint64_t viewIndex = wholeNumber(ext, "bufferView", at, true);
    if (viewIndex >= model.bufferViews.size())
        bad(at + ".bufferView", "names buffer view " + std::to_string(viewIndex) + ", which does not exist (" +
                                    std::to_string(model.bufferViews.size()) + " buffer views)");
    if (!ext.Has("attributes") || !ext.Get("attributes").IsObject()) bad(at, "has no \"attributes\" object");
    const tinygltf::Value& ids = ext.Get("attributes");
    // The glTF attributes the compressed data holds, each with its accessor and Draco id.
    struct Wanted {
        std::string name;
        int accessor;
        int id;
    };
    std::vector<Wanted> wanted;
    std::uint64_t bytes = 0;
    for (const auto& [name, accessor] : prim.attributes) {
        if (!ids.Has(name)) continue;
        const std::uint64_t id = wholeNumber(ids, name.c_str(), at + ".attributes", true);
        if (id > std::uint64_t(INT32_MAX)) bad(at + ".attributes." + name, "is too large");
        if (accessor < 0 || std::size_t(accessor) >= model.accessors.size())
            bad(primAt + ".attributes." + name,
                "names accessor " + std::to_string(accessor) + ", which does not exist");
        const auto& acc = model.accessors[std::size_t(accessor)];
        const int comp = tinygltf::GetComponentSizeInBytes(acc.componentType);
        const int nComp = tinygltf::GetNumComponentsInType(acc.type);
        if (comp <= 0 || nComp <= 0 || nComp > 16)
            bad("accessors[" + std::to_string(accessor) + "]", "has an unexpected type or componentType");
        std::uint64_t size = 0;
        if (!mulChecked(acc.count, std::uint64_t(comp) * std::uint64_t(nComp), size) || !addChecked(bytes, size, bytes))
            bad("accessors[" + std::to_string(accessor) + "].count", "is too large");
        wanted.push_back({name, accessor, int(id)});
    }
    if (prim.indices >= 0) {
        if (std::size_t(prim.indices) >= model.accessors.size())
            bad(primAt + ".indices", "names accessor " + std::to_string(prim.indices) + ", which does not exist");
        std::uint64_t size = 0;
        if (!mulChecked(model.accessors[std::size_t(prim.indices)].count, 4, size) || !addChecked(bytes, size, bytes))
            bad("accessors[" + std::to_string(prim.indices) + "].count", "is too large");
    }
    // The accessors' counts must match the decoded mesh (checked below), so they bound the output.
    if (!addChecked(total, bytes, total)) bad(at, "the decoded sizes overflow");
    checkMemoryFor(total, at);

    const tinygltf::BufferView& view = model.bufferViews[viewIndex];
    const std::string viewAt = "bufferViews[" + std::to_string(viewIndex) + "]";
    if (view.buffer < 0 || std::size_t(view.buffer) >= model.buffers.size())
        bad(viewAt + ".buffer", "names buffer " + std::to_string(view.buffer) + ", which does not exist");
    const auto& source = model.buffers[std::size_t(view.buffer)].data;
    std::uint64_t end = 0;
    if (!addChecked(view.byteOffset, view.byteLength, end) || end > source.size())
        bad(viewAt, "byteOffset " + std::to_string(view.byteOffset) + " + byteLength " +
                        std::to_string(view.byteLength) + " reaches past the end of buffer " +
                        std::to_string(view.buffer) + " (" + std::to_string(source.size()) + " bytes)");

    std::unique_ptr<DracoMesh> mesh;
    std::string error;
    try {
        mesh = DracoMesh::decode(source.data() + view.byteOffset, view.byteLength, error);
    } catch (const std::bad_alloc&) {
        bad(at, "decoding the Draco data in " + viewAt + " needs more memory than there is");
    }
    if (!mesh)
        bad(at, "the Draco data in " + viewAt + " does not decode (" + excerpt(error, 200) + "): cut short or corrupt");
    const std::uint32_t points = mesh->points();
    const std::uint32_t faces = mesh->faces();

    std::vector<unsigned char> out;
    std::vector<std::pair<int, std::uint64_t>> placed;  // accessor, offset in `out`
    for (const Wanted& w : wanted) {
        tinygltf::Accessor& acc = model.accessors[std::size_t(w.accessor)];
        const std::string accAt = "accessors[" + std::to_string(w.accessor) + "]";
        const DracoSource src{int(viewIndex), w.id};
        if (const auto it = decodedAccessors.find(w.accessor); it != decodedAccessors.end()) {
            if (it->second == src) continue;  // the same data, already decoded for another primitive
            bad(primAt + ".attributes." + w.name,
                "names " + accAt + ", which another compressed primitive decodes differently");
        }
        if (!mesh->hasAttribute(w.id))
            bad(at + ".attributes." + w.name,
                "Draco attribute " + std::to_string(w.id) + " is not in the data of " + viewAt);
        if (acc.count != points)
            bad(accAt + ".count", std::to_string(acc.count) + " elements, but the Draco data of " + w.name + " holds " +
                                      std::to_string(points) + " points");
        const int nComp = tinygltf::GetNumComponentsInType(acc.type);
        const std::uint64_t offset = out.size();
        out.resize(out.size() + std::uint64_t(points) * std::uint64_t(nComp) *
                                    std::uint64_t(tinygltf::GetComponentSizeInBytes(acc.componentType)));
        std::uint32_t badPoint = 0;
        if (!mesh->readAttribute(w.id, acc.componentType, nComp, out.data() + offset, badPoint))
            bad(at + ".attributes." + w.name, "the decoded value of point " + std::to_string(badPoint) +
                                                  " does not fit " + accAt + "'s component type " +
                                                  std::to_string(acc.componentType));
        placed.emplace_back(w.accessor, offset);
        decodedAccessors[w.accessor] = src;
    }
    bool placeIndices = false;
    std::uint64_t indexOffset = 0;
    const DracoSource indexSrc{int(viewIndex), -1};
    if (prim.indices >= 0 && decodedAccessors.count(prim.indices)) {
        if (!(decodedAccessors[prim.indices] == indexSrc))
            bad(primAt + ".indices", "names an accessor another compressed primitive decodes differently");
    } else {
        if (prim.indices >= 0 && model.accessors[std::size_t(prim.indices)].count != std::uint64_t(faces) * 3)
            bad("accessors[" + std::to_string(prim.indices) + "].count",
                std::to_string(model.accessors[std::size_t(prim.indices)].count) + " indices, but the Draco data of " +
                    primAt + " holds " + std::to_string(faces) + " triangles (" +
                    std::to_string(std::uint64_t(faces) * 3) + " indices)");
        indexOffset = out.size();
        std::vector<std::uint32_t> indices(std::size_t(faces) * 3);
        mesh->readIndices(indices.data());
        out.resize(out.size() + indices.size() * 4);
        std::memcpy(out.data() + indexOffset, indices.data(), indices.size() * 4);
        placeIndices = true;
    }
    if (out.empty()) return;
    const int buffer = addBuffer(model, std::move(out));
    const std::uint64_t bufferSize = model.buffers[std::size_t(buffer)].data.size();
    // One plain view for all of the primitive's decoded accessors, tightly packed.
    tinygltf::BufferView decodedView;
    decodedView.buffer = buffer;
    decodedView.byteOffset = 0;
    decodedView.byteLength = bufferSize;
    model.bufferViews.push_back(decodedView);
    const int newView = int(model.bufferViews.size() - 1);
    for (const auto& [accessor, offset] : placed) {
        tinygltf::Accessor& acc = model.accessors[std::size_t(accessor)];
        acc.bufferView = newView;
        acc.byteOffset = offset;
        acc.sparse.isSparse = false;  // the compressed data is the whole attribute
    }
    if (placeIndices) {
        if (prim.indices < 0) {
            tinygltf::Accessor acc;
            acc.type = TINYGLTF_TYPE_SCALAR;
            model.accessors.push_back(acc);
            prim.indices = int(model.accessors.size() - 1);
        }
        tinygltf::Accessor& acc = model.accessors[std::size_t(prim.indices)];
        acc.bufferView = newView;
        acc.byteOffset = indexOffset;
        acc.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
        acc.normalized = false;
        acc.count = std::size_t(faces) * 3;
        acc.sparse.isSparse = false;
        decodedAccessors[prim.indices] = indexSrc;
    }
}

}  // namespace

std::string_view gltfJsonChunk(const std::string& bytes, bool binary) {
    if (!binary) return bytes;
    if (bytes.size() < 20 || bytes.compare(0, 4, "glTF") != 0) return {};
    const std::uint32_t chunkLength = readU32(bytes, 12);
    if (bytes.compare(16, 4, "JSON") != 0 || chunkLength > bytes.size() - 20) return {};
    return std::string_view(bytes.data() + 20, chunkLength);
}

std::string glbLayoutProblem(const std::string& bytes) {
    if (bytes.size() < 12 || bytes.compare(0, 4, "glTF") != 0) return {};
    // Bytes after the declared length are ignored, as tinygltf ignores them.
    const std::uint64_t declared = readU32(bytes, 8);
    if (declared > bytes.size())
        return "GLB header: declares " + std::to_string(declared) + " bytes, but the file has only " +
               std::to_string(bytes.size()) + " (cut short?)";
    // Chunk by chunk: length (4 bytes), type (4), data; the JSON chunk first, then BIN.
    std::uint64_t at = 12;
    for (int chunk = 0; at < declared; ++chunk) {
        const std::string name = "GLB chunk " + std::to_string(chunk) +
                                 (chunk == 0   ? " (JSON)"
                                  : chunk == 1 ? " (BIN)"
                                               : "");
        if (declared - at < 8) return name + ": its 8-byte header is cut short at byte " + std::to_string(at);
        const std::uint64_t length = readU32(bytes, std::size_t(at));
        if (length > declared - at - 8)
            return name + ": declares " + std::to_string(length) + " bytes, but only " +
                   std::to_string(declared - at - 8) + " follow its header";
        at += 8 + length;
    }
    return {};
}

GltfPrepared prepareGltf(const std::string& bytes, bool binary) {
    GltfPrepared out;
    const std::string_view text = gltfJsonChunk(bytes, binary);
    // Most files name no extension; they are not parsed twice.
    if (text.find("\"extensions") == std::string_view::npos) return out;
    nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
    if (j.is_discarded() || !j.is_object()) return out;  // tinygltf says what is wrong
    std::set<std::string> required;
    if (const auto it = j.find("extensionsRequired"); it != j.end() && it->is_array()) {
        for (std::size_t i = 0; i < it->size(); ++i) {
            if (!(*it)[i].is_string()) continue;
            const std::string name = (*it)[i].get<std::string>();
            required.insert(name);
            if (kRead.count(name) || harmless(name)) continue;
            bad("extensionsRequired[" + std::to_string(i) + "]",
                "the file requires " + excerpt(name) + ", which shadowlab does not read (" + refusal(name) +
                    "); docs/scene-format.md lists the glTF extensions it reads");
        }
    }
    bool meshopt = required.count("EXT_meshopt_compression") || required.count("KHR_meshopt_compression");
    if (const auto it = j.find("extensionsUsed"); it != j.end() && it->is_array()) {
        for (const auto& used : *it) {
            if (!used.is_string()) continue;
            const std::string name = used.get<std::string>();
            meshopt = meshopt || name == "EXT_meshopt_compression" || name == "KHR_meshopt_compression";
            if (!kRead.count(name) && !harmless(name) && !required.count(name) && out.notes.size() < 16)
                out.notes.push_back("extensionsUsed: " + excerpt(name) +
                                    " is not read; the model is read as if it were absent");
        }
    }
    // tinygltf keeps an extension's whole numbers as int (2^32 + 5 would read as 5): the
    // numbers of the extensions decoded here are checked to fit first.
    auto checkInts = [](const nlohmann::json& object, const std::string& at, auto& self) -> void {
        if (object.is_object() || object.is_array()) {
            std::size_t i = 0;
            for (auto it = object.begin(); it != object.end(); ++it, ++i)
                self(*it, at + (object.is_object() ? "." + excerpt(it.key(), 40) : "[" + std::to_string(i) + "]"),
                     self);
        } else if ((object.is_number_integer() &&
                    (object.get<std::int64_t>() < 0 || object.get<std::int64_t>() > INT32_MAX)) ||
                   (object.is_number_unsigned() && object.get<std::uint64_t>() > std::uint64_t(INT32_MAX))) {
            bad(at, object.dump() + " is out of the range shadowlab reads (0..2147483647)");
        }
    };
    bool rewrite = false;
    if (const auto views = j.find("bufferViews"); views != j.end() && views->is_array())
        for (std::size_t v = 0; v < views->size(); ++v)
            for (const char* name : {"EXT_meshopt_compression", "KHR_meshopt_compression"})
                if ((*views)[v].is_object() && (*views)[v].contains("extensions") &&
                    (*views)[v]["extensions"].is_object() && (*views)[v]["extensions"].contains(name))
                    checkInts((*views)[v]["extensions"][name],
                              "bufferViews[" + std::to_string(v) + "].extensions." + name, checkInts);
    const auto accessors = j.find("accessors");
    if (const auto meshes = j.find("meshes"); meshes != j.end() && meshes->is_array())
        for (std::size_t m = 0; m < meshes->size(); ++m) {
            const nlohmann::json& mesh = (*meshes)[m];
            if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
            for (std::size_t p = 0; p < mesh["primitives"].size(); ++p) {
                const nlohmann::json& prim = mesh["primitives"][p];
                if (!prim.is_object() || !prim.contains("extensions") || !prim["extensions"].is_object() ||
                    !prim["extensions"].contains("KHR_draco_mesh_compression"))
                    continue;
                const nlohmann::json& ext = prim["extensions"]["KHR_draco_mesh_compression"];
                checkInts(ext,
                          "meshes[" + std::to_string(m) + "].primitives[" + std::to_string(p) +
                              "].extensions.KHR_draco_mesh_compression",
                          checkInts);
                if (!prim.contains("indices") || !prim["indices"].is_number_unsigned() || !ext.is_object() ||
                    !ext.contains("bufferView") || !ext["bufferView"].is_number_unsigned() || accessors == j.end() ||
                    !accessors->is_array() || prim["indices"].get<std::uint64_t>() >= accessors->size())
                    continue;  // tinygltf or the decoder reports what is wrong
                nlohmann::json& acc = (*accessors)[prim["indices"].get<std::size_t>()];
                if (!acc.is_object() || acc.contains("bufferView")) continue;
                acc["bufferView"] = ext["bufferView"];
                out.borrowedViews.push_back(prim["indices"].get<int>());
                rewrite = true;
            }
        }
    const auto buffers = j.find("buffers");
    if (meshopt && buffers != j.end() && buffers->is_array()) {
        // A GLB's first buffer without a URI is its binary chunk; any other buffer without one is
        // a meshopt fallback (the extension's "Fallback buffers"), which has no data to load.
        for (std::size_t i = binary ? 1 : 0; i < buffers->size(); ++i) {
            nlohmann::json& b = (*buffers)[i];
            if (!b.is_object() || b.contains("uri")) continue;
            const auto length = b.find("byteLength");
            if (length == b.end() || !length->is_number_unsigned()) continue;  // tinygltf reports it
            out.placeholders[int(i)] = length->get<std::uint64_t>();
            b = nlohmann::json{{"byteLength", 1}, {"uri", "data:application/octet-stream;base64,AA=="}};
            rewrite = true;
        }
    }
    if (!rewrite) return out;
    std::string json = j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    if (!binary) {
        out.rewritten = std::move(json);
        return out;
    }
    // The GLB again: header (magic, version, total length), the JSON chunk padded with spaces
    // to 4 bytes, then the original chunks after the JSON one, unchanged.
    while (json.size() % 4) json.push_back(' ');
    const std::size_t rest = 20 + std::size_t(readU32(bytes, 12));
    std::string& glb = out.rewritten;
    glb.reserve(20 + json.size() + (bytes.size() - rest));
    glb.append("glTF");
    appendU32(glb, readU32(bytes, 4));
    appendU32(glb, std::uint32_t(20 + json.size() + (bytes.size() - rest)));
    appendU32(glb, std::uint32_t(json.size()));
    glb.append("JSON");
    glb.append(json);
    glb.append(bytes, rest, std::string::npos);
    return out;
}

std::uint64_t decodeCompressedGeometry(tinygltf::Model& model, const GltfPrepared& prepared) {
    const MeshoptPlaceholders& placeholders = prepared.placeholders;
    for (const int accessor : prepared.borrowedViews)
        if (std::size_t(accessor) < model.accessors.size()) model.accessors[std::size_t(accessor)].bufferView = -1;
    std::uint64_t total = 0;
    const std::size_t views = model.bufferViews.size();
    for (std::size_t v = 0; v < views; ++v) {
        const auto& ext = model.bufferViews[v].extensions;
        const bool ext1 = ext.count("EXT_meshopt_compression"), khr = ext.count("KHR_meshopt_compression");
        if (ext1 && khr)
            bad("bufferViews[" + std::to_string(v) + "].extensions",
                "has both EXT_meshopt_compression and KHR_meshopt_compression, which exclude each other");
        if (ext1 || khr)
            decodeMeshoptView(model, v, ext1 ? "EXT_meshopt_compression" : "KHR_meshopt_compression", placeholders,
                              total);
    }
    // Every view left on a fallback buffer would read the placeholder's one byte.
    for (std::size_t v = 0; v < model.bufferViews.size(); ++v)
        if (placeholders.count(model.bufferViews[v].buffer))
            bad("bufferViews[" + std::to_string(v) + "].buffer",
                "names buffer " + std::to_string(model.bufferViews[v].buffer) +
                    ", a meshopt fallback buffer without data, but the view is not compressed itself");
    for (auto& [index, length] : placeholders) {
        (void)length;
        model.buffers[std::size_t(index)].data.clear();
    }
    std::map<int, DracoSource> decodedAccessors;
    for (std::size_t m = 0; m < model.meshes.size(); ++m)
        for (std::size_t p = 0; p < model.meshes[m].primitives.size(); ++p) {
            const auto& prim = model.meshes[m].primitives[p];
            if (!prim.extensions.count("KHR_draco_mesh_compression")) continue;
            if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != -1) continue;  // shadowlab reads triangles only
            decodeDracoPrimitive(model, m, p, decodedAccessors, total);
        }
    return total;
}

UvTransform readTextureTransform(const tinygltf::TextureInfo& info, const std::string& at, int& texCoord) {
    UvTransform t;
    texCoord = info.texCoord;
    const auto it = info.extensions.find("KHR_texture_transform");
    if (it == info.extensions.end()) return t;
    const std::string extAt = at + ".extensions.KHR_texture_transform";
    const tinygltf::Value& ext = it->second;
    if (!ext.IsObject()) bad(extAt, "must be an object");
    auto number = [&](const tinygltf::Value& v, const std::string& where) {
        const double d = v.IsNumber() || v.IsInt() ? v.GetNumberAsDouble() : NAN;
        if (!std::isfinite(d)) bad(where, "must be a finite number");
        return d;
    };
    auto pair = [&](const char* key, double fallback, double out[2]) {
        out[0] = out[1] = fallback;
        if (!ext.Has(key)) return;
        const tinygltf::Value& v = ext.Get(key);
        if (!v.IsArray() || v.ArrayLen() != 2) bad(extAt + "." + key, "must be an array of 2 numbers");
        for (int i = 0; i < 2; ++i) out[i] = number(v.Get(i), extAt + "." + key + "[" + std::to_string(i) + "]");
    };
    double offset[2], scale[2];
    pair("offset", 0.0, offset);
    pair("scale", 1.0, scale);
    const double rotation = ext.Has("rotation") ? number(ext.Get("rotation"), extAt + ".rotation") : 0.0;
    if (ext.Has("texCoord")) {
        const double d = number(ext.Get("texCoord"), extAt + ".texCoord");
        if (!(d >= 0 && d <= 64 && d == std::floor(d))) bad(extAt + ".texCoord", "must be a whole number in 0..64");
        texCoord = int(d);
    }
    // The extension's matrix: translation(offset) · rotation · scale, with its rotation
    // [cos sin; -sin cos] turning the image clockwise for a positive angle.
    const double c = std::cos(rotation), s = std::sin(rotation);
    t.m[0] = c * scale[0];
    t.m[1] = s * scale[1];
    t.m[2] = offset[0];
    t.m[3] = -s * scale[0];
    t.m[4] = c * scale[1];
    t.m[5] = offset[1];
    t.identity = t.m[0] == 1 && t.m[1] == 0 && t.m[2] == 0 && t.m[3] == 0 && t.m[4] == 1 && t.m[5] == 0;
    return t;
}

}  // namespace shadowlab::scene

// scene/loader.cpp: the JSON scene reader. Every value is checked where it is read, and the
// first problem becomes one SceneError that names the file, the JSON path and what is wrong.
#include "scene/loader.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "scene/budgets.h"
#include "scene/error.h"
#include "scene/gltf_export.h"
#include "scene/input_file.h"
#include "scene/json_input.h"
#include "scene/memory.h"
#include "scene/mesh_loader.h"
#include "scene/model_view.h"
#include "scene/scene_checks.h"
#include "scene/settings.h"
#include "scene/texture.h"

namespace shadowlab::scene {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// Edit distance, to suggest the key a user probably meant ("radus" -> "radius").
std::size_t editDistance(const std::string& a, const std::string& b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        std::size_t diag = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t up = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] != b[j - 1] ? 1 : 0)});
            diag = up;
        }
    }
    return row[b.size()];
}

std::string describe(const Json& v) { return describeJson(v); }

const char* typeName(const Json& v) {
    switch (v.type()) {
        case Json::value_t::null: return "null";
        case Json::value_t::boolean: return "a boolean";
        case Json::value_t::string: return "a string";
        case Json::value_t::array: return "an array";
        case Json::value_t::object: return "an object";
        default: return "a number";
    }
}

// Reads typed values out of one scene file's JSON with full checking.
class Reader {
public:
    explicit Reader(fs::path file) : file_(std::move(file)) {}

    [[noreturn]] void fail(const JsonPath& path, const std::string& what) const { throw SceneError(file_, path, what); }

    void expectObject(const Json& node, const JsonPath& path) const {
        if (!node.is_object()) fail(path, std::string("expected an object, got ") + typeName(node));
    }

    // Rejects keys that are not in `allowed`, suggesting the nearest allowed one.
    void checkKeys(const Json& node, const JsonPath& path, std::initializer_list<const char*> allowed) const {
        expectObject(node, path);
        for (const auto& item : node.items()) {
            const std::string& key = item.key();  // (a named variable: lambdas may capture it)
            if (std::any_of(allowed.begin(), allowed.end(), [&](const char* a) { return key == a; })) continue;
            std::string best;
            std::size_t bestDistance = 3;  // suggest only close matches
            std::string list;
            for (const char* a : allowed) {
                list += (list.empty() ? "" : ", ") + std::string(a);
                // (a key much longer than any allowed one is no typo; its distance would cost
                // its length times theirs)
                if (key.size() > 64) continue;
                if (const std::size_t d = editDistance(key, a); d < bestDistance) {
                    bestDistance = d;
                    best = a;
                }
            }
            fail(path / key,
                 "unknown key" + (best.empty() ? "" : " (did you mean '" + best + "'?)") + "; allowed here: " + list);
        }
    }

    const Json& require(const Json& node, const JsonPath& path, const char* key) const {
        const auto it = node.find(key);
        if (it == node.end()) fail(path / key, "is required");
        return *it;
    }

    double number(const Json& v, const JsonPath& path) const {
        if (!v.is_number()) fail(path, std::string("expected a number, got ") + typeName(v));
        const double d = v.get<double>();
        if (!std::isfinite(d)) fail(path, "must be finite, got " + describe(v));
        return d;
    }
    double number(const Json& node, const JsonPath& path, const char* key, double fallback) const {
        const auto it = node.find(key);
        return it == node.end() ? fallback : number(*it, path / key);
    }
    double positive(const Json& v, const JsonPath& path) const {
        const double d = number(v, path);
        if (!(d > 0.0)) fail(path, "must be > 0, got " + describe(v));
        return d;
    }
    double unitInterval(const Json& v, const JsonPath& path) const {
        const double d = number(v, path);
        if (d < 0.0 || d > 1.0) fail(path, "must be in 0..1, got " + describe(v));
        return d;
    }

    int integer(const Json& v, const JsonPath& path, long long lo, long long hi) const {
        if (!v.is_number_integer() && !(v.is_number_float() && std::floor(v.get<double>()) == v.get<double>()))
            fail(path, std::string("expected an integer, got ") + (v.is_number() ? describe(v) : typeName(v)));
        const double d = v.get<double>();
        if (d < double(lo) || d > double(hi))
            fail(path, "must be in " + std::to_string(lo) + ".." + std::to_string(hi) + ", got " + describe(v));
        return int(d);
    }

    std::string string(const Json& v, const JsonPath& path) const {
        if (!v.is_string()) fail(path, std::string("expected a string, got ") + typeName(v));
        return v.get<std::string>();
    }

    bool boolean(const Json& v, const JsonPath& path) const {
        if (!v.is_boolean()) fail(path, std::string("expected true or false, got ") + typeName(v));
        return v.get<bool>();
    }

    template <int N>
    glm::vec<N, double> vector(const Json& v, const JsonPath& path) const {
        if (!v.is_array() || v.size() != N)
            fail(path, "expected an array of " + std::to_string(N) + " numbers, got " + describe(v));
        glm::vec<N, double> out;
        for (int i = 0; i < N; ++i) out[i] = number(v[i], path / std::size_t(i));
        return out;
    }
    Vec3 vec3(const Json& node, const JsonPath& path, const char* key, const Vec3& fallback) const {
        const auto it = node.find(key);
        return it == node.end() ? fallback : vector<3>(*it, path / key);
    }
    Vec3 direction(const Json& v, const JsonPath& path) const {
        const Vec3 d = vector<3>(v, path);
        const double len = glm::length(d);
        if (!(len > 0.0) || !std::isfinite(len)) fail(path, "must be a non-zero direction, got " + describe(v));
        return d / len;
    }
    Vec3 color(const Json& node, const JsonPath& path, const char* key, const Vec3& fallback) const {
        const Vec3 c = vec3(node, path, key, fallback);
        if (c.x < 0 || c.y < 0 || c.z < 0)
            fail(path / key, "color components must be >= 0, got " + describe(node[key]));
        return c;
    }

    const fs::path& file() const { return file_; }

private:
    fs::path file_;
};

// A material's alpha keys (docs/scene-format.md, "Alpha-tested and blended casters"): the glTF
// alphaMode, alphaCutoff, baseColorFactor alpha and baseColorTexture, by JSON names.
void readAlpha(const Reader& r, const Json& node, const JsonPath& path, Material& m, TextureCache& textures) {
    if (node.contains("alpha_mode")) {
        const std::string mode = r.string(node["alpha_mode"], path / "alpha_mode");
        if (mode == "opaque")
            m.alphaMode = AlphaMode::Opaque;
        else if (mode == "mask")
            m.alphaMode = AlphaMode::Mask;
        else if (mode == "blend")
            m.alphaMode = AlphaMode::Blend;
        else
            r.fail(path / "alpha_mode", "unknown alpha mode '" + excerpt(mode) + "' (expected opaque, mask or blend)");
    }
    if (node.contains("alpha_cutoff")) {
        if (m.alphaMode != AlphaMode::Mask) r.fail(path / "alpha_cutoff", "applies only with \"alpha_mode\": \"mask\"");
        m.alphaCutoff = r.unitInterval(node["alpha_cutoff"], path / "alpha_cutoff");
    }
    if (node.contains("alpha")) m.alphaFactor = r.unitInterval(node["alpha"], path / "alpha");
    for (const char* key : {"wrap_s", "wrap_t", "texcoord"})
        if (node.contains(key) && !node.contains("texture"))
            r.fail(path / key, "applies only to a material with a \"texture\"");
    if (!node.contains("texture")) return;
    const std::string file = r.string(node["texture"], path / "texture");
    if (file.empty()) r.fail(path / "texture", "must name an image file");
    TextureWrap wrap[2] = {TextureWrap::Repeat, TextureWrap::Repeat};
    for (int k = 0; k < 2; ++k) {
        const char* key = k == 0 ? "wrap_s" : "wrap_t";
        if (!node.contains(key)) continue;
        const std::string w = r.string(node[key], path / key);
        if (!textureWrapFromName(w, wrap[k]))
            r.fail(path / key,
                   "unknown wrap mode '" + excerpt(w) + "' (expected repeat, clamp_to_edge or mirrored_repeat)");
    }
    if (node.contains("texcoord")) m.texCoord = r.integer(node["texcoord"], path / "texcoord", 0, 64);
    const fs::path base = r.file().has_parent_path() ? r.file().parent_path() : fs::path(".");
    const fs::path resolved = fs::path(file).is_absolute() ? fs::path(file) : base / file;
    try {
        m.alphaTexture = loadAlphaTexture(resolved, wrap[0], wrap[1], &textures);
    } catch (const InputFileError& e) {
        r.fail(path / "texture", e.what());
    }
}

Camera readCamera(const Reader& r, const Json& node, const JsonPath& path) {
    r.checkKeys(node, path, {"position", "look_at", "up", "fov_y", "resolution", "near", "far"});
    Camera c;
    c.position = r.vector<3>(r.require(node, path, "position"), path / "position");
    c.lookAt = r.vector<3>(r.require(node, path, "look_at"), path / "look_at");
    if (glm::length(c.lookAt - c.position) == 0.0) r.fail(path / "look_at", "must differ from camera.position");
    if (node.contains("up")) c.up = r.direction(node["up"], path / "up");
    c.fovYDegrees = r.number(node, path, "fov_y", c.fovYDegrees);
    if (!(c.fovYDegrees > 0.0 && c.fovYDegrees < 180.0))
        r.fail(path / "fov_y", "must be in (0, 180) degrees, got " + describe(node["fov_y"]));
    if (node.contains("resolution")) {
        const Json& res = node["resolution"];
        if (!res.is_array() || res.size() != 2)
            r.fail(path / "resolution", "expected [width, height], got " + describe(res));
        c.width = r.integer(res[0], path / "resolution" / 0, 1, kMaxResolution);
        c.height = r.integer(res[1], path / "resolution" / 1, 1, kMaxResolution);
        if (static_cast<long long>(c.width) * c.height > kMaxPixels)
            r.fail(path / "resolution", "is absurd: " + std::to_string(c.width) + "x" + std::to_string(c.height) +
                                            " is more than " + std::to_string(kMaxPixels) + " pixels");
    }
    if (node.contains("near")) c.near = r.positive(node["near"], path / "near");
    if (node.contains("far")) {
        c.far = r.positive(node["far"], path / "far");
        // Without a near plane, a thousandth of the far one when that is nearer than the default:
        // a scene a few centimetres across is not clipped away.
        if (!node.contains("near")) c.near = std::min(c.near, kNearPerFar * c.far);
    } else {
        c.far = std::max(c.far, 2.0 * c.near);  // a placeholder: fitted to the scene's bounds once it is read
    }
    if (!(c.far > c.near)) r.fail(path / "far", "must be greater than near");
    return c;
}

Light readLight(const Reader& r, const Json& node, const JsonPath& path) {
    r.checkKeys(
        node, path,
        {"type", "direction", "position", "color", "intensity", "radius", "cone_angle", "inner_cone_angle", "name"});
    Light l;
    const std::string type = r.string(r.require(node, path, "type"), path / "type");
    if (type == "directional") {
        l.type = LightType::Directional;
        l.direction = r.direction(r.require(node, path, "direction"), path / "direction");
        for (const char* key : {"position", "radius", "cone_angle", "inner_cone_angle"})
            if (node.contains(key)) r.fail(path / key, "does not apply to a directional light");
    } else if (type == "point" || type == "spot") {
        l.type = type == "point" ? LightType::Point : LightType::Spot;
        l.position = r.vector<3>(r.require(node, path, "position"), path / "position");
        if (node.contains("radius")) {
            l.radius = r.number(node["radius"], path / "radius");
            if (l.radius < 0.0) r.fail(path / "radius", "must be >= 0, got " + describe(node["radius"]));
        }
        if (l.type == LightType::Spot) {
            l.direction = r.direction(r.require(node, path, "direction"), path / "direction");
            l.coneAngleDegrees = r.number(r.require(node, path, "cone_angle"), path / "cone_angle");
            if (!(l.coneAngleDegrees > 0.0 && l.coneAngleDegrees < 90.0))
                r.fail(path / "cone_angle",
                       "must be in (0, 90) degrees (half-angle), got " + describe(node["cone_angle"]));
            if (node.contains("inner_cone_angle")) {
                l.innerConeAngleDegrees = r.number(node["inner_cone_angle"], path / "inner_cone_angle");
                if (!(l.innerConeAngleDegrees >= 0.0 && l.innerConeAngleDegrees <= l.coneAngleDegrees))
                    r.fail(path / "inner_cone_angle", "must be in [0, cone_angle] = [0, " +
                                                          describe(node["cone_angle"]) + "] degrees, got " +
                                                          describe(node["inner_cone_angle"]));
            }
        } else {
            for (const char* key : {"direction", "cone_angle", "inner_cone_angle"})
                if (node.contains(key)) r.fail(path / key, "does not apply to a point light");
        }
    } else {
        r.fail(path / "type", "unknown light type '" + type + "' (expected directional, point or spot)");
    }
    l.color = r.color(node, path, "color", l.color);
    if (node.contains("intensity")) {
        l.intensity = r.number(node["intensity"], path / "intensity");
        if (l.intensity < 0.0) r.fail(path / "intensity", "must be >= 0, got " + describe(node["intensity"]));
    }
    if (const ValueProblem problem = lightProblem(l)) r.fail(path / problem.key, problem.what);
    return l;
}

// A mesh object's glTF cameras, before the scene's bounds (which their near/far default to) are known.
struct PendingCameras {
    std::vector<GltfCamera> cameras;
    glm::dmat4 transform{1.0};
    std::string source;
    std::optional<std::string> pick;  // the object's "camera" key, as text
    JsonPath pickPath;
};

Object readObject(const Reader& r, const Json& node, const JsonPath& path, const std::map<std::string, int>& materials,
                  const std::vector<Material>& sceneMaterials, MeshCache& meshCache,
                  PendingCameras* pending = nullptr) {
    r.expectObject(node, path);
    Object o;
    const std::string type = r.string(r.require(node, path, "type"), path / "type");
    auto lookupMaterial = [&] {
        const std::string material = r.string(r.require(node, path, "material"), path / "material");
        const auto it = materials.find(material);
        if (it == materials.end()) {
            std::string known;
            for (const auto& [name, index] : materials) known += (known.empty() ? "" : ", ") + name;
            r.fail(path / "material",
                   "no material named '" + material + "' (defined: " + (known.empty() ? "none" : known) + ")");
        }
        return it->second;
    };
    if (type == "sphere") {
        r.checkKeys(node, path, {"type", "name", "material", "center", "radius"});
        Sphere s;
        s.center = r.vector<3>(r.require(node, path, "center"), path / "center");
        s.radius = r.positive(r.require(node, path, "radius"), path / "radius");
        o.shape = s;
    } else if (type == "quad") {
        r.checkKeys(node, path, {"type", "name", "material", "center", "normal", "size", "uv_min", "uv_max"});
        Quad q;
        if (node.contains("uv_min")) q.uvMin = r.vector<2>(node["uv_min"], path / "uv_min");
        if (node.contains("uv_max")) q.uvMax = r.vector<2>(node["uv_max"], path / "uv_max");
        q.center = r.vector<3>(r.require(node, path, "center"), path / "center");
        q.normal = r.direction(r.require(node, path, "normal"), path / "normal");
        const Json& size = r.require(node, path, "size");
        q.size = r.vector<2>(size, path / "size");
        for (int i = 0; i < 2; ++i)
            if (!(q.size[i] > 0.0)) r.fail(path / "size" / std::size_t(i), "must be > 0, got " + describe(size[i]));
        quadAxes(q.normal, q.uAxis, q.vAxis);
        o.shape = q;
    } else if (type == "box") {
        r.checkKeys(node, path, {"type", "name", "material", "min", "max"});
        Box b;
        b.min = r.vector<3>(r.require(node, path, "min"), path / "min");
        b.max = r.vector<3>(r.require(node, path, "max"), path / "max");
        for (int i = 0; i < 3; ++i)
            if (!(b.max[i] > b.min[i]))
                r.fail(path / "max", "must be greater than min on every axis (axis " + std::to_string(i) + ")");
        o.shape = b;
    } else if (type == "mesh") {
        r.checkKeys(node, path, {"type", "name", "material", "file", "translate", "rotate", "scale", "camera"});
        const std::string file = r.string(r.require(node, path, "file"), path / "file");
        if (file.empty()) r.fail(path / "file", "must name a mesh file");
        const Vec3 translate = r.vec3(node, path, "translate", Vec3(0.0));
        const Vec3 rotate = r.vec3(node, path, "rotate", Vec3(0.0));
        Vec3 scale(1.0);
        if (node.contains("scale")) {
            const Json& s = node["scale"];
            scale = s.is_array() ? r.vector<3>(s, path / "scale") : Vec3(r.number(s, path / "scale"));
            if (!(scale.x > 0 && scale.y > 0 && scale.z > 0)) r.fail(path / "scale", "must be > 0, got " + describe(s));
        }
        Mesh m;
        const fs::path base = r.file().has_parent_path() ? r.file().parent_path() : fs::path(".");
        m.file = fs::path(file).is_absolute() ? fs::path(file) : base / file;
        GltfExtras extras;
        // A textured material decides whether the file is read with texture coordinates.
        const Material& mat = sceneMaterials[std::size_t(lookupMaterial())];
        MeshRequest request;
        if (mat.alphaTextured()) request.uvSet = mat.texCoord;
        m.instances = loadMeshInstances(m.file, objectTransform(translate, rotate, scale), r.file(), path / "file",
                                        pending ? &extras : nullptr, &meshCache, request);
        if (pending) {
            pending->cameras = extras.cameras;
            pending->transform = objectTransform(translate, rotate, scale);
            pending->source = path.str() + " (" + fs::path(file).filename().string() + ")";
            if (node.contains("camera")) {
                const Json& c = node["camera"];
                pending->pickPath = path / "camera";
                if (c.is_string())
                    pending->pick = c.get<std::string>();
                else
                    pending->pick = std::to_string(r.integer(c, path / "camera", 0, 1 << 20));
            }
        }
        o.shape = m;
    } else {
        r.fail(path / "type", "unknown object type '" + type + "' (expected sphere, quad, box or mesh)");
    }
    o.name = node.contains("name") ? r.string(node["name"], path / "name") : path.str();
    o.material = lookupMaterial();
    if ((std::holds_alternative<Sphere>(o.shape) || std::holds_alternative<Box>(o.shape)) &&
        sceneMaterials[std::size_t(o.material)].alphaTextured())
        r.fail(path / "material", "material '" + sceneMaterials[std::size_t(o.material)].name +
                                      "' reads an alpha texture, which needs texture coordinates: only quads "
                                      "and meshes have them (use a quad or a mesh, or alpha_mode opaque)");
    return o;
}

// A range bound for a message (shortest form: 0.99, 42, 1e-06).
std::string numberText(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

ShadowDefaults readShadow(const Reader& r, const Json& node, const JsonPath& path) {
    r.checkKeys(node, path,
                {"shadow_map_size",
                 "depth_bias",
                 "slope_bias",
                 "filter",
                 "pcf_size",
                 "normal_offset",
                 "receiver_plane_bias",
                 "hardware_bias",
                 "fit_light_frustum",
                 "cascades",
                 "cascade_blend",
                 "ray_bias",
                 "precision",
                 "samples",
                 "min_variance",
                 "light_bleeding_reduction",
                 "evsm_positive_exponent",
                 "evsm_negative_exponent",
                 "esm_exponent",
                 "moment_bias",
                 "blur_width"});
    ShadowDefaults d;
    if (node.contains("shadow_map_size"))
        d.shadowMapSize = r.integer(node["shadow_map_size"], path / "shadow_map_size", 16, 16384);
    if (node.contains("depth_bias")) {
        d.depthBias = r.number(node["depth_bias"], path / "depth_bias");
        if (*d.depthBias < 0) r.fail(path / "depth_bias", "must be >= 0 (world units)");
    }
    if (node.contains("slope_bias")) {
        d.slopeBias = r.number(node["slope_bias"], path / "slope_bias");
        if (*d.slopeBias < 0) r.fail(path / "slope_bias", "must be >= 0 (texels)");
    }
    if (node.contains("filter")) {
        d.filter = r.string(node["filter"], path / "filter");
        if (*d.filter != "none" && *d.filter != "pcf2x2" && *d.filter != "pcf" && *d.filter != "poisson" &&
            *d.filter != "pcss" && *d.filter != "vsm" && *d.filter != "evsm2" && *d.filter != "evsm4" &&
            *d.filter != "esm" && *d.filter != "msm")
            r.fail(path / "filter",
                   "expected none, pcf2x2, pcf, poisson, pcss, vsm, evsm2, evsm4, esm or msm, got '" + *d.filter + "'");
    }
    if (node.contains("pcf_size")) d.pcfSize = r.integer(node["pcf_size"], path / "pcf_size", 1, 15);
    // The filterable maps' parameters (scene::MomentSettings, with its ranges).
    auto ranged = [&](std::optional<double>& into, const char* key, double lo, double hi, const char* unit) {
        if (!node.contains(key)) return;
        into = r.number(node[key], path / key);
        if (!(*into >= lo && *into <= hi))
            r.fail(path / key, "must be in " + numberText(lo) + ".." + numberText(hi) + " (" + unit + ")");
    };
    ranged(d.minVariance, "min_variance", 0.0, 1.0, "normalized depth squared");
    ranged(d.bleedReduction, "light_bleeding_reduction", 0.0, 0.99, "fraction of the visibility range cut");
    ranged(d.evsmPositive, "evsm_positive_exponent", 0.0, kMaxEvsmExponent, "float32 holds exp(2c) up to c = 42");
    ranged(d.evsmNegative, "evsm_negative_exponent", 0.0, kMaxEvsmExponent, "float32 holds exp(2c) up to c = 42");
    ranged(d.esmExponent, "esm_exponent", 0.0, kMaxEsmExponent, "float32 holds exp(c) up to c = 85");
    ranged(d.momentBias, "moment_bias", 0.0, 1.0, "fraction");
    if (node.contains("blur_width")) {
        d.blurWidth = r.integer(node["blur_width"], path / "blur_width", 1, kMaxBlurWidth);
        if (*d.blurWidth % 2 == 0)
            r.fail(path / "blur_width", "must be odd (texels), got " + std::to_string(*d.blurWidth));
    }
    if (node.contains("normal_offset")) {
        d.normalOffset = r.number(node["normal_offset"], path / "normal_offset");
        if (*d.normalOffset < 0) r.fail(path / "normal_offset", "must be >= 0 (texels)");
    }
    if (node.contains("receiver_plane_bias"))
        d.receiverPlaneBias = r.boolean(node["receiver_plane_bias"], path / "receiver_plane_bias");
    if (node.contains("hardware_bias")) d.hardwareBias = r.boolean(node["hardware_bias"], path / "hardware_bias");
    if (node.contains("fit_light_frustum"))
        d.fitLightFrustum = r.boolean(node["fit_light_frustum"], path / "fit_light_frustum");
    if (node.contains("cascades")) d.cascades = r.integer(node["cascades"], path / "cascades", 1, kMaxCascades);
    if (node.contains("cascade_blend")) {
        d.cascadeBlend = r.number(node["cascade_blend"], path / "cascade_blend");
        if (!(*d.cascadeBlend >= 0 && *d.cascadeBlend <= kMaxCascadeBlend))
            r.fail(path / "cascade_blend", "must be in 0..0.5 (a fraction of each cascade's slice)");
    }
    if (node.contains("ray_bias")) {
        const Json& v = node["ray_bias"];
        if (v.is_string()) {
            if (v.get<std::string>() != "robust") r.fail(path / "ray_bias", "expected a number or \"robust\"");
            d.robustRayOffset = true;
        } else {
            d.rayBias = r.number(v, path / "ray_bias");
            if (*d.rayBias < 0) r.fail(path / "ray_bias", "must be >= 0 (world units)");
        }
    }
    if (node.contains("precision")) {
        d.precision = r.string(node["precision"], path / "precision");
        if (*d.precision != "float" && *d.precision != "double")
            r.fail(path / "precision", "expected float or double, got '" + *d.precision + "'");
    }
    if (node.contains("samples")) d.samples = r.integer(node["samples"], path / "samples", 1, 65536);
    return d;
}

// The JSON scene's glTF cameras in world space (origin.cameras), and the one a mesh object's
// "camera" key names as the view.
void addFileCameras(const Reader& r, Scene& scene, const std::vector<PendingCameras>& pending, bool nearFarGiven) {
    const Bounds bounds = scene.bounds();
    for (const PendingCameras& p : pending) {
        std::vector<FileCamera> own;
        for (const GltfCamera& c : p.cameras) {
            const glm::dmat3 linear(p.transform);
            const Vec3 position(p.transform * glm::dvec4(c.position, 1.0));
            own.push_back({c.name.empty() ? c.nodeName : c.name, p.source,
                           cameraFromGltf(position, glm::normalize(linear * c.forward), glm::normalize(linear * c.up),
                                          c.yfovRadians, c.znear, c.zfar, 0.0, bounds, scene.camera)});
        }
        if (p.pick) {
            std::string why;
            const int i = findFileCamera(own, *p.pick, why);
            if (i < 0) r.fail(p.pickPath, why);
            const Camera keep = scene.camera;
            scene.camera = own[std::size_t(i)].camera;
            if (nearFarGiven) {
                scene.camera.near = keep.near;
                scene.camera.far = keep.far;
            }
            scene.origin.choices.emplace_back("view", "file camera " +
                                                          std::to_string(scene.origin.cameras.size() + std::size_t(i)) +
                                                          " (" + p.pickPath.str() + ")");
        }
        scene.origin.cameras.insert(scene.origin.cameras.end(), own.begin(), own.end());
    }
}

}  // namespace

namespace {

// The "path" block: the kinds and limits of `shadowlab path` (compare/path.h), checked here so a
// bad value names the file and its JSON path.
PathBlock readPath(const Reader& r, const Json& node, const JsonPath& path, const Scene& scene) {
    r.checkKeys(node, path, {"kind", "frames", "amount", "light", "animation"});
    PathBlock b;
    b.kind = r.string(r.require(node, path, "kind"), path / "kind");
    static const char* kKinds[] = {"orbit",       "dolly",         "pan",        "subtexel",
                                   "sun-azimuth", "sun-elevation", "light-move", "gltf-animation"};
    if (std::none_of(std::begin(kKinds), std::end(kKinds), [&](const char* k) { return b.kind == k; }))
        r.fail(path / "kind",
               "expected orbit, dolly, pan, subtexel, sun-azimuth, sun-elevation, light-move or "
               "gltf-animation, got " +
                   describe(node["kind"]));
    if (node.contains("frames")) b.frames = r.integer(node["frames"], path / "frames", 2, 10000);
    if (node.contains("amount")) {
        if (b.kind == "gltf-animation")
            r.fail(path / "amount", "a glTF animation has no amount (its keys set the motion)");
        b.amount = r.number(node["amount"], path / "amount");
        if (b.kind == "dolly" && !(*b.amount < 1.0))
            r.fail(path / "amount", "a dolly covers a fraction < 1 of the distance, got " + describe(node["amount"]));
    }
    const bool lightPath = b.kind == "sun-azimuth" || b.kind == "sun-elevation" || b.kind == "light-move";
    if (node.contains("light")) {
        if (!lightPath)
            r.fail(path / "light", "only a light path (sun-azimuth, sun-elevation, light-move) moves a light");
        b.light = r.integer(node["light"], path / "light", 0, (long long)(scene.lights.size()) - 1);
    }
    if (lightPath) {
        const Light& l = scene.lights[std::size_t(b.light.value_or(0))];
        const JsonPath at = node.contains("light") ? path / "light" : path / "kind";
        if (b.kind != "light-move" && l.type != LightType::Directional)
            r.fail(at,
                   b.kind + " turns a directional light; light " + std::to_string(b.light.value_or(0)) + " is not one");
        if (b.kind == "light-move" && l.type == LightType::Directional)
            r.fail(at, "light-move moves a spot or point light; light " + std::to_string(b.light.value_or(0)) +
                           " is directional (use sun-azimuth or sun-elevation)");
    }
    if (node.contains("animation")) {
        if (b.kind != "gltf-animation") r.fail(path / "animation", "only a gltf-animation path names an animation");
        const Json& a = node["animation"];
        if (a.is_string())
            b.animation = a.get<std::string>();
        else
            b.animation = std::to_string(r.integer(a, path / "animation", 0, 1000000));
    }
    if (b.kind == "gltf-animation")
        r.fail(path / "kind",
               "camera animations are read from a .gltf/.glb given as the scene "
               "(`shadowlab path MODEL.gltf --camera-animation`); a JSON scene has none");
    return b;
}

}  // namespace

ShadowDefaults readShadowBlock(const fs::path& file, const Json& node, const JsonPath& path) {
    return readShadow(Reader(file), node, path);
}

namespace {

// "line L, column C" for a byte offset, so a syntax error points at the place in an editor.
std::string lineColumn(const std::string& text, std::size_t byte) {
    std::size_t line = 1, column = 1;
    for (std::size_t i = 0; i < byte && i < text.size(); ++i) {
        if (text[i] == '\n') {
            ++line;
            column = 1;
        } else {
            ++column;
        }
    }
    return "line " + std::to_string(line) + ", column " + std::to_string(column);
}

Scene parseScene(const fs::path& file, const std::string& text) {
    const Reader r(file);
    const JsonPath root;
    Json doc;
    checkJsonNesting(file, text);
    // The parsed tree takes several times the text: refused before it is built when it cannot fit.
    const std::uint64_t treeBytes = std::uint64_t(text.size()) + jsonTreeBytes(text);
    if (const std::uint64_t available = availableMemoryBytes(); available != 0 && treeBytes > available)
        throw SceneError(file, root,
                         "parsing it needs about " + std::to_string(treeBytes / kMiB) + " MiB, more than the " +
                             std::to_string(available / kMiB) + " MiB available");
    try {
        doc = Json::parse(text);
    } catch (const Json::parse_error& e) {
        std::string what = e.what();
        // nlohmann's message starts "[json.exception.parse_error.101] parse error at line..."
        if (const auto pos = what.find("] "); pos != std::string::npos) what = what.substr(pos + 2);
        throw SceneError(file, root,
                         "invalid JSON near " + lineColumn(text, e.byte == 0 ? 0 : e.byte - 1) + ": " + what);
    } catch (const Json::exception& e) {
        // Number overflow (1e999) and the like: nlohmann reports no position for these.
        std::string what = e.what();
        if (const auto pos = what.find("] "); pos != std::string::npos) what = what.substr(pos + 2);
        throw SceneError(file, root, "invalid JSON: " + what + " (numbers must be finite)");
    }
    r.checkKeys(doc, root,
                {"camera", "background", "ambient", "materials", "lights", "objects", "shadow", "budgets",
                 "description", "ground", "$schema", "path"});

    Scene scene;
    scene.file = file;
    // A mesh object's "camera" key takes the view from its glTF file: the "camera" block may then
    // hold only the image size and near/far (docs/scene-format.md).
    bool viewFromModel = false;
    if (const auto it = doc.find("objects"); it != doc.end() && it->is_array())
        for (const Json& o : *it)
            viewFromModel =
                viewFromModel || (o.is_object() && o.contains("camera") && o.value("type", Json()) == "mesh");
    bool nearFarGiven = false;
    if (viewFromModel) {
        if (doc.contains("camera")) {
            const Json& node = doc["camera"];
            for (const char* key : {"position", "look_at", "up", "fov_y"})
                if (node.is_object() && node.contains(key))
                    r.fail(root / "camera" / key,
                           "a mesh object's \"camera\" key sets the view; give only "
                           "resolution, near and far here");
            r.checkKeys(node, root / "camera", {"resolution", "near", "far"});
            Json full = node;
            full["position"] = Json::array({0, 0, 1});
            full["look_at"] = Json::array({0, 0, 0});
            scene.camera = readCamera(r, full, root / "camera");
            nearFarGiven = node.contains("near") || node.contains("far");
        }
    } else {
        const Json& camera = r.require(doc, root, "camera");
        scene.camera = readCamera(r, camera, root / "camera");
        scene.origin.farFromBounds = camera.is_object() && !camera.contains("far");
        scene.origin.nearFromBounds = scene.origin.farFromBounds && !camera.contains("near");
    }
    if (doc.contains("ground")) scene.origin.ground = r.boolean(doc["ground"], root / "ground");
    if (doc.contains("$schema")) r.string(doc["$schema"], root / "$schema");
    scene.background = r.color(doc, root, "background", scene.background);
    if (doc.contains("ambient")) scene.ambient = r.unitInterval(doc["ambient"], root / "ambient");
    if (doc.contains("description")) r.string(doc["description"], root / "description");

    std::map<std::string, int> materialIndex;
    TextureCache textures;  // materials naming the same texture file share it
    const Json& materials = r.require(doc, root, "materials");
    r.expectObject(materials, root / "materials");
    if (materials.empty()) r.fail(root / "materials", "must define at least one material");
    for (const auto& [name, node] : materials.items()) {
        const JsonPath path = root / "materials" / name;
        r.checkKeys(
            node, path,
            {"albedo", "opacity", "alpha_mode", "alpha_cutoff", "alpha", "texture", "wrap_s", "wrap_t", "texcoord"});
        Material m;
        m.name = name;
        m.albedo = r.color(node, path, "albedo", m.albedo);
        if (m.albedo.x > 1 || m.albedo.y > 1 || m.albedo.z > 1)
            r.fail(path / "albedo", "albedo components must be in 0..1 (energy conserving)");
        if (node.contains("opacity")) m.opacity = r.unitInterval(node["opacity"], path / "opacity");
        readAlpha(r, node, path, m, textures);
        materialIndex[name] = int(scene.materials.size());
        scene.materials.push_back(m);
    }

    const Json& lights = r.require(doc, root, "lights");
    if (!lights.is_array()) r.fail(root / "lights", std::string("expected an array, got ") + typeName(lights));
    if (lights.empty()) r.fail(root / "lights", "must hold at least one light (a shadow needs a light)");
    for (std::size_t i = 0; i < lights.size(); ++i) {
        scene.lights.push_back(readLight(r, lights[i], root / "lights" / i));
        // "direction" is the way the light travels; giving the way to the sun instead is the usual
        // slip, and it puts the sun below the horizon: upward faces unlit, no shadow on a ground.
        const Light& l = scene.lights.back();
        if (l.type == LightType::Directional && glm::dot(l.direction, glm::normalize(scene.camera.up)) > 0.0)
            scene.origin.notes.push_back(
                file.string() + ": " + (root / "lights" / i / "direction").str() + " " +
                describe(lights[i]["direction"]) +
                " points up (against the camera's up): \"direction\" is the way the light travels, so this sun "
                "is below the horizon and faces turned up get no light and show no shadow; a sun above "
                "would be the opposite vector");
    }

    const Json& objects = r.require(doc, root, "objects");
    if (!objects.is_array()) r.fail(root / "objects", std::string("expected an array, got ") + typeName(objects));
    if (objects.empty()) r.fail(root / "objects", "must hold at least one object");
    if (objects.size() > 1000000) r.fail(root / "objects", "has more than 1,000,000 objects");
    MeshCache meshCache;  // objects naming the same file share its geometry
    std::vector<PendingCameras> pending;
    bool picked = false;
    for (std::size_t i = 0; i < objects.size(); ++i) {
        PendingCameras p;
        scene.objects.push_back(
            readObject(r, objects[i], root / "objects" / i, materialIndex, scene.materials, meshCache, &p));
        if (p.pick && picked) r.fail(p.pickPath, "only one mesh object may name the scene's camera");
        picked = picked || p.pick.has_value();
        if (!p.cameras.empty() || p.pick) pending.push_back(std::move(p));
    }
    addFileCameras(r, scene, pending, nearFarGiven);
    fitNearFarToBounds(scene);

    if (doc.contains("shadow")) scene.shadow = readShadow(r, doc["shadow"], root / "shadow");
    if (doc.contains("budgets")) scene.budgets = readBudgets(file, doc["budgets"], root / "budgets");
    if (doc.contains("path")) scene.path = readPath(r, doc["path"], root / "path", scene);
    checkSceneExtent(scene, true);
    scene.loadBytes = treeBytes + meshCache.peakLoadBytes;
    return scene;
}

// A model file as the whole scene (DESIGN.md): its geometry as one mesh object per glTF material,
// its first perspective camera and its KHR_lights_punctual lights; a framed camera and a default
// sun where it has none, as an OBJ or PLY file never has (docs/decisions.md).
Scene loadModelScene(const fs::path& file) {
    constexpr double kPi = 3.14159265358979323846;
    GltfExtras extras;
    Scene scene;
    scene.file = file;
    // One object per glTF material (docs/decisions.md, "A glTF model per material"): each keeps
    // its alpha mode, cutoff and texture; a single-material file stays one object named by its stem.
    MeshRequest request;
    request.perMaterial = true;
    const std::vector<MeshInstance> instances =
        loadMeshInstances(file, glm::dmat4(1.0), file, JsonPath(), &extras, nullptr, request);
    std::vector<int> order;  // glTF material indices in order of first use
    for (const MeshInstance& inst : instances)
        if (std::find(order.begin(), order.end(), inst.fileMaterial) == order.end()) order.push_back(inst.fileMaterial);
    for (const int fileMaterial : order) {
        Material m;
        if (fileMaterial >= 0 && std::size_t(fileMaterial) < extras.materials.size())
            m = extras.materials[std::size_t(fileMaterial)];
        else
            m.name = "model";
        m.albedo = {0.8, 0.8, 0.8};  // shadows are the point: every part the same grey
        m.opacity = 1.0;
        Mesh mesh;
        mesh.file = file;
        for (const MeshInstance& inst : instances)
            if (inst.fileMaterial == fileMaterial) mesh.instances.push_back(inst);
        const std::string name = order.size() == 1 ? file.stem().string() : file.stem().string() + "/" + m.name;
        scene.materials.push_back(std::move(m));
        scene.objects.push_back({name, std::move(mesh), int(scene.materials.size()) - 1});
    }
    checkSceneExtent(scene, false);  // before the framing is computed from the bounds
    const Bounds b = scene.bounds();
    scene.origin.modelScene = true;
    scene.origin.modelBounds = b;
    for (const GltfCamera& c : extras.cameras) {
        Camera camera =
            cameraFromGltf(c.position, c.forward, c.up, c.yfovRadians, c.znear, c.zfar, c.aspect, b, scene.camera);
        if (c.width > 0 && c.height > 0 && static_cast<long long>(c.width) * c.height <= kMaxPixels) {
            camera.width = c.width;  // a shadowlab export's image size (scene/gltf_export.h)
            camera.height = c.height;
        }
        scene.origin.cameras.push_back({c.name.empty() ? c.nodeName : c.name, file.filename().string(), camera});
    }
    // A shadowlab export is a whole scene (docs/export.md): its ground, if any, is one of its
    // objects, so none is added.
    if (extras.shadowlabExport) {
        scene.origin.ground = false;
        scene.origin.choices.emplace_back(
            "export", "a shadowlab export (" + file.filename().string() + "): its image size kept, no ground added");
    }
    scene.origin.cameraAnimations = extras.cameraAnimations;
    if (!scene.origin.cameras.empty()) {
        scene.camera = scene.origin.cameras.front().camera;
        scene.origin.choices.emplace_back("view", "file camera 0 of " + std::to_string(scene.origin.cameras.size()) +
                                                      " (the first; --camera picks another)");
    } else {
        // Framed from above and in front: a placeholder the view search replaces (scene/model_view.h).
        scene.camera = framedCamera(b, Vec3(0.55, 0.45, 1.0), 40.0, scene.camera);
        scene.origin.chooseView = true;
        scene.origin.choices.emplace_back("view", "framed from above and in front (the file has no camera)");
    }
    for (const GltfLight& l : extras.lights) {
        const JsonPath lightPath = JsonPath() / "extensions" / "KHR_lights_punctual" / "lights" / std::size_t(l.index);
        if (!(l.intensity >= 0))  // in the file's units, before the conversion below
            throw SceneError(file, lightPath / "intensity",
                             "must be finite and >= 0, got " + describeJson(l.intensity));
        Light light;
        light.color = l.color;
        if (l.type == "directional") {
            light.type = LightType::Directional;
            light.direction = l.direction;
            light.intensity = l.intensity;
        } else {
            light.type = l.type == "spot" ? LightType::Spot : LightType::Point;
            light.position = l.position;
            light.direction = l.direction;
            // glTF point intensity is in candela (irradiance I/d²); ours is I/(4π d²).
            light.intensity = 4.0 * kPi * l.intensity;
            if (extras.shadowlabExport && l.radius > 0 && std::isfinite(l.radius)) light.radius = l.radius;
            if (light.type == LightType::Spot) {
                light.coneAngleDegrees = std::clamp(l.outerConeRadians * 180.0 / kPi, 0.1, 89.9);
                // glTF's default inner angle is 0: the falloff starts on the axis.
                light.innerConeAngleDegrees = std::clamp(l.innerConeRadians * 180.0 / kPi, 0.0, light.coneAngleDegrees);
                // A shadowlab export's hard cone (its inner angle written just inside the outer).
                if (extras.shadowlabExport &&
                    l.innerConeRadians >= l.outerConeRadians * kExportHardConeInnerRatio * (1.0 - 1e-12))
                    light.innerConeAngleDegrees = Light{}.innerConeAngleDegrees;
            }
        }
        // The checks a JSON light gets, at the glTF light's path (its position and direction
        // come from its node).
        if (const ValueProblem problem = lightProblem(light))
            throw SceneError(
                file, lightPath / (problem.key == "cone_angle" ? std::string("spot.outerConeAngle") : problem.key),
                problem.what + (problem.key == "position" || problem.key == "direction"
                                    ? " (from the transform of the node that holds the light)"
                                    : ""));
        scene.lights.push_back(light);
    }
    if (scene.lights.empty()) {
        Light sun;  // from above, left and in front of the default framing; a view search may turn it
        sun.direction = glm::normalize(Vec3(-0.4, -1.0, -0.6));
        sun.intensity = 1.4;
        scene.lights.push_back(sun);
        scene.origin.chooseSun = true;
        scene.origin.choices.emplace_back("sun", "a default sun (the file has no light)");
    } else {
        // Named by kind: "sun" would call a spot one. ("1 spot and 2 point lights from the file")
        int count[3] = {0, 0, 0};
        for (const Light& l : scene.lights) ++count[int(l.type)];
        const char* kinds[3] = {"directional", "point", "spot"};
        std::vector<std::string> parts;
        for (int k : {0, 2, 1})
            if (count[k] > 0) parts.push_back(std::to_string(count[k]) + " " + kinds[k]);
        std::string text;
        for (std::size_t i = 0; i < parts.size(); ++i)
            text += (i == 0 ? "" : i + 1 == parts.size() ? " and " : ", ") + parts[i];
        scene.origin.choices.emplace_back("lights",
                                          text + (scene.lights.size() == 1 ? " light" : " lights") + " from the file");
    }
    checkSceneExtent(scene, false);
    scene.loadBytes = extras.loadBytes;
    scene.origin.notes = extras.notes;
    return scene;
}

// Mesh files that can be the whole scene: glTF with its cameras and lights where it has them;
// OBJ and PLY, which have neither, with a searched view and sun over a ground like a bare glTF.
bool isModelFormat(const std::string& ext) { return ext == ".gltf" || ext == ".glb" || ext == ".obj" || ext == ".ply"; }

// Model formats people try first that shadowlab does not read: named as such rather than
// parsed as JSON (which would report a syntax error at byte 1).
bool isOtherModelFormat(const std::string& ext) {
    for (const char* e :
         {".stl", ".fbx", ".dae", ".3ds", ".blend", ".usd", ".usda", ".usdc", ".usdz", ".off", ".x3d", ".wrl", ".abc"})
        if (ext == e) return true;
    return false;
}

}  // namespace

Scene loadScene(const fs::path& file) {
    const std::string ext = lowercaseExtension(file);
    // Told by its name before any byte is read: a .ply read as JSON would be a parse error.
    if (isOtherModelFormat(ext))
        throw SceneError(file, {},
                         "unsupported format '" + excerpt(ext) +
                             "': a scene is a .json file or a .gltf, .glb, "
                             ".obj or .ply model (convert the model, e.g. to .obj or .glb)");
    std::string text;
    try {
        if (isModelFormat(ext))
            checkInputFile(file, kMaxMeshFileBytes);
        else
            text = readInputFile(file, kMaxJsonFileBytes);
    } catch (const InputFileError& e) {
        throw SceneError(file, {}, e.problem());
    }
    if (isModelFormat(ext)) return loadModelScene(file);
    return parseScene(file, text);
}

fs::path scenesDirectory() {
    if (const char* env = std::getenv("SHADOWLAB_SCENES")) return env;
    return SHADOWLAB_SCENES_DIR;
}

fs::path findScene(const std::string& nameOrPath) {
    std::error_code ec;
    const fs::path asGiven(nameOrPath);
    if (fs::is_regular_file(asGiven, ec)) return asGiven;
    const fs::path dir = scenesDirectory();
    for (const fs::path& candidate : {dir / nameOrPath, dir / (nameOrPath + ".json")})
        if (fs::is_regular_file(candidate, ec)) return candidate;
    // Something is there but is no file (a folder, a FIFO, a device, a symbolic-link loop): say
    // what, rather than that there is no such file.
    if (fs::exists(fs::symlink_status(asGiven, ec))) checkInputFile(asGiven, kMaxMeshFileBytes);
    std::set<std::string> names;
    for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator();
         it.increment(ec))
        if (it->path().extension() == ".json" &&
            !it->path().stem().string().ends_with(".schema"))  // not scene.schema.json
            names.insert(fs::relative(it->path(), dir, ec).replace_extension().string());
    std::string list;
    for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
    throw InputError(nameOrPath + ": no such scene file, and no shipped scene of that name (shipped: " +
                     (list.empty() ? "none found in " + dir.string() : list) + ")");
}

}  // namespace shadowlab::scene

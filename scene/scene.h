// scene/scene.h: the validated scene every backend renders; loaded in double precision.
// Nothing here knows about Vulkan or ray tracing: backends read this and write a Frame.
#pragma once

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <glm/glm.hpp>

#include "scene/budgets.h"

namespace shadowlab::scene {

using Vec2 = glm::dvec2;
using Vec3 = glm::dvec3;

// Pinhole camera, vertical field of view; pixel (x, y) is sampled at its center and row 0 is
// the top of the image (see camera.h for the shared ray/projection math).
// A JSON camera's near plane when it names none: kDefaultNear, or kNearPerFar of the far plane
// when that is nearer (scene/loader.cpp, fitNearFarToBounds).
inline constexpr double kDefaultNear = 0.1;
inline constexpr double kNearPerFar = 1e-3;

struct Camera {
    Vec3 position{0, 2, 6};
    Vec3 lookAt{0, 0.7, 0};
    Vec3 up{0, 1, 0};
    double fovYDegrees = 40.0;
    int width = 1280;
    int height = 720;
    double near = kDefaultNear;
    double far = 100.0;
};

// glTF 2.0 alphaMode (3.9.4): OPAQUE ignores alpha, MASK cuts texels whose alpha is below the
// cutoff out of the caster, BLEND lets 1 - alpha of the light through (docs/scene-format.md).
enum class AlphaMode { Opaque, Mask, Blend };
// Which hits an alpha test drops: none, a shadow ray's (MASK below the cutoff) or a camera ray's
// (Material::cameraSkips).
enum class AlphaTest { Off, Shadow, Camera };
// The camera's one visible surface per pixel (docs/raytrace.md, "What the camera sees"): a BLEND
// texel is seen where its alpha is at least this, i.e. where it would weigh at least as much as
// everything behind it in "over" compositing; below, the camera looks through it.
inline constexpr double kBlendVisibleAlpha = 0.5;
// glTF sampler wrap modes (10497 REPEAT, 33071 CLAMP_TO_EDGE, 33648 MIRRORED_REPEAT).
enum class TextureWrap { Repeat, ClampToEdge, MirroredRepeat };

// A material's alpha texture (the alpha of a glTF baseColorTexture, or of a JSON material's
// "texture"), read once with OpenImageIO. Sampled nearest: texel (floor(u·width),
// floor(v·height)) after wrapping, row 0 the image's first (top) row, so UV (0, 0) is the
// image's top-left corner as glTF says; both backends sample it so (docs/scene-format.md).
struct AlphaTexture {
    std::filesystem::path file;
    int width = 0, height = 0;
    std::vector<float> alpha;  // width·height, row by row from the top; 1 where the image has no alpha
    TextureWrap wrapS = TextureWrap::Repeat, wrapT = TextureWrap::Repeat;
    std::size_t bytes() const { return sizeof(AlphaTexture) + alpha.capacity() * sizeof(float); }
};

// The texel index along one axis for coordinate `c` on an axis of `size` texels (nearest).
// Templated so the float tracer evaluates it in float like the shaders, the reference in double.
template <typename Real>
inline int wrapTexel(Real c, int size, TextureWrap wrap) {
    const Real scaled = std::floor(c * Real(size));
    // Far outside the texture every wrap lands on a texel; clamp first so the cast is defined.
    const Real limit = Real(1 << 30);
    const long long i = (long long)(scaled < -limit ? -limit : scaled > limit ? limit : scaled);
    const long long n = size;
    switch (wrap) {
        case TextureWrap::ClampToEdge: return int(i < 0 ? 0 : i >= n ? n - 1 : i);
        case TextureWrap::MirroredRepeat: {
            const long long m = ((i % (2 * n)) + 2 * n) % (2 * n);
            return int(m < n ? m : 2 * n - 1 - m);
        }
        case TextureWrap::Repeat: break;
    }
    return int(((i % n) + n) % n);
}

template <typename Real>
inline float sampleAlpha(const AlphaTexture& t, Real u, Real v) {
    const int x = wrapTexel(u, t.width, t.wrapS), y = wrapTexel(v, t.height, t.wrapT);
    return t.alpha[std::size_t(y) * std::size_t(t.width) + std::size_t(x)];
}

struct Material {
    std::string name;
    Vec3 albedo{0.8, 0.8, 0.8};
    // < 1 makes the material semi-transparent to shadow rays: each object a shadow ray
    // crosses multiplies the light by (1 - opacity) once. The camera never sees through it.
    double opacity = 1.0;
    // Alpha (docs/scene-format.md, "Alpha-tested and blended casters"): alpha(uv) = alphaFactor
    // × the texture's alpha at uv (1 without a texture). Mask: a shadow ray passes where
    // alpha(uv) < alphaCutoff; Blend: a hit lets 1 − opacity·alpha(uv) through (the opacity
    // path, per hit). The camera looks through MASK texels below the cutoff and BLEND texels
    // below kBlendVisibleAlpha (cameraSkips); opacity alone never hides a surface from it.
    AlphaMode alphaMode = AlphaMode::Opaque;
    double alphaCutoff = 0.5;
    double alphaFactor = 1.0;  // glTF baseColorFactor[3]
    std::shared_ptr<const AlphaTexture> alphaTexture;
    int texCoord = 0;  // glTF TEXCOORD_n set of the texture (meshes); quads have their own
    bool opaque() const { return opacity >= 1.0 && alphaMode != AlphaMode::Blend; }
    // Alpha read per hit (a texture in MASK or BLEND); otherwise it is a constant.
    bool alphaTextured() const { return alphaTexture && alphaMode != AlphaMode::Opaque; }
    // Mask / blend decisions for any hit; `texAlpha` is the texture's alpha there (1 without).
    double alphaAt(double texAlpha) const { return alphaFactor * texAlpha; }
    bool masked(double texAlpha) const { return alphaMode == AlphaMode::Mask && alphaAt(texAlpha) < alphaCutoff; }
    // Whether alpha(uv) can fall below `cutoff` anywhere: false where alpha is a constant at or
    // above it, or the texture's smallest texel times the factor is, both in float (the shaders'
    // and the float tracer's product) and in double (the reference's). A test against that cutoff
    // can then never fire, and a pass may leave it out. (A factor outside [0, 1]: always true.)
    bool alphaCanFallBelow(double cutoff) const;
    // The alpha below which the camera looks through a texel (no test for OPAQUE: -1).
    double cameraCutoff() const {
        return alphaMode == AlphaMode::Mask ? alphaCutoff : alphaMode == AlphaMode::Blend ? kBlendVisibleAlpha : -1.0;
    }
    bool cameraSkips(double texAlpha) const {
        return alphaMode != AlphaMode::Opaque && alphaAt(texAlpha) < cameraCutoff();
    }
    // The light a hit lets through: 1 − opacity, and for BLEND 1 − opacity·alpha(uv).
    double transmittance(double texAlpha) const {
        return alphaMode == AlphaMode::Blend ? 1.0 - opacity * alphaAt(texAlpha) : 1.0 - opacity;
    }
};

enum class LightType { Directional, Point, Spot };

struct Light {
    LightType type = LightType::Directional;
    Vec3 direction{0, -1, 0};  // the way light travels (unit length); directional and spot
    Vec3 position{0, 0, 0};    // point and spot
    Vec3 color{1, 1, 1};
    double intensity = 1.0;
    double radius = 0.0;            // point/spot: > 0 makes a spherical area light (soft shadows)
    double coneAngleDegrees = 0.0;  // spot: half-angle of the cone
    // Spot: full intensity within this half-angle, falling to 0 at coneAngleDegrees along
    // KHR_lights_punctual's curve (scene/shading.h spotFalloff). At or above coneAngleDegrees (the
    // default) the cone's edge is hard.
    double innerConeAngleDegrees = 90.0;
};

struct Sphere {
    Vec3 center{0, 0, 0};
    double radius = 1.0;
};

// A rectangle centered at `center` with unit normal `normal`. Its edges run along `uAxis`
// (size.x) and `vAxis` (size.y); see quadAxes() for how they follow from the normal.
// Quads are two-sided: they block light and are seen from both sides.
// Texture coordinates run from uvMin at center − size/2 (along uAxis, vAxis) to uvMax at
// center + size/2 (the JSON keys "uv_min", "uv_max"; default the texture once).
struct Quad {
    Vec3 center{0, 0, 0};
    Vec3 normal{0, 1, 0};
    Vec2 size{1, 1};
    Vec3 uAxis{1, 0, 0};
    Vec3 vAxis{0, 0, 1};
    Vec2 uvMin{0, 0};
    Vec2 uvMax{1, 1};
};

struct Box {
    Vec3 min{0, 0, 0};
    Vec3 max{0, 0, 0};
};

// A triangle mesh in its own object space (double precision), shared (shared_ptr<const>) by
// every object and glTF node that places it. Loaded from OBJ/glTF by mesh_loader.h; `normals`
// is per vertex, computed when the file has none (flat for glTF, smooth for OBJ and PLY).
struct TriangleMesh {
    std::vector<Vec3> positions;
    std::vector<Vec3> normals;
    std::vector<std::uint32_t> indices;  // three per triangle
    // Per vertex, only where a material reads an alpha texture (glTF TEXCOORD_n, OBJ vt); else empty.
    std::vector<Vec2> uvs;
    std::size_t droppedDegenerate = 0;  // triangles removed on load (zero area / non-finite)
    std::size_t triangleCount() const { return indices.size() / 3; }
};

// Object space to world space: an affine 4x3 matrix (three rows; columns 0..2 the linear part,
// column 3 the translation), double. Normals go by the inverse transpose of the linear part.
using Affine = glm::dmat4x3;
inline Vec3 transformPoint(const Affine& m, const Vec3& p) { return m * glm::dvec4(p, 1.0); }
inline Vec3 transformVector(const Affine& m, const Vec3& v) { return m * glm::dvec4(v, 0.0); }
inline glm::dmat3 normalMatrix(const Affine& m) { return glm::transpose(glm::inverse(glm::dmat3(m))); }
inline Affine affineOf(const glm::dmat4& m) { return Affine(m); }

// One placement of a geometry: the same `geometry` pointer in several instances (other nodes
// of the glTF file, other objects naming the same file) is one mesh in memory, placed several
// times (docs/decisions.md, "Mesh instancing").
struct MeshInstance {
    std::shared_ptr<const TriangleMesh> geometry;
    Affine transform{1.0};
    // A glTF file read per material (a model given as the scene): the glTF material index of
    // the geometry's primitives (-1: none); -1 otherwise.
    int fileMaterial = -1;
};

// A mesh object: one scene object (one object id) whatever its file holds. An OBJ file is one
// instance; a glTF file is one instance per node that uses a mesh (its node hierarchy applied,
// then the object's translate/rotate/scale).
struct Mesh {
    std::filesystem::path file;  // as resolved against the scene file's folder
    std::vector<MeshInstance> instances;
    std::size_t triangleCount() const;  // placed triangles (an instanced triangle counts each time)
    // One instance of `geometry` (tests and generated meshes).
    static Mesh single(std::filesystem::path file, std::shared_ptr<const TriangleMesh> geometry,
                       const Affine& transform = Affine(1.0)) {
        return Mesh{std::move(file), {MeshInstance{std::move(geometry), transform}}};
    }
};

using Shape = std::variant<Sphere, Quad, Box, Mesh>;

struct Object {
    std::string name;  // "objects[3]" unless the file names it
    Shape shape;
    int material = 0;  // index into Scene::materials
};

// Per-scene defaults for the render settings (the optional "shadow" block). Every field is
// optional: absent means "use the program's scene-scaled default".
struct ShadowDefaults {
    std::optional<int> shadowMapSize;
    std::optional<double> depthBias;    // world units
    std::optional<double> slopeBias;    // shadow-map texels
    std::optional<std::string> filter;  // "none" | "pcf2x2" | "pcf" | "poisson"
    std::optional<int> pcfSize;         // texels
    // Filterable maps (MomentSettings): min_variance, light_bleeding_reduction,
    // evsm_positive_exponent, evsm_negative_exponent, esm_exponent, moment_bias, blur_width.
    std::optional<double> minVariance, bleedReduction, evsmPositive, evsmNegative, esmExponent, momentBias;
    std::optional<int> blurWidth;
    std::optional<double> normalOffset;  // texels
    std::optional<bool> receiverPlaneBias;
    std::optional<bool> hardwareBias;
    std::optional<bool> fitLightFrustum;
    std::optional<int> cascades;          // directional lights: cascaded shadow maps, 1..kMaxCascades
    std::optional<double> cascadeBlend;   // fraction of each slice blended into the next, 0..0.5
    std::optional<double> rayBias;        // world units; absent: the view-scaled default
    std::optional<bool> robustRayOffset;  // "ray_bias": "robust"
    std::optional<std::string> precision;
    std::optional<int> samples;

    // These defaults with every key that `over` sets taken from it (a check case's "settings" over
    // its scene's "shadow" block). "ray_bias" is one key: a number or "robust" replaces both fields.
    ShadowDefaults overriddenBy(const ShadowDefaults& over) const;
    bool operator==(const ShadowDefaults&) const = default;
};

struct Bounds {
    Vec3 min{std::numeric_limits<double>::infinity()};
    Vec3 max{-std::numeric_limits<double>::infinity()};
    bool empty() const { return !(min.x <= max.x); }
    void extend(const Vec3& p) {
        min = glm::min(min, p);
        max = glm::max(max, p);
    }
    void extend(const Bounds& b) {
        if (!b.empty()) {
            extend(b.min);
            extend(b.max);
        }
    }
    Vec3 center() const { return 0.5 * (min + max); }
    Vec3 extent() const { return max - min; }
    double diagonal() const { return empty() ? 0.0 : glm::length(max - min); }
    // Largest absolute coordinate: what float rounding of a position scales with.
    double maxAbsCoordinate() const;
};

// A camera held by one of the scene's glTF files (the model given as the scene, or a mesh
// object's file), placed in world space; --camera and a mesh object's "camera" key pick one.
struct FileCamera {
    std::string name;    // the glTF camera's name, else its node's ("" when both are unnamed)
    std::string source;  // the file, or "objects[2] (truck.gltf)" in a JSON scene
    Camera camera;       // the scene's image size; near/far from the file or the scene's size
};

// One animated property of a glTF node (glTF 2.0, 3.11): key times in seconds and values, xyz for
// a translation, a quaternion xyzw for a rotation; CUBICSPLINE keys hold three values each (in-tangent,
// value, out-tangent).
struct AnimationCurve {
    enum class Interpolation { Linear, Step, CubicSpline };
    Interpolation interpolation = Interpolation::Linear;
    std::vector<double> times;
    std::vector<glm::dvec4> values;
};

// A glTF animation's channels that move the node of one of the file's cameras, kept so a path study
// can sample the camera along it (scene/camera_animation.h). The node's parents are not animated.
struct CameraAnimation {
    std::string name;        // the animation's "name" ("" when unnamed)
    int index = -1;          // in the file's animations
    int camera = -1;         // into SceneOrigin::cameras
    glm::dmat4 parent{1.0};  // the node's parents' transform
    Vec3 translation{0, 0, 0};
    glm::dvec4 rotation{0, 0, 0, 1};  // xyzw
    Vec3 scale{1, 1, 1};
    std::optional<AnimationCurve> translationCurve, rotationCurve;
    double start = 0.0, end = 0.0;  // the keys' time range, seconds
};

// Where a scene's view, sun and ground came from: what its files hold, what is left to choose
// (a glTF given as the scene without a camera or a light; see scene/model_view.h and
// raytrace/view_search.h), and each choice in words for --explain and the Frame's attributes.
struct SceneOrigin {
    std::vector<FileCamera> cameras;
    // Animations of those cameras' nodes (a .gltf/.glb given as the scene; `path --camera-animation`).
    std::vector<CameraAnimation> cameraAnimations;
    bool modelScene = false;     // a .gltf/.glb given directly as the scene
    bool chooseView = false;     // the camera is a placeholder: a view search replaces it
    bool chooseSun = false;      // lights[0] is a placeholder sun: a view search replaces its direction
    std::optional<bool> ground;  // the scene file's "ground" key
    // The JSON camera gives no "far": it reaches the farthest corner of the scene's bounds,
    // refitted when a ground is added (fitNearFarToBounds, scene/model_view.h).
    bool farFromBounds = false;
    bool nearFromBounds = false;  // nor "near": fitted with far (fitNearFarToBounds)
    Bounds modelBounds;           // the objects without an added ground (what a view frames)
    int addedGround = -1;         // index in objects of the ground addGround added, else -1
    // ("view", "searched: ..."), ("sun", ...), ("ground", ...): printed by --explain, recorded
    // in every Frame as attributes "choice.view", "choice.sun", ...
    std::vector<std::pair<std::string, std::string>> choices;
    // What loading had to assume, which every command prints as a note and every Frame records
    // ("note.0", "note.1", ...): e.g. a texture whose image file is missing.
    std::vector<std::string> notes;
};

// The optional "path" block: the camera or light path `shadowlab path` renders when the command
// line names none (compare/path.h holds the kinds and what `amount` means for each).
struct PathBlock {
    std::string kind;  // orbit | dolly | pan | subtexel | sun-azimuth | sun-elevation | light-move | gltf-animation
    std::optional<int> frames;
    std::optional<double> amount;
    std::optional<int> light;
    std::optional<std::string> animation;  // gltf-animation: a name or an index
};

struct Scene {
    std::filesystem::path file;  // where it was loaded from (for messages and metadata)
    Camera camera;
    Vec3 background{0.05, 0.05, 0.08};
    double ambient = 0.05;
    std::vector<Material> materials;
    std::vector<Light> lights;
    std::vector<Object> objects;
    ShadowDefaults shadow;
    std::optional<PathBlock> path;
    SceneOrigin origin;
    // The optional "budgets" block: limits `run` and `check` hold each method to (docs/ci.md).
    Budgets budgets;
    // What loading took at its peak beyond the scene itself (the file's text, its parsed JSON
    // tree, the largest mesh file's temporaries): part of the memory estimate (scene/memory.h).
    std::uint64_t loadBytes = 0;

    const Material& materialOf(const Object& o) const { return materials[o.material]; }
    bool allOpaque() const;
    Bounds bounds() const;  // of every object
};

Bounds boundsOf(const Shape& shape);
// The quad's edge directions: uAxis is world X projected onto the quad's plane, or world Z
// when the normal is (anti)parallel to X; vAxis = normal × uAxis. Fixed so that both
// backends and the tests agree on which way `size` runs.
void quadAxes(const Vec3& normal, Vec3& uAxis, Vec3& vAxis);

}  // namespace shadowlab::scene

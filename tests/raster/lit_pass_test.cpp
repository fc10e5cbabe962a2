// tests/raster/lit_pass_test.cpp: the camera pass alone (raster/lit_pass.cpp) on lavapipe with the
// validation layer: for a quad under one directional light without a shadow test, every pixel
// holds what the geometry says, worked out here from the camera: the quad's id, N·L, view depth,
// visibility 1 and its shading where the pixel's centre ray meets the quad, the background and
// zero AOVs elsewhere; read in place and through the readback copy alike. Also the targets' size
// limit and where lit.vert hands lit.frag the light's map coordinates.
#include "raster/lit_pass.h"

#include <array>
#include <cmath>
#include <map>
#include <set>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "raster/geometry.h"
#include "raster/tolerances.h"
#include "raster/vulkan_error.h"
#include "scene/camera.h"
#include "shaders/spirv.h"
#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raster {
namespace {

using test::Vec3;

// A 3 x 3 floor quad (object 0, id 1) at y = 0, albedo (0.8, 0.6, 0.4), seen from (0, 3, 4) at 96 x 64;
// a directional light toward L = (1, 2, 0.5)/|·| of intensity 2; ambient 0.05.
constexpr int kWidth = 96, kHeight = 64;
const Vec3 kAlbedo(0.8, 0.6, 0.4), kBackground(0.1, 0.2, 0.3);
const Vec3 kToLight = glm::normalize(Vec3(1, 2, 0.5));
constexpr double kAmbient = 0.05, kIntensity = 2.0;

scene::Scene floorScene() {
    scene::Scene s;
    s.camera = {.position = Vec3(0, 3, 4), .lookAt = Vec3(0), .width = kWidth, .height = kHeight};  // fov 40°
    s.ambient = kAmbient;
    s.background = kBackground;
    test::addMaterial(s, "floor");
    s.materials[0].albedo = kAlbedo;
    test::addDirectional(s, -kToLight, kIntensity);
    test::addQuad(s, Vec3(0), Vec3(0, 1, 0), 3, 3);
    return s;
}

// What the pass wrote: per pixel the beauty (rgb) and each AOV plane (LitPlane order: visibility,
// object id, N·L, view depth, blocker id at index 1..5; index 0 unused).
struct Pixels {
    std::vector<glm::vec3> beauty;
    std::array<std::vector<float>, kLitPlanes> planes;
    float at(LitPlane plane, std::size_t i) const { return planes[std::size_t(plane)][i]; }
};

// The lit pass of `s` alone: the light's uniforms as the renderer fills them for a directional
// light, but with layer −1 (no shadow test), the placeholder maps a render without shadow layers
// binds, the geometry relative to the camera, the pass rendering into its own targets; `draw`
// false draws nothing.
Pixels litPass(const Context& ctx, const scene::Scene& s, bool readInPlace, bool draw = true) {
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    const SceneGeometry g = tessellateScene(s, cam.position);
    const Buffer vb = uploadBuffer(ctx, g.vertices, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
    const Buffer ib = uploadBuffer(ctx, g.indices, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
    DrawGeometry geometry;
    geometry.vertices = vb.buffer.get();
    geometry.indices = ib.buffer.get();
    geometry.indexCount = draw ? std::uint32_t(g.indices.size()) : 0u;

    shaders::LitUniforms u{};
    u.viewProj =
        glm::mat4(scene::projectionMatrix(cam, s.camera.near, s.camera.far) * scene::viewMatrix(cam, cam.position));
    u.forward = glm::vec3(cam.forward);
    u.ambient = float(s.ambient);
    u.background = glm::vec3(s.background);
    u.lightCount = 1;
    u.mapSize = 1.0f;
    shaders::LightData& l = u.lights[0];
    l.toShadow = glm::mat4(1.0f);
    l.towardLight = glm::vec3(kToLight);
    l.layer = -1.0f;  // no shadow test
    l.radiance = glm::vec3(float(kIntensity));
    l.visibilityWeight = float(kIntensity);
    l.maxSlopeTan = float(kMaxSlopeTan);
    l.filterCode = SHADOWLAB_FILTER_NONE;
    l.pcfSize = 1;
    l.kind = SHADOWLAB_LIGHT_DIRECTIONAL;
    const std::vector<glm::vec4> albedos = {glm::vec4(glm::vec3(kAlbedo), 1.0f)};

    const LitTargets targets = createLitTargets(ctx, kWidth, kHeight, 0, readInPlace);
    const LitPipeline pipeline = createLitPipeline(ctx,
                                                   LitVariant{.filter = scene::ShadowFilter::None,
                                                              .normalOffset = false,
                                                              .beautyFormat = targets.beautyFormat,
                                                              .lightKinds = 1u << SHADOWLAB_LIGHT_DIRECTIONAL},
                                                   VK_NULL_HANDLE, glm::vec3(s.background));
    // Placeholders, moved to SHADER_READ_ONLY_OPTIMAL by a shadow pass of no layers.
    const ShadowPipeline shadowPipeline = createShadowPipeline(ctx);
    const ShadowMaps maps = createShadowMaps(ctx, 1, 1);
    const TransmittanceMaps transmittance = createTransmittanceMaps(ctx, 1, 1);
    const MomentMaps moments = createMomentMaps(ctx, 1, 1);
    const TransmittancePass placeholders{nullptr, &transmittance, {}, nullptr, {}};
    EXPECT_EQ(targets.hostReadable, readInPlace) << "lavapipe reads its targets in place when asked";
    const LitBindings bindings =
        createLitBindings(ctx, pipeline, u, shaders::TransmitWindows{}, albedos, maps, transmittance, moments);
    const Readback readback = createReadback(ctx, targets);
    LitAttachments attachments;
    for (const Image& plane : targets.planes) attachments.add(plane);

    VkCommandBuffer commands = ctx.beginCommands();
    recordShadowPass(commands, shadowPipeline, maps, geometry, {}, true, &placeholders);
    recordLitPass(commands, pipeline, bindings, targets, attachments, geometry, glm::vec3(s.background));
    ReadbackSelection all;
    all.planes.fill(true);
    if (!targets.hostReadable) recordReadback(commands, targets, readback, all);
    ctx.submitAndWait(commands);
    if (!targets.hostReadable)
        for (const Buffer& b : readback.planes) invalidate(ctx, b);
    // (lavapipe's host-visible memory is coherent: targets read in place need no invalidation.)
    Pixels out;
    for (std::uint32_t p = 0; p < kLitPlanes; ++p) {
        const std::size_t texel = litPlaneTexelBytes(targets, LitPlane(p));
        const char* base = targets.hostReadable ? static_cast<const char*>(targets.planes[p].mapped)
                                                : static_cast<const char*>(readback.planes[p].mapped);
        const std::size_t pitch =
            targets.hostReadable ? std::size_t(targets.planes[p].rowPitch) : std::size_t(kWidth) * texel;
        for (int y = 0; y < kHeight; ++y)
            for (int x = 0; x < kWidth; ++x) {
                const float* v = reinterpret_cast<const float*>(base + std::size_t(y) * pitch + std::size_t(x) * texel);
                if (p == 0)
                    out.beauty.emplace_back(v[0], v[1], v[2]);
                else
                    out.planes[p].push_back(v[0]);
            }
    }
    return out;
}

TEST(RasterLitPass, DrawsTheQuadTheCameraSeesWithItsShadingAndAovs) {
    // Per pixel, the centre ray eye + t·d meets y = 0 at q (test::floorPoint). On the quad
    // (|q.x|, |q.z| < 1.5, more than 0.1 inside: a pixel's footprint there is under 0.06): id 1,
    // N·L = L.y (the normal +y faces the camera above it), view depth (q − eye)·forward, visibility
    // 1 (no shadow test), color albedo·(ambient + intensity·N·L). Past the quad by 0.1: the
    // background color, visibility 0, zero AOVs.
    const scene::Scene s = floorScene();
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    test::ValidatedContext vc;
    for (const bool inPlace : {true, false}) {
        SCOPED_TRACE(inPlace ? "read in place" : "copied");
        const Pixels p = litPass(vc.get(), s, inPlace);
        int onQuad = 0, off = 0, wrong = 0;
        for (int y = 0; y < kHeight; ++y)
            for (int x = 0; x < kWidth; ++x) {
                const std::size_t i = std::size_t(y) * kWidth + std::size_t(x);
                const Vec3 q = test::floorPoint(cam, x, y);
                const double edge = std::max(std::abs(q.x), std::abs(q.z));
                const bool down = test::pixelRay(cam, x, y).y < 0.0;
                const glm::vec3 b = p.beauty[i];
                const float id = p.at(LitPlane::kObjectId, i), nl = p.at(LitPlane::kNdotL, i),
                            z = p.at(LitPlane::kDepth, i), blocker = p.at(LitPlane::kBlockerId, i),
                            v = p.at(LitPlane::kVisibility, i);
                if (down && edge < 1.4) {
                    ++onQuad;
                    const double ndotl = kToLight.y;
                    const Vec3 color = kAlbedo * (kAmbient + kIntensity * ndotl);
                    const double depth = glm::dot(q - cam.position, cam.forward);
                    const bool ok = id == 1.0f && std::abs(nl - ndotl) < 1e-5 && std::abs(z - depth) < 1e-4 &&
                                    blocker == 0.0f && v == 1.0f && std::abs(b.r - color.r) < 1e-5 &&
                                    std::abs(b.g - color.g) < 1e-5 && std::abs(b.b - color.b) < 1e-5;
                    if (!ok && ++wrong <= 3)
                        ADD_FAILURE() << "quad pixel " << x << "," << y << ": beauty " << b.r << " " << b.g << " "
                                      << b.b << ", visibility " << v << ", aovs " << id << " " << nl << " " << z << " "
                                      << blocker;
                } else if (!down || edge > 1.6) {
                    ++off;
                    const bool ok = b == glm::vec3(kBackground) && v == 0.0f && id == 0.0f && nl == 0.0f && z == 0.0f &&
                                    blocker == 0.0f;
                    if (!ok && ++wrong <= 3) ADD_FAILURE() << "background pixel " << x << "," << y;
                }
            }
        // The quad spans about 3/5 rad of the view's 57° across and is foreshortened (seen 37°
        // above the plane): well over a thousand of the 6144 pixels; the corners show background.
        EXPECT_GT(onQuad, 1000);
        EXPECT_GT(off, 1000);
        EXPECT_EQ(wrong, 0);
    }
}

TEST(RasterLitPass, WithNothingToDrawEveryPixelIsTheBackgroundWithZeroAovs) {
    test::ValidatedContext vc;
    const Pixels p = litPass(vc.get(), floorScene(), true, false);
    int wrong = 0;
    for (std::size_t i = 0; i < p.beauty.size(); ++i) {
        bool zero = true;
        for (std::uint32_t plane = 1; plane < kLitPlanes; ++plane) zero = zero && p.planes[plane][i] == 0.0f;
        wrong += p.beauty[i] != glm::vec3(kBackground) || !zero;
    }
    EXPECT_EQ(p.beauty.size(), std::size_t(kWidth) * kHeight);
    EXPECT_EQ(wrong, 0);
}

TEST(RasterLitPass, TargetsLargerThanTheDeviceAllowsAreRefusedNamingTheLimit) {
    test::ValidatedContext vc;
    const Context& ctx = vc.get();
    const std::uint32_t limit = ctx.properties.limits.maxImageDimension2D;
    try {
        createLitTargets(ctx, limit + 1, 4);
        FAIL() << "expected RasterError";
    } catch (const RasterError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(std::to_string(limit + 1) + "x4"), std::string::npos) << what;
        EXPECT_NE(what.find("limit of " + std::to_string(limit)), std::string::npos) << what;
    }
}

TEST(RasterLitPass, PackedConstantsCarryTheOneMapLightsMatrix) {
    // lit.frag (oneMapMatrix) reads the one-map light's toShadow from cascade 0's three rows
    // (packed values 34..45, constants 52..63) and a spot's last row from the light slots' spare
    // components (values 15, 23, 29 and 30: outLight[3].w, outLight[5].w, outFrame[1].y and .z),
    // its inner cone's cosine from the last (value 31, outFrame[1].w);
    // a change of the matrix alone must change the packed values, which Renderer::update compares
    // to leave the baked pipelines. A matrix whose every entry differs shows a misplaced one.
    shaders::LitUniforms u{};
    u.lightCount = 1;
    u.mapSize = 2048.0f;
    u.lights[0].spotCosInner = 0.875f;  // a spot's inner cone: value 31, outFrame[1].w
    for (int column = 0; column < 4; ++column)
        for (int row = 0; row < 4; ++row) u.lights[0].toShadow[column][row] = float(1 + 4 * column + row);
    for (const int kind : {SHADOWLAB_LIGHT_DIRECTIONAL, SHADOWLAB_LIGHT_SPOT}) {
        u.lights[0].kind = kind;
        const auto c = packLightConstants(u, false);
        for (int row = 0; row < 3; ++row)
            for (int column = 0; column < 4; ++column)
                EXPECT_EQ(c[std::size_t(34 + 4 * row + column)], float(1 + 4 * column + row)) << row << column;
        const bool spot = kind == SHADOWLAB_LIGHT_SPOT;
        EXPECT_EQ(c[15], spot ? 4.0f : 0.0f);
        EXPECT_EQ(c[23], spot ? 8.0f : 0.0f);
        EXPECT_EQ(c[29], spot ? 12.0f : 0.0f);
        EXPECT_EQ(c[30], spot ? 16.0f : 0.0f);
        EXPECT_EQ(c[31], spot ? 0.875f : 0.0f);
        EXPECT_EQ(c[28], 2048.0f);  // the map size keeps its slot
        shaders::LitUniforms moved = u;
        moved.lights[0].toShadow[3][0] += 1.0f;  // a translation: only the matrix differs
        EXPECT_NE(packLightConstants(moved, false), c);
    }
    // A cascaded sun's cascade 0 keeps its own values; with two lights nothing is light 0's alone.
    u.lights[0].kind = SHADOWLAB_LIGHT_DIRECTIONAL;
    u.lights[0].cascadeCount = 3;
    u.cascades[0].toShadow[0][0] = 99.0f;
    EXPECT_EQ(packLightConstants(u, false)[34], 99.0f);
    u.lights[0].cascadeCount = 0;
    u.lightCount = 2;
    u.lights[0].kind = SHADOWLAB_LIGHT_SPOT;
    const auto two = packLightConstants(u, false);
    EXPECT_EQ(two[34], 99.0f);
    EXPECT_EQ(two[15], 0.0f);
    EXPECT_EQ(two[30], 0.0f);
    EXPECT_EQ(two[31], 0.0f);
}

TEST(RasterLitPass, OnlyOneDirectionalMapOrOneSpotIsTheOneMapLight) {
    // Light 0's constants and its one map matrix are baked in (or passed on flat) only when that one
    // matrix serves every fragment: one light, directional with a single map or a spot, and no
    // receiver plane (which bakes every light's). Points pick a cube face per fragment, cascades a map.
    constexpr std::uint32_t dir = 1u << SHADOWLAB_LIGHT_DIRECTIONAL, spot = 1u << SHADOWLAB_LIGHT_SPOT,
                            point = 1u << SHADOWLAB_LIGHT_POINT;
    EXPECT_TRUE(hasOneMapLight({.lightKinds = dir}));
    EXPECT_TRUE(hasOneMapLight({.lightKinds = spot}));
    EXPECT_FALSE(hasOneMapLight({.lightKinds = point}));
    EXPECT_FALSE(hasOneMapLight({.lightKinds = dir, .cascades = 3}));
    EXPECT_TRUE(hasOneMapLight({.lightKinds = spot, .cascades = 3}));  // cascades are directional only
    EXPECT_FALSE(hasOneMapLight({.lightCount = 2, .lightKinds = dir}));
    EXPECT_FALSE(hasOneMapLight({.lightKinds = spot, .receiverPlane = true}));
    EXPECT_FALSE(hasOneMapLight({.lightKinds = dir | spot}));
}

// Calls visit(opcode, operands) for each instruction of a SPIR-V module, read as the SPIR-V
// specification lays it out: a five-word header, then instructions whose first word holds the word
// count (high 16 bits) and the opcode (low 16). False (and a test failure) where it is malformed.
template <class Visit>
bool forEachInstruction(std::span<const std::uint32_t> spirv, Visit visit) {
    for (std::size_t at = 5; at < spirv.size();) {
        const std::uint32_t count = spirv[at] >> 16, opcode = spirv[at] & 0xffffu;
        if (count == 0 || at + count > spirv.size()) {
            ADD_FAILURE() << "malformed SPIR-V at word " << at;
            return false;
        }
        visit(opcode, spirv.subspan(at + 1, count - 1));
        at += count;
    }
    return true;
}

constexpr std::uint32_t kOpDecorate = 71, kOpVariable = 59;

// The locations of a module's Input (or Output) variables that carry a Location decoration
// (built-ins have none): OpDecorate target, decoration (Location = 30), value; OpVariable result
// type, result id, storage class (Input = 1, Output = 3).
std::set<std::uint32_t> interfaceLocations(std::span<const std::uint32_t> spirv, std::uint32_t storageClass) {
    constexpr std::uint32_t kLocation = 30;
    std::map<std::uint32_t, std::uint32_t> locationOf;
    std::vector<std::uint32_t> variables;
    const bool read = forEachInstruction(spirv, [&](std::uint32_t opcode, std::span<const std::uint32_t> w) {
        if (opcode == kOpDecorate && w.size() >= 3 && w[1] == kLocation) locationOf[w[0]] = w[2];
        if (opcode == kOpVariable && w.size() >= 3 && w[2] == storageClass) variables.push_back(w[1]);
    });
    std::set<std::uint32_t> locations;
    if (!read) return locations;
    for (std::uint32_t id : variables)
        if (const auto found = locationOf.find(id); found != locationOf.end()) locations.insert(found->second);
    return locations;
}

// The SpecId decorations of a module's specialization constants (OpDecorate, decoration SpecId = 1).
std::set<std::uint32_t> specializationIds(std::span<const std::uint32_t> spirv) {
    constexpr std::uint32_t kSpecId = 1;
    std::set<std::uint32_t> ids;
    forEachInstruction(spirv, [&](std::uint32_t opcode, std::span<const std::uint32_t> w) {
        if (opcode == kOpDecorate && w.size() >= 3 && w[1] == kSpecId) ids.insert(w[2]);
    });
    return ids;
}

TEST(RasterLitPass, EachVertexShaderWritesExactlyWhatItsFragmentShaderReads) {
    // lit.frag's inputs must all be lit.vert's outputs (Vulkan's interface rule), and an output no
    // input takes still costs llvmpipe a store per vertex, as a declared input costs it a setup per
    // triangle: so the sets are equal, for every pair litStages() hands out.
    constexpr std::uint32_t kInput = 1, kOutput = 3;
    constexpr std::uint32_t dir = 1u << SHADOWLAB_LIGHT_DIRECTIONAL, spot = 1u << SHADOWLAB_LIGHT_SPOT,
                            point = 1u << SHADOWLAB_LIGHT_POINT;
    int pairs = 0;
    for (const scene::ShadowFilter filter : {scene::ShadowFilter::Pcf2x2, scene::ShadowFilter::Pcf})
        for (const bool aov : {true, false})
            for (const std::uint32_t lightTargets : {0u, kLightTargets})
                for (const std::uint32_t kinds : {dir, spot, point, dir | spot})
                    for (const std::uint32_t cascades : {1u, 4u})
                        for (const bool blend : {false, true})
                            for (const bool baked : {false, true})
                                for (const bool sun : {true, false})
                                    for (const bool alpha : {false, true}) {
                                        if ((lightTargets > 0 && !aov) || (blend && cascades == 1)) continue;
                                        LitVariant v{.filter = filter,
                                                     .aovTarget = aov,
                                                     .lightTargets = lightTargets,
                                                     .lightCount = kinds == (dir | spot) ? 2u : 1u,
                                                     .lightKinds = kinds,
                                                     .cascades = cascades,
                                                     .cascadeBlend = blend,
                                                     .vertexLightConstants = true,
                                                     .specializedLightConstants = baked,
                                                     .oneLightModules = sun};
                                        const LitStages stages = litStages(v, alpha);
                                        EXPECT_EQ(interfaceLocations(stages.vertex, kOutput),
                                                  interfaceLocations(stages.fragment, kInput))
                                            << "filter " << int(filter) << " aov " << aov << " light targets "
                                            << lightTargets << " kinds " << kinds << " cascades " << cascades
                                            << " blend " << blend << " baked " << baked << " sun modules " << sun
                                            << " alpha " << alpha;
                                        ++pairs;
                                    }
    EXPECT_GT(pairs, 100);
}

TEST(RasterLitPass, OneSunWithBakedConstantsOrCascadesHasNoFlatLightInterface) {
    // lit.vert's flat light constants sit at locations 3..13 (outMapRows[3], outLight[6],
    // outFrame[2]). One sun with its constants baked in reads none of them, nor does a cascaded sun
    // (a matrix per cascade). Neither stage may declare what the pipeline does not read.
    constexpr std::uint32_t kInput = 1, kOutput = 3;
    constexpr std::uint32_t dir = 1u << SHADOWLAB_LIGHT_DIRECTIONAL;
    for (const bool alpha : {false, true})
        for (const bool aov : {true, false}) {
            const LitStages oneMap =
                litStages({.aovTarget = aov, .lightKinds = dir, .specializedLightConstants = true}, alpha);
            const LitStages cascaded = litStages({.aovTarget = aov, .lightKinds = dir, .cascades = 4}, alpha);
            for (const std::uint32_t slot : {6u, 12u}) {
                EXPECT_FALSE(interfaceLocations(oneMap.vertex, kOutput).contains(slot)) << slot;
                EXPECT_FALSE(interfaceLocations(oneMap.fragment, kInput).contains(slot)) << slot;
                EXPECT_FALSE(interfaceLocations(cascaded.fragment, kInput).contains(slot)) << slot;
            }
            for (const LitStages* stages : {&oneMap, &cascaded}) {
                EXPECT_FALSE(interfaceLocations(stages->vertex, kOutput).contains(3u));
                EXPECT_FALSE(interfaceLocations(stages->fragment, kInput).contains(3u));
            }
            // The flat-output path keeps them: lit.frag reads them there, the map matrix's rows in
            // the slots a sun leaves spare (no locations 3..5 of their own).
            const LitStages flat =
                litStages({.aovTarget = aov, .lightKinds = dir, .vertexLightConstants = true}, alpha);
            EXPECT_FALSE(interfaceLocations(flat.vertex, kOutput).contains(3u));
            EXPECT_FALSE(interfaceLocations(flat.fragment, kInput).contains(3u));
            EXPECT_TRUE(interfaceLocations(flat.fragment, kInput).contains(6u));
            EXPECT_TRUE(interfaceLocations(flat.vertex, kOutput).contains(12u));
        }
}

TEST(RasterLitPass, OneSpotOrOnePointLightWithBakedConstantsGetsItsSizeOptimizedModule) {
    // The *_spot and *_point modules fix one light of that kind, no transmittance, no receiver
    // plane and one map, and bake the constants in: exactly those variants get them, with none or
    // pcf2x2, where LitVariant::oneLightModules asks for them.
    constexpr std::uint32_t spot = 1u << SHADOWLAB_LIGHT_SPOT, point = 1u << SHADOWLAB_LIGHT_POINT;
    for (const bool alpha : {false, true})
        for (const bool aov : {true, false})
            for (const std::uint32_t kind : {spot, point}) {
                const bool isSpot = kind == spot;
                const std::span<const std::uint32_t> expected =
                    isSpot ? (aov ? (alpha ? shaders::litFragAlphaTapsSpotSpirv() : shaders::litFragTapsSpotSpirv())
                                  : (alpha ? shaders::litFragBeautyAlphaTapsSpotSpirv()
                                           : shaders::litFragBeautyTapsSpotSpirv()))
                           : (aov ? (alpha ? shaders::litFragAlphaTapsPointSpirv() : shaders::litFragTapsPointSpirv())
                                  : (alpha ? shaders::litFragBeautyAlphaTapsPointSpirv()
                                           : shaders::litFragBeautyTapsPointSpirv()));
                const LitVariant one{.filter = scene::ShadowFilter::None,
                                     .aovTarget = aov,
                                     .lightKinds = kind,
                                     .specializedLightConstants = true};
                const std::string what =
                    std::string(isSpot ? "spot" : "point") + (aov ? ", aov" : ", beauty") + (alpha ? ", alpha" : "");
                EXPECT_TRUE(usesSpotOrPointModule(one)) << what;
                EXPECT_EQ(litStages(one, alpha).fragment.data(), expected.data()) << what;
                LitVariant pcf2x2 = one;
                pcf2x2.filter = scene::ShadowFilter::Pcf2x2;
                EXPECT_EQ(litStages(pcf2x2, alpha).fragment.data(), expected.data()) << what;
                LitVariant notThese[6] = {one, one, one, one, one, one};
                notThese[0].filter = scene::ShadowFilter::Pcf;
                notThese[1].oneLightModules = false;
                notThese[2].specializedLightConstants = false;
                notThese[3].transmittance = true;
                notThese[4].receiverPlane = true;
                notThese[5].lightCount = 2;
                notThese[5].lightKinds = kind | (1u << SHADOWLAB_LIGHT_DIRECTIONAL);
                for (int k = 0; k < 6; ++k) {
                    EXPECT_FALSE(usesSpotOrPointModule(notThese[k])) << what << ", case " << k;
                    EXPECT_NE(litStages(notThese[k], alpha).fragment.data(), expected.data()) << what << ", case " << k;
                }
            }
}

TEST(RasterLitPass, OneSpotOrASunOutsideTheSunModulesWithBakedConstantsHasNoFlatLightInterface) {
    // The general modules (a spot light; a sun with a wide kernel, a filterable map or a
    // transmittance map) bake the one light's constants in too: then neither stage declares the
    // flat slots (3..13). With the constants from the vertex shader both keep them.
    constexpr std::uint32_t kInput = 1, kOutput = 3;
    constexpr std::uint32_t dir = 1u << SHADOWLAB_LIGHT_DIRECTIONAL, spot = 1u << SHADOWLAB_LIGHT_SPOT;
    struct Case {
        std::uint32_t kinds;
        scene::ShadowFilter filter;
        bool transmittance;
    };
    const Case cases[] = {{spot, scene::ShadowFilter::Pcf2x2, false}, {spot, scene::ShadowFilter::Pcss, false},
                          {spot, scene::ShadowFilter::Vsm, true},     {dir, scene::ShadowFilter::Pcf, false},
                          {dir, scene::ShadowFilter::Evsm4, false},   {dir, scene::ShadowFilter::Pcf2x2, true}};
    for (const Case& c : cases)
        for (const bool alpha : {false, true})
            for (const bool aov : {true, false}) {
                const std::string what = "kinds " + std::to_string(c.kinds) + " filter " +
                                         std::to_string(int(c.filter)) + " alpha " + std::to_string(alpha) + " aov " +
                                         std::to_string(aov);
                LitVariant v{.filter = c.filter,
                             .aovTarget = aov,
                             .lightKinds = c.kinds,
                             .transmittance = c.transmittance,
                             .specializedLightConstants = true};
                const LitStages baked = litStages(v, alpha);
                for (const std::uint32_t slot : {3u, 6u, 12u}) {
                    EXPECT_FALSE(interfaceLocations(baked.vertex, kOutput).contains(slot)) << what;
                    EXPECT_FALSE(interfaceLocations(baked.fragment, kInput).contains(slot)) << what;
                }
                v.specializedLightConstants = false;
                v.vertexLightConstants = true;
                const LitStages flat = litStages(v, alpha);
                EXPECT_TRUE(interfaceLocations(flat.fragment, kInput).contains(3u)) << what;
                EXPECT_TRUE(interfaceLocations(flat.fragment, kInput).contains(6u)) << what;
            }
}

TEST(RasterLitPass, EveryLightIsBakedInWhereThereIsNoOneMapLight) {
    // Several lights, one point light, or the receiver-plane bias: every light's constants baked in
    // (bakesEveryLight), in the general modules without the flat light slots (3..13); with per-light
    // visibility targets, the modules that write them (outputs 6 and 7); for the beauty alone, the
    // modules that write only it (output 0).
    constexpr std::uint32_t kInput = 1, kOutput = 3;
    constexpr std::uint32_t dir = 1u << SHADOWLAB_LIGHT_DIRECTIONAL, spot = 1u << SHADOWLAB_LIGHT_SPOT,
                            point = 1u << SHADOWLAB_LIGHT_POINT;
    EXPECT_FALSE(bakesEveryLight(LitVariant{.lightKinds = dir}));
    EXPECT_FALSE(bakesEveryLight(LitVariant{.lightKinds = spot}));
    EXPECT_FALSE(bakesEveryLight(LitVariant{.lightKinds = dir, .cascades = 3}));
    EXPECT_FALSE(bakesEveryLight(LitVariant{.lightCount = 0, .lightKinds = 0}));
    EXPECT_TRUE(bakesEveryLight(LitVariant{.lightKinds = point}));
    EXPECT_TRUE(bakesEveryLight(LitVariant{.lightKinds = dir, .receiverPlane = true}));
    EXPECT_TRUE(bakesEveryLight(LitVariant{.lightCount = 2, .lightKinds = dir}));
    EXPECT_TRUE(bakesEveryLight(LitVariant{.lightCount = 3, .lightKinds = dir | spot | point, .cascades = 4}));
    for (const scene::ShadowFilter filter : {scene::ShadowFilter::Pcf2x2, scene::ShadowFilter::Pcss})
        for (const bool alpha : {false, true})
            for (const std::uint32_t targets : {0u, kLightTargets})
                for (const bool aov : {true, false}) {
                    const std::string what = "filter " + std::to_string(int(filter)) + " alpha " +
                                             std::to_string(alpha) + " light targets " + std::to_string(targets) +
                                             " aov " + std::to_string(aov);
                    const LitVariant v{.filter = filter,
                                       .aovTarget = aov,
                                       .lightTargets = targets,
                                       .lightCount = 3,
                                       .lightKinds = dir | spot | point,
                                       .specializedLightConstants = true};
                    const LitStages baked = litStages(v, alpha);
                    for (const std::uint32_t slot : {3u, 6u, 12u}) {
                        EXPECT_FALSE(interfaceLocations(baked.vertex, kOutput).contains(slot)) << what;
                        EXPECT_FALSE(interfaceLocations(baked.fragment, kInput).contains(slot)) << what;
                    }
                    // The *_every build itself: it declares every light's constants (the last is 563).
                    const bool taps = filter == scene::ShadowFilter::Pcf2x2;
                    const auto expected =
                        !aov ? (taps ? (alpha ? shaders::litFragBeautyAlphaTapsEverySpirv()
                                              : shaders::litFragBeautyTapsEverySpirv())
                                     : (alpha ? shaders::litFragBeautyAlphaEverySpirv()
                                              : shaders::litFragBeautyEverySpirv()))
                        : targets > 0
                            ? (taps ? (alpha ? shaders::litFragLightsAlphaTapsEverySpirv()
                                             : shaders::litFragLightsTapsEverySpirv())
                                    : (alpha ? shaders::litFragLightsAlphaEverySpirv()
                                             : shaders::litFragLightsEverySpirv()))
                            : (taps ? (alpha ? shaders::litFragAlphaTapsEverySpirv() : shaders::litFragTapsEverySpirv())
                                    : (alpha ? shaders::litFragAlphaEverySpirv() : shaders::litFragEverySpirv()));
                    EXPECT_EQ(baked.fragment.data(), expected.data()) << what;
                    EXPECT_TRUE(specializationIds(baked.fragment).contains(563u)) << what;
                    EXPECT_EQ(interfaceLocations(baked.fragment, kOutput).contains(1u), aov) << what;
                    EXPECT_EQ(interfaceLocations(baked.fragment, kOutput).contains(6u), aov && targets > 0) << what;
                    EXPECT_EQ(interfaceLocations(baked.fragment, kOutput).contains(7u), aov && targets > 0) << what;
                }
    // The one-light modules do not carry them (their pipelines' creation would pay for the code).
    for (const bool alpha : {false, true}) {
        const LitVariant one{.lightKinds = spot, .specializedLightConstants = true};
        EXPECT_FALSE(specializationIds(litStages(one, alpha).fragment).contains(116u)) << alpha;
        EXPECT_TRUE(specializationIds(litStages(one, alpha).fragment).contains(18u)) << alpha;
    }
}

}  // namespace
}  // namespace shadowlab::raster

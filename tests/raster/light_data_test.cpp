// tests/raster/light_data_test.cpp: the lit pass's per-light uniforms (raster/light_data.h) without
// a device: each named member of LightData and CascadeData against the light, its layers and the
// settings it was made from.
#include "raster/light_data.h"

#include <array>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "raster/tolerances.h"
#include "scene/camera.h"
#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raster {
namespace {

using test::Vec3;

// test::fixedSettings with a filter, kernel and normal offset that are not the defaults, so each
// reaches LightData visibly.
scene::RasterSettings fixedSettings(int mapSize = 512) {
    scene::RasterSettings r = test::fixedSettings(mapSize);
    r.filter = scene::ShadowFilter::Poisson;
    r.pcfSize = 7;
    r.normalOffset = 0.75;
    return r;
}

// Light `index` of `s` as the renderer fills it (camera-relative to the scene's camera), with its
// cascade slots.
struct Filled {
    shaders::LightData light;
    std::array<shaders::CascadeData, SHADOWLAB_MAX_CASCADES> cascades{};
    std::vector<ShadowLayer> layers;
    Vec3 origin;
};
Filled fill(const scene::Scene& s, const scene::RasterSettings& r, int index, double viewDepthOffset = 0.0) {
    Filled f;
    f.origin = scene::cameraBasis(s.camera).position;
    f.layers = planShadowLayers(s, test::planFor(s, r), r, f.origin);
    f.light = lightData(s.lights[std::size_t(index)], index, f.layers, r, f.origin, viewDepthOffset, f.cascades);
    return f;
}

void expectVec3Near(const glm::vec3& got, const Vec3& want, double tolerance) {
    EXPECT_NEAR(got.x, want.x, tolerance);
    EXPECT_NEAR(got.y, want.y, tolerance);
    EXPECT_NEAR(got.z, want.z, tolerance);
}

TEST(LightData, ASpotLightHasTheCosineOfItsHalfAngleItsAxisAndItsMapsRange) {
    scene::Scene s = test::makeScene({});
    s.lights[0] = test::spotDown();  // (0, 8, 0) straight down, half-angle 60°
    s.lights[0].radius = 0.25;
    const scene::RasterSettings r = fixedSettings();
    const Filled f = fill(s, r, 0);
    const shaders::LightData& l = f.light;
    ASSERT_EQ(f.layers.size(), 1u);
    const LightFrustum& map = f.layers[0].frustum;
    EXPECT_EQ(l.kind, SHADOWLAB_LIGHT_SPOT);
    EXPECT_NEAR(l.spotCosCone, 0.5, 1e-7);  // cos 60°
    expectVec3Near(l.spotDirection, {0, -1, 0}, 0.0);
    expectVec3Near(l.position, Vec3(0, 8, 0) - f.origin, 1e-6);
    EXPECT_EQ(l.layer, 0.0f);
    EXPECT_EQ(l.lightSize, 0.5f);  // the diameter
    // The perspective map's near and far along the axis are its frustum's.
    EXPECT_EQ(l.mapNear, float(map.near));
    EXPECT_EQ(l.mapFar, float(map.far));
    EXPECT_LE(l.mapNear, 6.5f);  // the sphere's top (y = 1.5), a caster, lies 6.5 below the light
    // A perspective map of N texels over tan −t..t: 2t/N per unit of distance along the axis.
    EXPECT_NEAR(l.texelWorldSize, 2.0 * map.tanHalfFov / 512.0, 1e-7 * l.texelWorldSize);  // float
    EXPECT_EQ(l.depthBiasWorld, 0.01f);
    EXPECT_EQ(l.slopeBiasTexels, 1.5f);
    // The map matrix takes the light's own position to the map's center ray: (u, v) = (0.5, 0.5)
    // for any point on the axis, here 3 units below the light.
    const glm::vec4 c = l.toShadow * glm::vec4(l.position + 3.0f * l.spotDirection, 1.0f);
    EXPECT_NEAR(c.x / c.w, 0.5, 1e-6);
    EXPECT_NEAR(c.y / c.w, 0.5, 1e-6);
    // The members of other kinds stay zero.
    EXPECT_EQ(l.pointFaceTan, 0.0f);
    EXPECT_EQ(l.cascadeCount, 0);
    EXPECT_EQ(l.depthPerWorld, 0.0f);
    EXPECT_EQ(l.towardLight, glm::vec3(0.0f));
    for (const shaders::PointFace& face : l.pointFaces) EXPECT_EQ(face.near, 0.0f);
}

TEST(LightData, APointLightHasTheFacesTangentAndEachFacesRangeByFace) {
    scene::Scene s = test::makeScene({});
    scene::Light p;
    p.type = scene::LightType::Point;
    p.position = {0.5, 3, -0.25};
    p.intensity = 30.0;
    p.radius = 0.1;
    s.lights[0] = p;
    const scene::RasterSettings r = fixedSettings(512);
    const Filled f = fill(s, r, 0);
    const shaders::LightData& l = f.light;
    EXPECT_EQ(l.kind, SHADOWLAB_LIGHT_POINT);
    expectVec3Near(l.position, p.position - f.origin, 1e-6);
    EXPECT_NEAR(l.lightSize, 0.2, 1e-7);
    // A face's 90° edge (tan 1) lies (N/2)/t texels from its center when the N texels span tan
    // −t..t; the face reaches m = kPointFaceMarginTexels past it: N/2 − N/(2t) = m, t = N/(N − 2m).
    EXPECT_NEAR(l.pointFaceTan, 512.0 / (512.0 - 2.0 * kPointFaceMarginTexels), 1e-6);
    // Six layers, one per face, in face order after the light's first layer; each face's own near
    // and far sit under its face index.
    ASSERT_EQ(f.layers.size(), 6u);
    EXPECT_EQ(l.layer, 0.0f);
    for (const ShadowLayer& layer : f.layers) {
        ASSERT_EQ(layer.reason, LayerReason::kCubeFace);
        const shaders::PointFace& face = l.pointFaces[layer.index];
        EXPECT_EQ(face.near, float(layer.frustum.near)) << layer.label;
        EXPECT_EQ(face.far, float(layer.frustum.far)) << layer.label;
        EXPECT_LT(face.near, face.far) << layer.label;
    }
    // The sphere's top (0, 1.5, 0), a caster inside the −Y face (index 3), lies 1.5 below the
    // light along that face's axis, so that face's map cannot start past it.
    EXPECT_LE(l.pointFaces[3].near, 1.5f);
    // Each face's projection is built in lit.frag: no matrix, and mapNear/mapFar are set there.
    EXPECT_EQ(l.toShadow, glm::mat4(0.0f));
    EXPECT_EQ(l.mapNear, 0.0f);
    EXPECT_EQ(l.mapFar, 0.0f);
    EXPECT_EQ(l.spotCosCone, 0.0f);
}

TEST(LightData, ADirectionalLightPointsTowardTheLightAndCarriesTheSettings) {
    scene::Scene s = test::makeScene({});
    s.lights[0].color = {1.0, 0.5, 0.0};
    s.lights[0].intensity = 3.0;
    const scene::RasterSettings r = fixedSettings(1024);
    const Filled f = fill(s, r, 0);
    const shaders::LightData& l = f.light;
    ASSERT_EQ(f.layers.size(), 1u);
    const LightFrustum& map = f.layers[0].frustum;
    EXPECT_EQ(l.kind, SHADOWLAB_LIGHT_DIRECTIONAL);
    expectVec3Near(l.towardLight, {0, 1, 0}, 0.0);  // the light travels straight down
    EXPECT_EQ(l.cascadeCount, 0);
    // color · intensity, and intensity · mean color = 3 · 0.5.
    expectVec3Near(l.radiance, {3.0, 1.5, 0.0}, 0.0);
    EXPECT_EQ(l.visibilityWeight, 1.5f);
    // An orthographic map of N texels over 2·halfWidth, its depth 0..1 over the depth range.
    EXPECT_NEAR(l.texelWorldSize, 2.0 * map.halfWidth / 1024.0, 1e-7 * l.texelWorldSize);
    EXPECT_NEAR(l.depthPerWorld, 1.0 / map.depthRange(), 1e-6 / map.depthRange());
    EXPECT_EQ(l.depthBiasWorld, 0.01f);
    EXPECT_EQ(l.slopeBiasTexels, 1.5f);
    // The settings every light shares.
    EXPECT_EQ(l.filterCode, SHADOWLAB_FILTER_POISSON);
    EXPECT_EQ(l.pcfSize, 7);
    EXPECT_EQ(l.normalOffsetTexels, 0.75f);
    EXPECT_EQ(l.maxSlopeTan, float(kMaxSlopeTan));
    // The members of other kinds stay zero.
    EXPECT_EQ(l.position, glm::vec3(0.0f));
    EXPECT_EQ(l.spotDirection, glm::vec3(0.0f));
    EXPECT_EQ(l.lightSize, 0.0f);
    EXPECT_EQ(l.pointFaceTan, 0.0f);
}

TEST(LightData, ACascadedLightFillsEachCascadeAndTakesCascadeZerosMap) {
    const scene::Scene s = test::makeLongPlane(64, 36);
    scene::RasterSettings r = fixedSettings(1024);
    r.cascades = 3;
    const double viewDepthOffset = 0.25;
    const Filled f = fill(s, r, 0, viewDepthOffset);
    const shaders::LightData& l = f.light;
    ASSERT_EQ(f.layers.size(), 3u);
    EXPECT_EQ(l.cascadeCount, 3);
    EXPECT_EQ(l.layer, 0.0f);
    for (std::size_t c = 0; c < 3; ++c) {
        const ShadowLayer& layer = f.layers[c];
        const shaders::CascadeData& cd = f.cascades[c];
        // The slice's far end in lit.frag's view depth (taken from the origin, not the camera).
        EXPECT_EQ(cd.sliceFar, float(layer.sliceFar - viewDepthOffset)) << c;
        EXPECT_NEAR(cd.texelWorldSize, 2.0 * layer.frustum.halfWidth / 1024.0, 1e-7 * cd.texelWorldSize) << c;
        EXPECT_EQ(cd.depthPerWorld, float(1.0 / layer.frustum.depthRange())) << c;
        EXPECT_EQ(cd.depthBiasWorld, float(layer.shaderDepthBias)) << c;
        EXPECT_EQ(cd.toShadow, glm::mat4(layer.frustum.toTexture(f.origin))) << c;
    }
    // Nearer slices end nearer and have finer texels.
    EXPECT_LT(f.cascades[0].sliceFar, f.cascades[1].sliceFar);
    EXPECT_LT(f.cascades[0].texelWorldSize, f.cascades[2].texelWorldSize);
    // Past the count the slots stay empty.
    EXPECT_EQ(f.cascades[3].sliceFar, 0.0f);
    // The light's own map members are cascade 0's.
    EXPECT_EQ(l.toShadow, f.cascades[0].toShadow);
    EXPECT_EQ(l.texelWorldSize, f.cascades[0].texelWorldSize);
    EXPECT_EQ(l.depthPerWorld, f.cascades[0].depthPerWorld);
    EXPECT_EQ(l.depthBiasWorld, f.cascades[0].depthBiasWorld);
}

TEST(LightData, ALightsLayerFollowsTheLayersOfTheLightsBeforeIt) {
    // A directional light (one map, layer 0), then a point light (six faces, layers 1..6).
    scene::Scene s = test::makeScene({});
    scene::Light p;
    p.type = scene::LightType::Point;
    p.position = {0, 3, 0};
    p.intensity = 30.0;
    s.lights.push_back(p);
    const scene::RasterSettings r = fixedSettings();
    const Filled directional = fill(s, r, 0);
    const Filled point = fill(s, r, 1);
    ASSERT_EQ(point.layers.size(), 7u);
    EXPECT_EQ(directional.light.layer, 0.0f);
    EXPECT_EQ(point.light.layer, 1.0f);
    for (std::size_t k = 1; k < 7; ++k) {
        const ShadowLayer& layer = point.layers[k];
        EXPECT_EQ(std::size_t(layer.index), k - 1);  // +X −X +Y −Y +Z −Z follow the first
        EXPECT_EQ(point.light.pointFaces[layer.index].far, float(layer.frustum.far));
    }
}

TEST(LightData, ALightWithoutLayersHasNoShadowTest) {
    const scene::Scene s = test::makeScene({});
    std::array<shaders::CascadeData, SHADOWLAB_MAX_CASCADES> cascades{};
    const shaders::LightData l = lightData(s.lights[0], 0, {}, fixedSettings(), Vec3(0.0), 0.0, cascades);
    EXPECT_EQ(l.layer, -1.0f);  // lit.frag skips the shadow test below 0
    expectVec3Near(l.towardLight, {0, 1, 0}, 0.0);
    EXPECT_EQ(l.cascadeCount, 0);
}

}  // namespace
}  // namespace shadowlab::raster

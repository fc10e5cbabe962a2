// tests/raster/pipeline_test.cpp: the graphics pipelines (raster/pipeline.cpp) on lavapipe with the
// validation layer: every pipeline a render can ask for is created without a message (the layer
// checks each one's vertex inputs, outputs, descriptors, push constants and specialization against
// its shaders); the dynamic depth bias adds the constant factor in units of r to the stored depth;
// a format the device lacks is refused, naming it.
#include "raster/pipeline.h"

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "raster/alpha_casters.h"
#include "raster/geometry.h"
#include "raster/light_frustum.h"
#include "raster/lit_pass.h"
#include "raster/moment_maps.h"
#include "raster/shadow_pass.h"
#include "raster/vulkan_error.h"
#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raster {
namespace {

using test::Vec3;

// A scene with an alpha-tested caster, for the pipelines' SHADOWLAB_ALPHA variants.
scene::Scene alphaScene() {
    scene::Scene s = test::makeScene(test::SphereOverPlane{});
    s.materials.push_back(test::alphaMaterial("leaf", scene::AlphaMode::Mask, test::checkerTexture(2, 1.0f, 0.0f)));
    test::addQuad(s, Vec3(0, 2, 0), Vec3(0, 1, 0), 1, 1, 1);
    return s;
}

TEST(RasterPipeline, EveryPipelineARenderAsksForIsCreatedWithoutValidationMessages) {
    test::ValidatedContext vc;
    const Context& ctx = vc.get();
    const scene::Scene s = alphaScene();
    ASSERT_TRUE(planAlpha(s, false).data);
    const SceneGeometry g = tessellateScene(s, s.camera.position, true);
    const AlphaCasters alpha = createAlphaCasters(ctx, s, g);
    const VkDescriptorSetLayout alphaLayout = alpha.descriptors.layout.get();

    // The depth pass: with and without blocker ids, the hardware bias, the alpha test.
    for (const bool ids : {false, true})
        for (const bool hardwareBias : {false, true})
            for (const VkDescriptorSetLayout layout : {VkDescriptorSetLayout(VK_NULL_HANDLE), alphaLayout}) {
                const ShadowPipeline p = createShadowPipeline(ctx, ids, hardwareBias, layout);
                EXPECT_TRUE(p.pipeline) << ids << hardwareBias << (layout != VK_NULL_HANDLE);
                EXPECT_EQ(p.hardwareBias, hardwareBias);
                EXPECT_EQ(p.alpha, layout != VK_NULL_HANDLE);
            }
    // Semi-transparent casters (both passes) and the filterable maps' compute passes.
    const ShadowMaps maps = createShadowMaps(ctx, 64, 2);
    const TransmittanceMaps transmittance = createTransmittanceMaps(ctx, 64, 2);
    const MomentMaps moments = createMomentMaps(ctx, 64, 2);
    for (const VkDescriptorSetLayout layout : {VkDescriptorSetLayout(VK_NULL_HANDLE), alphaLayout}) {
        EXPECT_TRUE(createTransmittancePipeline(ctx, layout).pipeline);
        EXPECT_TRUE(createTransmittanceRestPipeline(ctx, transmittance, layout).pipeline);
    }
    scene::MomentSettings wide;
    wide.blurWidth = 63;  // the widest blur: the x and y passes unroll 63 taps
    for (const scene::ShadowFilter f : {scene::ShadowFilter::Vsm, scene::ShadowFilter::Evsm2,
                                        scene::ShadowFilter::Evsm4, scene::ShadowFilter::Esm, scene::ShadowFilter::Msm})
        for (const scene::MomentSettings& m : {scene::MomentSettings{}, wide}) {
            const MomentPipeline p = createMomentPipeline(ctx, maps, moments, f, m);
            EXPECT_TRUE(p.pipeline) << scene::toString(f) << m.blurWidth;
            EXPECT_TRUE(p.blurPipeline) << scene::toString(f) << m.blurWidth;
        }

    // The lit pass: every filter once, each beside another option the renderer sets from the plan
    // and the frame's channels (renderer.cpp: the channels pick the targets, the scene's lights the
    // kinds and counts, the settings the rest).
    constexpr std::uint32_t kDirectional = 1u << SHADOWLAB_LIGHT_DIRECTIONAL, kSpot = 1u << SHADOWLAB_LIGHT_SPOT,
                            kPoint = 1u << SHADOWLAB_LIGHT_POINT;
    using F = scene::ShadowFilter;
    const LitVariant variants[] = {
        {},  // the default: pcf2x2, one directional light, every target
        {.filter = F::None, .blockerIds = false, .aovTarget = false},   // beauty and visibility only
        {.filter = F::Pcf, .aovTarget = false, .displayTarget = true},  // the 8-bit display target
        {.filter = F::Poisson,
         .lightTargets = kLightTargets,
         .lightCount = 3,
         .lightKinds = kDirectional | kSpot | kPoint},
        {.filter = F::Pcss, .lightKinds = kSpot, .receiverPlane = true},
        {.filter = F::Vsm, .cascades = 3, .cascadeBlend = true},
        {.filter = F::Evsm2, .transmittance = true},
        {.filter = F::Evsm4, .vertexLightConstants = true},
        {.filter = F::Esm, .lightKinds = kPoint},
        {.filter = F::Msm, .normalOffset = false},
        {.lightKinds = kSpot, .vertexLightConstants = true},
    };
    for (LitVariant v : variants) {
        SCOPED_TRACE(scene::toString(v.filter));
        v.beautyFormat = litBeautyFormat(ctx, false);  // as the renderer sets it from its targets
        const LitPipeline plain = createLitPipeline(ctx, v);
        EXPECT_TRUE(plain.pipeline);
        EXPECT_FALSE(plain.alpha);
        // The camera's alpha test (scenes with MASK or BLEND materials) of the same variant.
        const LitPipeline withAlpha = createLitPipeline(ctx, v, alphaLayout);
        EXPECT_TRUE(withAlpha.pipeline);
        EXPECT_TRUE(withAlpha.alpha);
    }
}

TEST(RasterPipeline, TheDynamicDepthBiasAddsTheConstantFactorInUnitsOfR) {
    // A 2 x 2 quad at y = 0 and a small box whose top is at y = 3, light straight down, the
    // bounding-sphere map (center (0, 1.5, 0), depth (t + h)/2h with t the distance along the light
    // from the center and h its half-width, 1.01 · √17/2 = 2.08): the quad at depth
    // (1.5 + h)/2h = 0.86, the box's top at (−1.5 + h)/2h = 0.14. A pipeline with the dynamic depth
    // bias, given the constant factor C = 256 and slope 0, adds C·r to each stored depth, where r
    // is D32_SFLOAT's step at the primitive's depth, 2^(e − 23) for its exponent e (Vulkan spec,
    // "Depth Bias"): 2^−24 in [0.5, 1), so 2^−16 on the quad; 2^−26 in [0.125, 0.25), so 2^−18 on
    // the box's top. Without the dynamic bias the same factors change nothing.
    test::ValidatedContext vc;
    const Context& ctx = vc.get();
    scene::Scene s;
    test::addMaterial(s, "matte");
    test::addQuad(s, Vec3(0), Vec3(0, 1, 0), 2, 2);
    test::addBox(s, Vec3(-0.1, 2.9, -0.1), Vec3(0.1, 3.0, 0.1));
    const Vec3 dir(0, -1, 0), origin(0);
    constexpr int size = 128;
    const LightFrustum f = fitDirectionalLight(s.bounds(), dir, size);
    const double zQuad = (glm::dot(Vec3(0) - f.center, dir) + f.halfWidth) / (2 * f.halfWidth);
    const double zTop = (glm::dot(Vec3(0, 3, 0) - f.center, dir) + f.halfWidth) / (2 * f.halfWidth);
    ASSERT_NEAR(zQuad, 0.86, 0.01);
    ASSERT_NEAR(zTop, 0.14, 0.01);
    const SceneGeometry g = tessellateScene(s, origin);
    const Buffer vb = uploadBuffer(ctx, g.vertices, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
    const Buffer ib = uploadBuffer(ctx, g.indices, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
    const DrawGeometry draw{vb.buffer.get(), ib.buffer.get(), std::uint32_t(g.indices.size())};
    const std::vector<DepthBiasFactors> bias = {{.constant = 256.0f, .slope = 0.0f}};
    auto depths = [&](bool hardwareBias) {
        const ShadowPipeline pipeline = createShadowPipeline(ctx, false, hardwareBias);
        const ShadowMaps maps = createShadowMaps(ctx, size, 1);
        VkCommandBuffer commands = ctx.beginCommands();
        recordShadowPass(commands, pipeline, maps, draw, {glm::mat4(f.toClip(origin))}, false, nullptr, &bias);
        ctx.submitAndWait(commands);
        return readShadowMap(ctx, maps, 0);
    };
    const std::vector<float> plain = depths(false), biased = depths(true);
    int quad = 0, top = 0, other = 0, wrong = 0;
    for (std::size_t i = 0; i < plain.size(); ++i) {
        double expected = 0.0;
        if (std::abs(plain[i] - zQuad) < 1e-6)
            ++quad, expected = std::ldexp(1.0, -16);
        else if (std::abs(plain[i] - zTop) < 1e-6)
            ++top, expected = std::ldexp(1.0, -18);
        else
            ++other;  // empty (1, unbiased: nothing drawn) or the box's sides at the outline
        if (expected > 0.0 && std::abs(double(biased[i]) - double(plain[i]) - expected) > 1e-3 * expected) ++wrong;
        if (expected == 0.0 && plain[i] == 1.0f && biased[i] != 1.0f) ++wrong;
    }
    // The quad covers 2/4.16 of the map's width, (128·0.48)² ≈ 3500 texels; the top 0.2 of it,
    // about 36.
    EXPECT_GT(quad, 3000);
    EXPECT_GT(top, 20);
    EXPECT_EQ(wrong, 0);
}

TEST(RasterPipeline, AMissingFormatFeatureIsRefusedNamingTheDeviceTheFormatAndThePurpose) {
    test::ValidatedContext vc;
    const Context& ctx = vc.get();
    EXPECT_NO_THROW(requireFormat(ctx, VK_FORMAT_D32_SFLOAT, VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT, "depth"));
    // An 8-bit color format is never a depth attachment (VK_FORMAT_R8G8B8A8_UNORM is 37).
    try {
        requireFormat(ctx, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT, "a test's depth");
        FAIL() << "expected RasterError";
    } catch (const RasterError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(ctx.deviceReport.name), std::string::npos) << what;
        EXPECT_NE(what.find("format 37"), std::string::npos) << what;
        EXPECT_NE(what.find("a test's depth"), std::string::npos) << what;
        EXPECT_NE(what.find("--device"), std::string::npos) << what;
    }
}

TEST(RasterPipeline, ALitPipelineForABeautyFormatTheDeviceCannotRenderIntoIsRefusedBeforeTheDriverSeesIt) {
    // A block-compressed format is never a color attachment (VK_FORMAT_BC1_RGB_UNORM_BLOCK is 131);
    // a pipeline for it would be invalid usage, and the validated context would count a message.
    test::ValidatedContext vc;
    const Context& ctx = vc.get();
    try {
        createLitPipeline(ctx, LitVariant{.beautyFormat = VK_FORMAT_BC1_RGB_UNORM_BLOCK});
        FAIL() << "expected RasterError";
    } catch (const RasterError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("format 131"), std::string::npos) << what;
        EXPECT_NE(what.find("beauty target"), std::string::npos) << what;
    }
}

}  // namespace
}  // namespace shadowlab::raster

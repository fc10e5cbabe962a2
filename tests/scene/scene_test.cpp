// tests/scene/scene_test.cpp: small queries on the scene model (scene/scene.cpp).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "scene/loader.h"
#include "scene/scene.h"

using namespace shadowlab;
using Json = nlohmann::json;

namespace {

// Every key a "shadow" block accepts, each with a valid value; `second` picks another valid value
// for each, so that every field of the two parsed blocks differs.
Json everyShadowKey(bool second) {
    return Json{{"shadow_map_size", second ? 1024 : 512},
                {"depth_bias", second ? 0.02 : 0.01},
                {"slope_bias", second ? 3.0 : 2.0},
                {"filter", second ? "vsm" : "pcf"},
                {"pcf_size", second ? 5 : 3},
                {"min_variance", second ? 1e-4 : 1e-5},
                {"light_bleeding_reduction", second ? 0.3 : 0.2},
                {"evsm_positive_exponent", second ? 30.0 : 20.0},
                {"evsm_negative_exponent", second ? 8.0 : 5.0},
                {"esm_exponent", second ? 60.0 : 40.0},
                {"moment_bias", second ? 3e-5 : 2e-5},
                {"blur_width", second ? 9 : 5},
                {"normal_offset", second ? 1.5 : 1.0},
                {"receiver_plane_bias", second},
                {"hardware_bias", second},
                {"fit_light_frustum", second},
                {"cascades", second ? 3 : 2},
                {"cascade_blend", second ? 0.2 : 0.1},
                {"ray_bias", second ? 0.002 : 0.001},
                {"precision", second ? "double" : "float"},
                {"samples", second ? 16 : 8}};
}

scene::ShadowDefaults parse(const Json& block) { return scene::readShadowBlock("test.json", block, scene::JsonPath()); }

}  // namespace

// A block that sets every key replaces every field: a field the merge forgot would keep the first
// block's value, and the two would differ.
TEST(ShadowDefaults, AnOverrideThatSetsEveryKeyReplacesEveryField) {
    const scene::ShadowDefaults first = parse(everyShadowKey(false));
    const scene::ShadowDefaults second = parse(everyShadowKey(true));
    ASSERT_NE(first, second);
    EXPECT_EQ(first.overriddenBy(second), second);
}

TEST(ShadowDefaults, AnEmptyOverrideKeepsEveryField) {
    const scene::ShadowDefaults first = parse(everyShadowKey(false));
    EXPECT_EQ(first.overriddenBy(scene::ShadowDefaults{}), first);
}

// "ray_bias" is one key with two forms: "robust" over a number drops the number, and back.
TEST(ShadowDefaults, RayBiasIsOneKeyInEitherForm) {
    const scene::ShadowDefaults number = parse(Json{{"ray_bias", 0.001}});
    const scene::ShadowDefaults robust = parse(Json{{"ray_bias", "robust"}});
    const scene::ShadowDefaults a = number.overriddenBy(robust);
    EXPECT_FALSE(a.rayBias.has_value());
    EXPECT_TRUE(a.robustRayOffset.value_or(false));
    const scene::ShadowDefaults b = robust.overriddenBy(number);
    EXPECT_EQ(b.rayBias, 0.001);
    EXPECT_FALSE(b.robustRayOffset.value_or(false));
}

// --- alpha tests that can never fire --------------------------------------------------------

namespace {

scene::Material maskMaterial(double factor, double cutoff, std::vector<float> texels = {}) {
    scene::Material m;
    m.alphaMode = scene::AlphaMode::Mask;
    m.alphaFactor = factor;
    m.alphaCutoff = cutoff;
    if (!texels.empty()) {
        auto t = std::make_shared<scene::AlphaTexture>();
        t->width = int(texels.size());
        t->height = 1;
        t->alpha = std::move(texels);
        m.alphaTexture = t;
    }
    return m;
}

}  // namespace

TEST(MaterialAlpha, AConstantAlphaFallsBelowACutoffOnlyWhenItIsBelowIt) {
    // Without a texture alpha(uv) is the factor everywhere (glTF baseColorFactor[3]).
    EXPECT_FALSE(maskMaterial(1.0, 0.5).alphaCanFallBelow(0.5));
    EXPECT_FALSE(maskMaterial(0.5, 0.5).alphaCanFallBelow(0.5));  // at the cutoff is not below it
    EXPECT_TRUE(maskMaterial(0.4, 0.5).alphaCanFallBelow(0.5));
    EXPECT_TRUE(maskMaterial(0.0, 0.5).alphaCanFallBelow(0.5));
}

TEST(MaterialAlpha, ATextureFallsBelowWhereItsSmallestTexelTimesTheFactorDoes) {
    EXPECT_FALSE(maskMaterial(1.0, 0.5, {1.0f, 0.9f, 0.5f}).alphaCanFallBelow(0.5));
    EXPECT_TRUE(maskMaterial(1.0, 0.5, {1.0f, 0.49f, 1.0f}).alphaCanFallBelow(0.5));
    EXPECT_TRUE(maskMaterial(0.5, 0.5, {1.0f, 0.9f}).alphaCanFallBelow(0.5));   // 0.45 < 0.5
    EXPECT_FALSE(maskMaterial(0.8, 0.5, {0.7f, 1.0f}).alphaCanFallBelow(0.5));  // 0.56
    // Outside the loaders' [0, 1] (a scene made in code) no claim is made: with a factor of −1 the
    // texel 1 gives −1, below a cutoff of 0, although the smallest texel's product (0) is not.
    EXPECT_TRUE(maskMaterial(-1.0, 0.0, {0.0f, 1.0f}).alphaCanFallBelow(0.0));
    EXPECT_TRUE(maskMaterial(2.0, 0.5, {1.0f}).alphaCanFallBelow(0.5));
    // An OPAQUE material ignores its texture: alpha is the factor.
    scene::Material opaque = maskMaterial(1.0, 0.5, {0.0f});
    opaque.alphaMode = scene::AlphaMode::Opaque;
    EXPECT_FALSE(opaque.alphaCanFallBelow(0.5));
}

TEST(MaterialAlpha, EitherPrecisionsProductBelowTheCutoffCounts) {
    // The texel 0.7f is 0.699999988: in float it equals the cutoff 0.7 rounded to float, so the
    // shaders' test passes it, but the reference's double product is below 0.7 and cuts it.
    EXPECT_LT(double(0.7f), 0.7);
    EXPECT_FALSE(0.7f < float(0.7));
    EXPECT_TRUE(maskMaterial(1.0, 0.7, {0.7f}).alphaCanFallBelow(0.7));
    // The other way round: 0.228225 · (200/255) is 0.179000003 in double, at or above a cutoff
    // of 0.179, but the float product rounds to 0.17899999 below float(0.179).
    const float texel = 200.0f / 255.0f;
    EXPECT_GE(0.228225 * double(texel), 0.179);
    EXPECT_LT(float(0.228225) * texel, float(0.179));
    EXPECT_TRUE(maskMaterial(0.228225, 0.179, {texel}).alphaCanFallBelow(0.179));
}

// tests/studies/path_test.cpp: frames along paths on lavapipe with the validation layer: a raster
// Renderer moved by update() draws what a fresh one draws; snapped fitted maps hold still under
// sub-texel camera moves (bit-identical maps, no flicker) where unsnapped ones flicker; a cascade
// seam under a dolly with and without blending; the ray tracer reused across cameras; and the
// path folder (journal, resume, outputs).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <unistd.h>

#include <gtest/gtest.h>

#include "compare/compare.h"
#include "compare/temporal.h"
#include "compare/text.h"
#include "raster/light_frustum.h"
#include "raster/renderer.h"
#include "raytrace/renderer.h"
#include "scene/error.h"
#include "studies/path.h"
#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::studies {
namespace {

namespace fs = std::filesystem;
using scene::Vec3;
using shadowlab::test::SphereOverPlane;

scene::RenderSettings settingsFor(const scene::Scene& s, int mapSize) {
    scene::RenderSettings settings = scene::resolveSettings(s, {});
    settings.raster.shadowMapSize = mapSize;
    settings.raster.shadowMapSizeIsDefault = false;
    settings.raster.depthBias = scene::defaultDepthBias(s, mapSize);
    settings.raster.depthBiasIsDefault = true;
    settings.raster.validate = true;
    return settings;
}

scene::Scene slantedSphere(int width, int height) {
    SphereOverPlane p;
    p.lightDirection = Vec3(-1, -2, -1);
    p.width = width;
    p.height = height;
    return shadowlab::test::makeScene(p);
}

// The same with a plane that shades itself (a mesh), so that every visible point of it is a receiver
// the fitted map must hold, and the map follows the camera as it moves (over a quad it would hold
// only the fixed region under the sphere, and not move at all).
scene::Scene slantedSphereOverAShadingPlane(int width, int height) {
    scene::Scene s = slantedSphere(width, height);
    shadowlab::test::makeGroundShadeItself(s, 1);
    return s;
}

std::vector<const scene::Frame*> pointers(const std::vector<scene::Frame>& frames) {
    std::vector<const scene::Frame*> p;
    for (const scene::Frame& f : frames) p.push_back(&f);
    return p;
}

TEST(RasterRendererUpdate, UpdatingToTheSameSceneRendersTheSameFrameBitForBit) {
    const scene::Scene s = slantedSphere(96, 54);
    const scene::RenderSettings settings = settingsFor(s, 256);
    raster::Renderer r(s, scene::makeRenderPlan(s, settings), settings.raster);
    const scene::Frame before = r.render();
    r.update(s);
    const scene::Frame after = r.render();
    EXPECT_EQ(before.visibility, after.visibility);
    EXPECT_EQ(before.beauty, after.beauty);
    EXPECT_EQ(before.depth, after.depth);
    EXPECT_GT(after.timing("update"), 0.0);
    EXPECT_EQ(after.timing("setup"), 0.0);
    EXPECT_EQ(r.validationMessages(), 0);
}

// A Renderer made for frame 0 and moved to another camera keeps its vertices relative to frame
// 0's camera, so it is not bit-identical to a Renderer made for the new camera, but within float
// rounding: the same objects, the same shadows, the same view depth on the plane `planeId` (spheres
// keep frame 0's tessellation, which follows the camera's distance, so their depth may differ).
void expectSameImage(const scene::Frame& moved, const scene::Frame& fresh, float planeId) {
    ASSERT_EQ(moved.pixelCount(), fresh.pixelCount());
    std::size_t sameId = 0, both = 0, agree = 0;
    std::vector<double> depthErrors;
    for (std::size_t i = 0; i < moved.pixelCount(); ++i) {
        if (moved.objectId[i] != fresh.objectId[i]) continue;
        ++sameId;
        if (fresh.objectId[i] == 0) continue;
        ++both;
        agree += std::abs(moved.visibility[i] - fresh.visibility[i]) <= 0.5f;
        if (fresh.objectId[i] == planeId)
            depthErrors.push_back(std::abs(double(moved.depth[i]) - fresh.depth[i]) / fresh.depth[i]);
    }
    EXPECT_GE(double(sameId), 0.998 * double(moved.pixelCount()));
    EXPECT_GE(double(agree), 0.998 * double(both));
    // The depth offset is applied: without it Z is off by the move (a relative error of ~0.1 or
    // more). At grazing view one float rounding of a vertex moves a pixel's depth by more than
    // 1e-4, so the bound is on the 99th percentile.
    std::sort(depthErrors.begin(), depthErrors.end());
    ASSERT_FALSE(depthErrors.empty());
    EXPECT_LT(depthErrors[depthErrors.size() * 99 / 100], 1e-4);
}

TEST(RasterRendererUpdate, AMovedCameraDrawsWhatAFreshRendererForThatCameraDraws) {
    const scene::Scene s0 = slantedSphere(96, 54);
    scene::Scene s1 = s0;
    s1.camera.position += Vec3(0.7, -0.4, -1.1);  // dolly in and to the side
    s1.camera.lookAt += Vec3(0.2, 0.0, 0.0);
    scene::RenderSettings settings = settingsFor(s0, 256);
    settings.raster.fitLightFrustum = true;
    raster::Renderer moved(s0, scene::makeRenderPlan(s0, settings), settings.raster);
    moved.render();
    moved.update(s1);
    const scene::Frame a = moved.render();
    const scene::Frame b = shadowlab::test::renderChecked(s1, settings.raster);
    EXPECT_EQ(a.attributes.at("light_frustum"), b.attributes.at("light_frustum"));
    expectSameImage(a, b, 2.0f);
    EXPECT_EQ(moved.validationMessages(), 0);
}

TEST(RasterRendererUpdate, CascadesFollowTheMovedCameraAsAFreshRenderersDo) {
    const scene::Scene s0 = shadowlab::test::makeLongPlane(96, 54);
    scene::Scene s1 = s0;
    s1.camera.position += 0.2 * (s0.camera.lookAt - s0.camera.position);  // dolly in
    scene::RenderSettings settings = settingsFor(s0, 512);
    settings.raster.cascades = 3;
    settings.raster.cascadeBlend = 0.2;
    raster::Renderer moved(s0, scene::makeRenderPlan(s0, settings), settings.raster);
    moved.render();
    moved.update(s1);
    const scene::Frame a = moved.render();
    const scene::Frame b = shadowlab::test::renderChecked(s1, settings.raster);
    EXPECT_EQ(a.attributes.at("cascade_splits"), b.attributes.at("cascade_splits"));
    EXPECT_EQ(a.attributes.at("light_frustum"), b.attributes.at("light_frustum"));
    expectSameImage(a, b, 1.0f);
    EXPECT_EQ(moved.validationMessages(), 0);
}

TEST(RasterRendererUpdate, AChangeThatNeedsOtherMapsIsRefused) {
    const scene::Scene s0 = shadowlab::test::makeLongPlane(64, 36);
    scene::Scene s1 = s0;
    s1.camera.lookAt = s0.camera.position + Vec3(0, 0, 10);  // looks away: no cascades, one map
    scene::RenderSettings settings = settingsFor(s0, 256);
    settings.raster.cascades = 3;
    raster::Renderer r(s0, scene::makeRenderPlan(s0, settings), settings.raster);
    EXPECT_THROW(r.update(s1), raster::RasterError);
    scene::Scene s2 = s0;
    s2.camera.width = 32;
    EXPECT_THROW(r.update(s2), raster::RasterError);
}

TEST(RaytraceRenderer, OneAccelerationStructureRendersEveryCameraAsAFreshOne) {
    const scene::Scene s0 = slantedSphere(64, 36);
    scene::Scene s1 = s0;
    s1.camera.position += Vec3(1.0, 0.5, 0.0);
    s1.lights[0].direction = glm::normalize(Vec3(-1, -3, 0.5));
    const scene::RenderSettings settings = settingsFor(s0, 256);
    const raytrace::Renderer reference(s0, settings.raytrace, true);
    const scene::RenderPlan plan = scene::makeRenderPlan(s1, settings);
    const scene::Frame a = reference.render(s1, plan);
    const scene::Frame b = raytrace::renderReference(s1, plan, settings.raytrace);
    EXPECT_EQ(a.visibility, b.visibility);
    EXPECT_EQ(a.beauty, b.beauty);
    EXPECT_EQ(a.attributes.at("backend"), "reference");
    EXPECT_EQ(a.timing("setup"), 0.0);
}

// Sub-texel camera steps, drawn from frame 0's camera (the held view: the image does not move, so
// any change is the map's). Snapped: every frame's fitted map is the same frustum, the maps are
// bit-identical and nothing flickers. Unsnapped: the map follows the receivers by a fraction of a
// texel each frame, and the filtered edge flickers.
struct HeldPath {
    std::vector<raster::LightFrustum> frusta;
    std::vector<std::vector<float>> maps;  // layer 0 of every frame
    compare::TemporalSummary temporal;
};

constexpr int kHeldMapSize = 128;

std::vector<scene::Scene> subTexelScenes(double startShift, const scene::RenderSettings& settings) {
    scene::Scene base = slantedSphereOverAShadingPlane(128, 72);
    const scene::CameraBasis cam = scene::cameraBasis(base.camera);
    const Vec3 along = glm::normalize(cam.right + cam.up);  // the path's own direction
    base.camera.position += startShift * along;
    base.camera.lookAt += startShift * along;
    PathSpec spec;
    spec.kind = PathKind::SubTexel;
    spec.frames = 6;
    spec.amount = 0.1;  // a tenth of min(texel, pixel) a frame: half of one over the path
    return pathScenes(base, settings, spec);
}

bool sameFrustum(const raster::LightFrustum& a, const raster::LightFrustum& b) {
    return a.center == b.center && a.halfWidth == b.halfWidth && a.nearDepth == b.nearDepth && a.farDepth == b.farDepth;
}

// A snapped map changes where the receivers' center crosses a texel's rounding boundary (a jump of
// one whole texel) or their size a size step: the start, moved along the path's direction in
// twentieths of a texel, where the fitting rule keeps one frustum over the whole path.
double startInsideOneSnapStep(const scene::RenderSettings& settings) {
    const scene::Scene probe = slantedSphereOverAShadingPlane(128, 72);
    const double texel = subTexelStep(probe, settings.raster, 1.0).texel;
    for (int k = 0; k < 40; ++k) {
        const std::vector<scene::Scene> scenes = subTexelScenes(0.05 * k * texel, settings);
        bool still = true;
        const raster::LightFrustum f0 =
            raster::fitDirectionalLightToReceivers(scenes[0], scenes[0].lights[0].direction, kHeldMapSize, true);
        for (const scene::Scene& s : scenes)
            still =
                still &&
                sameFrustum(raster::fitDirectionalLightToReceivers(s, s.lights[0].direction, kHeldMapSize, true), f0);
        if (still) return 0.05 * k * texel;
    }
    ADD_FAILURE() << "no start within two texels keeps the snapped frustum over the path";
    return 0.0;
}

HeldPath heldSubTexelPath(bool snap, double startShift) {
    scene::RenderSettings settings = settingsFor(slantedSphereOverAShadingPlane(128, 72), kHeldMapSize);
    settings.raster.fitLightFrustum = true;
    settings.raster.snapLightFrustum = snap;
    const std::vector<scene::Scene> scenes = subTexelScenes(startShift, settings);
    HeldPath out;
    raster::Renderer r(scenes[0], scene::makeRenderPlan(scenes[0], settings), settings.raster);
    std::vector<scene::Frame> frames;
    for (const scene::Scene& s : scenes) {
        out.frusta.push_back(raster::fitDirectionalLightToReceivers(s, s.lights[0].direction, kHeldMapSize, snap));
        r.update(s, scenes[0].camera);
        raster::RenderDebug debug;
        debug.captureShadowMaps = true;
        frames.push_back(r.render(scene::kAllChannels, &debug));
        out.maps.push_back(debug.layerDepths.at(0));
    }
    EXPECT_EQ(r.validationMessages(), 0);
    const scene::Frame reference =
        raytrace::renderReference(scenes[0], scene::makeRenderPlan(scenes[0], settings), settings.raytrace);
    const std::vector<const scene::Frame*> refs(frames.size(), &reference);
    out.temporal = compare::measureTemporal(pointers(frames), refs);
    return out;
}

TEST(PathStability, SnappedFittedMapsHoldStillUnderSubTexelMovesWhereUnsnappedOnesFlicker) {
    scene::RenderSettings fitted = settingsFor(slantedSphereOverAShadingPlane(128, 72), kHeldMapSize);
    fitted.raster.fitLightFrustum = true;
    const double start = startInsideOneSnapStep(fitted);
    const HeldPath snapped = heldSubTexelPath(true, start);
    for (const raster::LightFrustum& f : snapped.frusta) ASSERT_TRUE(sameFrustum(f, snapped.frusta[0]));
    for (std::size_t t = 1; t < snapped.maps.size(); ++t) EXPECT_EQ(snapped.maps[t], snapped.maps[0]) << "frame " << t;
    EXPECT_EQ(snapped.temporal.totalFlicker, 0u);
    EXPECT_EQ(snapped.temporal.meanErrorVariation, 0.0);
    EXPECT_EQ(snapped.temporal.meanSwimPixels, 0.0);

    const HeldPath unsnapped = heldSubTexelPath(false, start);
    for (std::size_t t = 1; t < unsnapped.frusta.size(); ++t)
        EXPECT_NE(unsnapped.frusta[t].center, unsnapped.frusta[t - 1].center) << "frame " << t;
    EXPECT_NE(unsnapped.maps.back(), unsnapped.maps[0]);
    std::printf(
        "held view, 5 sub-texel steps: snapped flicker %zu px; unsnapped %zu px (mean rate %.4f%%), "
        "swim %.4f px, error variation %.2e\n",
        snapped.temporal.totalFlicker, unsnapped.temporal.totalFlicker, 100 * unsnapped.temporal.meanFlickerRate,
        unsnapped.temporal.meanSwimPixels, unsnapped.temporal.meanErrorVariation);
    EXPECT_GT(unsnapped.temporal.totalFlicker, 0u);
    EXPECT_GT(unsnapped.temporal.meanSwimPixels, 0.0);
    EXPECT_GT(unsnapped.temporal.meanErrorVariation, 0.0);
}

// Over the pixels of one pair whose view depth (frame t) lies in the band before an inner split
// (the last `band` of the slice) or up to 2% past it, where a dolly moves the seam over the image:
// the flicker pixels, and the sum of the error's change | |V_M − V_R|(t+1) − |V_M − V_R|(t) |.
struct Seam {
    std::size_t flicker = 0;
    double variation = 0.0;
};
Seam seamFlicker(const scene::Frame& m0, const scene::Frame& m1, const scene::Frame& r0, const scene::Frame& r1,
                 double band) {
    const compare::Comparison c0 = compare::compareFrames(m0, r0), c1 = compare::compareFrames(m1, r1);
    const std::vector<unsigned char> mask = compare::flickerMask(m0, m1, r0, r1, c0.classes, c1.classes);
    std::vector<double> splits;
    std::stringstream in(m0.attributes.at("cascade_splits"));
    for (std::string item; std::getline(in, item, ';');) splits.push_back(std::stod(item));
    Seam seam;
    const auto counted = [](compare::PixelClass c) {
        return c != compare::PixelClass::NotCounted && c != compare::PixelClass::Invalid;
    };
    for (std::size_t i = 0; i < mask.size(); ++i) {
        if (!counted(c0.classes[i]) || !counted(c1.classes[i])) continue;
        for (std::size_t k = 1; k + 1 < splits.size(); ++k)
            if (m0.depth[i] >= splits[k] - band * (splits[k] - splits[k - 1]) && m0.depth[i] <= splits[k] * 1.02) {
                seam.flicker += mask[i];
                seam.variation += std::abs(std::abs(double(m1.visibility[i]) - r1.visibility[i]) -
                                           std::abs(double(m0.visibility[i]) - r0.visibility[i]));
                break;
            }
    }
    return seam;
}

TEST(PathStability, CascadeSeamFlickerUnderADollyWithAndWithoutBlending) {
    // The long plane with a rail along the view: its shadow's edge runs through every split.
    scene::Scene base = shadowlab::test::makeLongPlane(160, 90);
    scene::Object rail;
    rail.name = "rail";
    rail.shape = scene::Box{Vec3(0.8, 0.0, -190.0), Vec3(1.4, 1.0, -2.5)};
    base.objects.push_back(rail);
    PathSpec spec;
    spec.kind = PathKind::Dolly;
    spec.frames = 8;
    spec.amount = 0.2;
    scene::RenderSettings settings = settingsFor(base, 512);
    settings.raster.cascades = 3;
    const std::vector<scene::Scene> scenes = pathScenes(base, settings, spec);
    std::vector<scene::Frame> moving;  // the reference at every frame
    const raytrace::Renderer reference(scenes[0], settings.raytrace, true);
    for (const scene::Scene& s : scenes) moving.push_back(reference.render(s, scene::makeRenderPlan(s, settings)));
    const double band = 0.25;
    // held: each frame's cascades drawn from frame 0's camera, against frame 0's reference: the
    // splits move over a still image, so what changes is the cascade switch alone.
    auto run = [&](double blend, bool held) {
        scene::RenderSettings b = settings;
        b.raster.cascadeBlend = blend;
        raster::Renderer r(scenes[0], scene::makeRenderPlan(scenes[0], b), b.raster);
        std::vector<scene::Frame> frames;
        for (const scene::Scene& s : scenes) {
            if (held)
                r.update(s, scenes[0].camera);
            else
                r.update(s);
            frames.push_back(r.render());
        }
        const std::vector<scene::Frame> refs = held ? std::vector<scene::Frame>(scenes.size(), moving[0]) : moving;
        EXPECT_EQ(r.validationMessages(), 0);
        Seam seam;
        for (std::size_t t = 0; t + 1 < frames.size(); ++t) {
            const Seam s = seamFlicker(frames[t], frames[t + 1], refs[t], refs[t + 1], band);
            seam.flicker += s.flicker;
            seam.variation += s.variation;
        }
        const compare::TemporalSummary all = compare::measureTemporal(pointers(frames), pointers(refs));
        std::printf(
            "dolly, 3 cascades, %s view, blend %.2f: seam flicker %zu px, seam error variation %.3f; all flicker %zu "
            "px (mean rate %.3f%%), swim %.3f px\n",
            held ? "held" : "moving", blend, seam.flicker, seam.variation, all.totalFlicker, 100 * all.meanFlickerRate,
            all.meanSwimPixels);
        return seam;
    };
    const Seam hard = run(0.0, true), blended = run(band, true);
    const Seam hardMoving = run(0.0, false), blendedMoving = run(band, false);
    // What this shows (docs/temporal.md): the seam flickers with and without the blend band, and
    // the band does not reduce it here; it spreads the switch over the band, whose pixels then
    // change a little every frame (a larger error variation), while the dolly also changes every
    // cascade's texel size (the slices follow the visible depth range), which flickers all over.
    EXPECT_GT(hard.flicker, 0u);
    EXPECT_GT(blended.flicker, 0u);
    EXPECT_GT(hardMoving.flicker, 0u);
    EXPECT_GT(blendedMoving.flicker, 0u);
}

TEST(PathFolder, WritesEveryOutputResumesWithoutRenderingAgainAndRefusesAnotherPath) {
    const fs::path dir = fs::temp_directory_path() / ("shadowlab-path-test-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    scene::Scene base = slantedSphere(48, 27);
    base.file = "test-scene.json";
    scene::RenderSettings settings = settingsFor(base, 128);
    PathSpec spec;
    spec.kind = PathKind::SunAzimuth;
    spec.frames = 3;
    PathRunOptions options;
    options.outputDir = dir;
    const PathResult first = runPath(base, settings, spec, options);
    ASSERT_EQ(first.methods.size(), 2u);  // a light path has no held view
    EXPECT_EQ(first.methods[0].name, "raster");
    EXPECT_EQ(first.referenceTemporal.totalFlicker, 0u);  // zero by definition
    for (const char* f : {"report.html", "metrics.json", "flicker.svg", "error.svg", "raster.gif", "raytrace.gif",
                          "frames.jsonl", "path.json", "frames/0002-raster.exr", "frames/0002-reference.exr"})
        EXPECT_TRUE(fs::exists(dir / f)) << f;
    // The report says, per method, its best and worst frame by wrong pixels and what the worst holds:
    // the figures are the frames' own metrics, read back here.
    {
        std::ifstream in(dir / "report.html");
        const std::string html((std::istreambuf_iterator<char>(in)), {});
        const auto& ms = first.methods[0].metrics;
        std::size_t worst = 0;
        for (std::size_t t = 0; t < ms.size(); ++t)
            if (ms[t].mismatchRate > ms[worst].mismatchRate) worst = t;
        const std::string expected = "; frame " + std::to_string(worst) + " has " +
                                     compare::formatCount(ms[worst].falseShadow) + " false and " +
                                     compare::formatCount(ms[worst].missedShadow) + " missed shadow pixels";
        EXPECT_NE(html.find("<h2>Error per frame</h2>"), std::string::npos);
        const std::size_t at = html.find("<b>raster</b>: ");
        ASSERT_NE(at, std::string::npos);
        const std::string paragraph = html.substr(at, html.find("</p>", at) - at);
        EXPECT_NE(paragraph.find(expected), std::string::npos) << paragraph;
        EXPECT_NE(paragraph.find("frames/000" + std::to_string(worst) + "-raster.exr"), std::string::npos) << paragraph;
    }
    // Again without --resume: refused, nothing rendered.
    EXPECT_THROW(runPath(base, settings, spec, options), scene::InputError);
    // Resumed: every frame comes from the journal and the figures are the same.
    options.resume = true;
    const PathResult again = runPath(base, settings, spec, options);
    EXPECT_EQ(again.resumedFrames, 3);
    EXPECT_EQ(again.methods[0].temporal.totalFlicker, first.methods[0].temporal.totalFlicker);
    EXPECT_EQ(again.methods[0].metrics[2].falseShadow, first.methods[0].metrics[2].falseShadow);
    // A torn last journal line is dropped and that frame rendered again.
    {
        std::ifstream in(dir / "frames.jsonl");
        std::string a, b;
        std::getline(in, a);
        std::getline(in, b);
        in.close();
        std::ofstream out(dir / "frames.jsonl", std::ios::trunc);
        out << a << "\n" << b << "\n{\"frame\": 2, \"fra";
    }
    const PathResult torn = runPath(base, settings, spec, options);
    EXPECT_EQ(torn.resumedFrames, 2);
    EXPECT_EQ(torn.methods[0].metrics[2].falseShadow, first.methods[0].metrics[2].falseShadow);
    // Another path in the same folder is refused even with --resume.
    spec.frames = 4;
    EXPECT_THROW(runPath(base, settings, spec, options), scene::InputError);
    fs::remove_all(dir);
}

TEST(PathScenes, PathsMoveWhatTheySayAndRejectWhatTheSceneCannotHave) {
    const scene::Scene base = slantedSphere(64, 36);
    const scene::RenderSettings settings = settingsFor(base, 256);
    PathSpec spec;
    spec.kind = PathKind::Orbit;
    spec.frames = 5;
    spec.amount = 40.0;
    const std::vector<scene::Scene> orbit = pathScenes(base, settings, spec);
    ASSERT_EQ(orbit.size(), 5u);
    // The last frame is turned 40° about Y through the look-at point: same distance, same height.
    const Vec3 d0 = base.camera.position - base.camera.lookAt, d4 = orbit[4].camera.position - base.camera.lookAt;
    EXPECT_NEAR(glm::length(d4), glm::length(d0), 1e-12);
    EXPECT_NEAR(d4.y, d0.y, 1e-12);
    EXPECT_NEAR(std::acos(glm::dot(glm::normalize(Vec3(d0.x, 0, d0.z)), glm::normalize(Vec3(d4.x, 0, d4.z)))) * 180 /
                    shadowlab::test::kPi,
                40.0, 1e-9);
    spec.kind = PathKind::SubTexel;
    spec.amount = 0.5;
    const std::vector<scene::Scene> sub = pathScenes(base, settings, spec);
    const SubTexelStep step = subTexelStep(base, settings.raster, 0.5);
    EXPECT_NEAR(glm::length(sub[1].camera.position - base.camera.position), step.step, 1e-12);
    EXPECT_NEAR(step.step, 0.5 * std::min(step.texel, step.pixel), 1e-15);
    spec.kind = PathKind::LightMove;  // the light is directional
    EXPECT_THROW(pathScenes(base, settings, spec), scene::InputError);
    spec.kind = PathKind::SunAzimuth;
    spec.light = 3;
    EXPECT_THROW(pathScenes(base, settings, spec), scene::InputError);
    spec.light = 0;
    spec.frames = 1;
    EXPECT_THROW(pathScenes(base, settings, spec), scene::InputError);
}

}  // namespace
}  // namespace shadowlab::studies

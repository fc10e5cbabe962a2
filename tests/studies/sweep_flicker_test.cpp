// tests/studies/sweep_flicker_test.cpp: the sweep's flicker axis with a fake renderer whose frames
// are known along a pan: a method equal to the reference and a fixed wrong stripe have zero
// flicker, a stripe in every other frame flickers by its area; a sweep without the axis renders
// and writes what it did; the grid file's flicker block and the axes for snapping, cascade blend,
// fitting and filters, with their errors at their JSON paths.
#include "studies/sweep.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "scene/error.h"
#include "scene/loader.h"
#include "studies/sweep_report.h"
#include "tests/compare/synthetic.h"

namespace shadowlab::studies {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

constexpr int kW = 24, kH = 16, kStripe = 4;  // the stripe: the kStripe leftmost columns in shadow

fs::path writeScene(const fs::path& dir) {
    fs::create_directories(dir);
    const Json scene = {
        {"camera",
         {{"position", {0, 2, 6}},
          {"look_at", {0, 0.7, 0}},
          {"up", {0, 1, 0}},
          {"fov_y", 40},
          {"resolution", {kW, kH}}}},
        {"materials", {{"matte", {{"albedo", {0.8, 0.8, 0.8}}}}}},
        {"lights", {{{"type", "directional"}, {"direction", {-1, -2, -1}}}}},
        {"objects", {{{"type", "sphere"}, {"center", {0, 1, 0}}, {"radius", 1}, {"material", "matte"}}}}};
    std::ofstream(dir / "a.json") << scene.dump(2);
    return dir / "a.json";
}

// Frames along a pan of `amount` over `frames` frames: the frame index from how far the camera moved
// (a pan moves it by t/(frames − 1) · amount · distance along the view's right axis).
struct PanFake {
    const scene::Scene* base = nullptr;
    double amount = 0.1;
    int frames = 3;
    int renders = 0;
    int frameOf(const scene::Scene& s) const {
        const double distance = glm::length(base->camera.lookAt - base->camera.position);
        const double moved = glm::length(s.camera.position - base->camera.position);
        return int(std::lround(moved / (amount * distance) * (frames - 1)));
    }
    RenderFn fn() {
        return [this](const scene::Scene& s, const scene::RenderSettings& settings, scene::Backend backend) {
            ++renders;
            scene::Frame f = compare::test::uniformFrame(s.camera.width, s.camera.height, 1.0f, 0.6f, 1.0f);
            f.timingsMs = {{"setup", 1.0}, {"render", 2.0}};
            // raster map 512: the stripe in every frame (a fixed wrong offset); map 1024: in odd frames.
            const bool stripe =
                backend == scene::Backend::Raster && (settings.raster.shadowMapSize == 512 ||
                                                      (settings.raster.shadowMapSize == 1024 && frameOf(s) % 2 == 1));
            if (stripe)
                for (int y = 0; y < f.height; ++y)
                    for (int x = 0; x < kStripe; ++x) f.visibility[std::size_t(y) * f.width + x] = 0.0f;
            return f;
        };
    }
};

class SweepFlicker : public ::testing::Test {
protected:
    void SetUp() override {
        root = fs::path(::testing::TempDir()) /
               ("shadowlab_flicker_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
        fs::remove_all(root);
        scene = scene::loadScene(writeScene(root / "scenes"));
    }
    void TearDown() override { fs::remove_all(root); }
    SweepGrid grid(bool flicker) const {
        SweepGrid g;
        g.repetitions = 2;
        for (int size : {512, 1024}) {
            SweepConfig c;
            c.backend = scene::Backend::Raster;
            c.overrides.shadowMapSize = size;
            g.configs.push_back(c);
        }
        SweepConfig rt;
        rt.backend = scene::Backend::Raytrace;
        g.configs.push_back(rt);
        if (flicker) {
            PathSpec p;
            p.kind = PathKind::Pan;
            p.frames = 3;
            p.amount = 0.1;
            g.flicker = p;
        }
        return g;
    }
    fs::path root;
    scene::Scene scene;
};

TEST_F(SweepFlicker, RowsCarryFlickerThatIsZeroForTheReferenceAndAFixedOffsetAndTheStripeAreaOtherwise) {
    PanFake fake;
    fake.base = &scene;
    SweepOptions o;
    o.outputDir = root / "out";
    o.render = fake.fn();
    const SweepResult r = runSweep(scene, grid(true), o);
    ASSERT_EQ(r.rows.size(), 3u);
    const double stripeRate = double(kStripe) / kW;  // kStripe · kH of kW · kH counted pixels
    // Map 512: wrong in every frame alike: no flicker, no error variation, but an error.
    EXPECT_EQ(r.rows[0].temporalValue("flicker_px"), 0.0);
    EXPECT_EQ(r.rows[0].temporalValue("error_variation"), 0.0);
    EXPECT_NEAR(r.rows[0].rate("mismatch_rate"), stripeRate, 1e-12);
    // Map 1024: the stripe in frame 1 only, so both pairs flip it: 2 · kStripe · kH pixels, a rate
    // of kStripe / kW per pair, and |ΔV| = 1 over the stripe.
    EXPECT_EQ(r.rows[1].temporalValue("flicker_px"), 2.0 * kStripe * kH);
    EXPECT_NEAR(r.rows[1].temporalValue("flicker_rate"), stripeRate, 1e-12);
    EXPECT_NEAR(r.rows[1].temporalValue("max_flicker_rate"), stripeRate, 1e-12);
    EXPECT_NEAR(r.rows[1].temporalValue("error_variation"), stripeRate, 1e-9);
    EXPECT_EQ(r.rows[1].temporal["pairs"], Json::array({kStripe * kH, kStripe * kH}));
    EXPECT_EQ(r.rows[1].rate("mismatch_rate"), 0.0);  // the still frame (frame 0) is right
    // The ray tracer equals the reference in every frame.
    EXPECT_EQ(r.rows[2].temporalValue("flicker_px"), 0.0);
    EXPECT_EQ(r.rows[2].temporalValue("swim_px"), 0.0);
    // A fake renderer has no Renderer to hold the view: no held figures.
    EXPECT_TRUE(std::isnan(r.rows[1].temporalValue("flicker_rate", true)));
    // The columns and the plot.
    std::ifstream csv(root / "out" / "results.csv");
    std::string header;
    std::getline(csv, header);
    EXPECT_NE(
        header.find(",flicker_path,flicker_rate,flicker_px,error_variation,swim_px,edge_offset_px,held_flicker_rate"),
        std::string::npos)
        << header;
    SweepReportInput in = makeSweepReportInput("a", "a.json", r);
    const std::string html = renderSweepReportHtml(in);
    EXPECT_NE(html.find("Flicker against error"), std::string::npos);
    EXPECT_NE(sweepFlickerSvg(in).find("<svg"), std::string::npos);
    // Resumed: the rows come from the journal with their figures, and nothing renders again.
    const int renders = fake.renders;
    o.resume = true;
    const SweepResult again = runSweep(scene, grid(true), o);
    EXPECT_EQ(fake.renders, renders);
    EXPECT_EQ(again.rows[1].temporal, r.rows[1].temporal);
    // Another flicker path in the same folder is another sweep.
    SweepGrid other = grid(true);
    other.flicker->frames = 4;
    EXPECT_THROW(runSweep(scene, other, o), scene::InputError);
}

TEST_F(SweepFlicker, ASweepWithoutTheAxisRendersAndWritesWhatItDidWithoutIt) {
    PanFake fake;
    fake.base = &scene;
    SweepOptions o;
    o.outputDir = root / "out";
    o.render = fake.fn();
    const SweepGrid g = grid(false);
    runSweep(scene, g, o);
    // One reference, then per row a warm-up and the timed frames: nothing along a path.
    EXPECT_EQ(fake.renders, 1 + int(g.configs.size()) * (1 + g.repetitions));
    std::ifstream csv(root / "out" / "results.csv");
    std::string header;
    std::getline(csv, header);
    EXPECT_EQ(header.find("flicker"), std::string::npos) << header;
    EXPECT_TRUE(header.ends_with(",error,machine")) << header;
    std::ifstream journal(root / "out" / "results.jsonl");
    for (std::string line; std::getline(journal, line);) EXPECT_FALSE(Json::parse(line).contains("temporal"));
    EXPECT_FALSE(fs::exists(root / "out" / "flicker"));
    std::ifstream manifest(root / "out" / "sweep.json");
    EXPECT_FALSE(Json::parse(manifest).contains("flicker"));
    // The keys of rows that do not set the new axes are unchanged.
    EXPECT_EQ(g.configs[0].key(), "backend=raster;map=512");
}

class FlickerGridFile : public SweepFlicker {
protected:
    fs::path write(const std::string& text) {
        fs::create_directories(root);
        std::ofstream(root / "grid.json") << text;
        return root / "grid.json";
    }
};

TEST_F(FlickerGridFile, TheFlickerBlockAndTheStabilityAxesAreRead) {
    const SweepGrid g = loadGrid(write(R"({"flicker": {"kind": "orbit", "frames": 5, "amount": 3},
        "raster": {"fit_light_frustum": [true], "snap_light_frustum": [true, false], "cascades": [3],
                   "cascade_blend": [0, 0.2], "filter": ["pcf2x2", "poisson"]}})"),
                                 scene);
    ASSERT_TRUE(g.flicker.has_value());
    EXPECT_EQ(g.flicker->kind, PathKind::Orbit);
    EXPECT_EQ(g.flicker->frames, 5);
    EXPECT_EQ(g.flicker->amount, std::optional<double>(3.0));
    ASSERT_EQ(g.configs.size(), 8u);  // 2 snap × 2 blend × 2 filters
    std::set<std::string> keys;
    for (const SweepConfig& c : g.configs) keys.insert(c.key());
    EXPECT_EQ(keys.size(), 8u);
    EXPECT_TRUE(keys.count("backend=raster;filter=poisson;fit_light_frustum=1;cascades=3;snap=0;cascade_blend=0.2"));
    // true: the default path, four frames of sub-texel steps.
    const SweepGrid d = loadGrid(write(R"({"flicker": true, "raytrace": {"precision": ["float"]}})"), scene);
    ASSERT_TRUE(d.flicker.has_value());
    EXPECT_EQ(d.flicker->kind, PathKind::SubTexel);
    EXPECT_EQ(d.flicker->frames, 4);
    EXPECT_FALSE(loadGrid(write(R"({"flicker": false, "raytrace": {"precision": ["float"]}})"), scene).flicker);
}

TEST_F(FlickerGridFile, BadValuesAreRejectedWithTheirJsonPath) {
    const std::vector<std::pair<std::string, std::string>> cases = {
        {R"({"flicker": 3, "raytrace": {"precision": ["float"]}})", "flicker"},
        {R"({"flicker": {"kind": "zigzag"}, "raytrace": {"precision": ["float"]}})", "flicker.kind"},
        {R"({"flicker": {"frames": 1}, "raytrace": {"precision": ["float"]}})", "flicker.frames"},
        {R"({"flicker": {"frames": 500}, "raytrace": {"precision": ["float"]}})", "flicker.frames"},
        {R"({"flicker": {"speed": 1}, "raytrace": {"precision": ["float"]}})", "flicker.speed"},
        {R"({"flicker": {"kind": "light-move"}, "raytrace": {"precision": ["float"]}})",
         "flicker"},  // directional light
        {R"({"raster": {"cascade_blend": [0.1, 0.7]}})", "raster.cascade_blend[1]"},
        {R"({"raster": {"snap_light_frustum": ["yes"]}})", "raster.snap_light_frustum[0]"},
        {R"({"raster": {"fit_light_frustum": [1]}})", "raster.fit_light_frustum[0]"},
    };
    for (const auto& [text, path] : cases) {
        try {
            loadGrid(write(text), scene);
            ADD_FAILURE() << "accepted " << text;
        } catch (const scene::SceneError& e) {
            EXPECT_EQ(e.jsonPath(), path) << text << ": " << e.what();
        }
    }
}

}  // namespace
}  // namespace shadowlab::studies

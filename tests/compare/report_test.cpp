// tests/compare/report_test.cpp: report.html is written, self-contained, balanced, names only
// the image files it was given, and shows the metrics; the findings paragraph says what the
// metrics say.
#include "compare/report.h"

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include <gtest/gtest.h>

#include "compare/compare.h"
#include "compare/text.h"
#include "tests/compare/synthetic.h"

namespace shadowlab::compare {
namespace {

namespace fs = std::filesystem;

std::size_t count(const std::string& s, const std::string& what) {
    std::size_t n = 0;
    for (auto p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
    return n;
}

// A run of the synthetic scene: reference, a ray tracer with terminator acne and a shadow
// map with acne, a detached shadow and jaggies.
ReportInput syntheticRun() {
    test::SyntheticOptions o;
    o.width = 120;
    o.height = 68;
    scene::Frame ref = test::syntheticFrame(o);
    ref.timingsMs = {{"render", 900.0}};
    ref.attributes = {{"backend", "reference"}, {"version", "0.1.0"}};
    test::SyntheticOptions ro = o;
    ro.acne = ro.shiftShadow = ro.jaggies = true;
    scene::Frame raster = test::syntheticFrame(ro);
    raster.timingsMs = {{"setup", 40.0}, {"shadow_pass", 3.0}};
    raster.attributes = {{"backend", "raster"}, {"depth_bias", "0.002"}};
    test::SyntheticOptions to = o;
    to.rayAcne = true;
    scene::Frame ray = test::syntheticFrame(to);
    ray.timingsMs = {{"render", 120.0}};

    ReportInput in;
    in.sceneName = "synthetic <test>";
    in.scenePath = "scenes/synthetic.json";
    in.planText = "any-hit shadow rays: all objects opaque";
    in.objectNames = {"the plane", "the sphere"};
    in.reference = {"reference", "reference.png", ref};
    in.methods.push_back({"raytrace", "raytrace.png", "diff-raytrace.png", ray, compareFrames(ray, ref).metrics});
    in.methods.push_back({"raster", "raster.png", "diff-raster.png", raster, compareFrames(raster, ref).metrics});
    return in;
}

TEST(Report, NamesOnlyTheGivenImageFilesAndNothingRemote) {
    const ReportInput in = syntheticRun();
    const std::string html = renderReportHtml(in);
    const std::set<std::string> given = {"reference.png", "raytrace.png", "diff-raytrace.png", "raster.png",
                                         "diff-raster.png"};
    std::set<std::string> seen;
    const std::regex ref(R"((src|href)="([^"]*)\")");
    for (auto it = std::sregex_iterator(html.begin(), html.end(), ref); it != std::sregex_iterator(); ++it) {
        const std::string target = (*it)[2];
        EXPECT_TRUE(given.count(target)) << "unexpected link target " << target;
        seen.insert(target);
    }
    EXPECT_EQ(seen, given);  // every image is shown
    EXPECT_EQ(html.find("<script"), std::string::npos);
    EXPECT_EQ(html.find("<link"), std::string::npos);
    EXPECT_EQ(html.find("url("), std::string::npos);
}

TEST(Report, IsBalancedEnoughToParse) {
    const std::string html = renderReportHtml(syntheticRun());
    EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
    for (const std::string tag :
         {"div", "table", "tr", "figure", "svg", "section", "details", "p", "ul", "li", "g", "text"})
        EXPECT_EQ(count(html, "<" + tag + ">") + count(html, "<" + tag + " "), count(html, "</" + tag + ">")) << tag;
    EXPECT_NE(html.find("</html>"), std::string::npos);
    // The scene name is escaped, not markup.
    EXPECT_NE(html.find("synthetic &lt;test&gt;"), std::string::npos);
    EXPECT_EQ(html.find("<test>"), std::string::npos);
}

TEST(Report, ShowsEachMethodsMetricsAndTimings) {
    const ReportInput in = syntheticRun();
    const std::string html = renderReportHtml(in);
    for (const auto& m : in.methods) {
        const Metrics& k = m.metrics;
        EXPECT_NE(html.find(">" + formatCount(k.counted) + "<"), std::string::npos) << m.label;
        EXPECT_NE(html.find(">" + formatCount(k.falseShadow) + "<"), std::string::npos) << m.label;
        EXPECT_NE(html.find(formatPercent(k.falseShadowRate)), std::string::npos) << m.label;
        EXPECT_NE(html.find(formatPercent(k.missedShadowRate)), std::string::npos) << m.label;
        EXPECT_NE(html.find(formatFixed(k.shadowIoU, 4)), std::string::npos) << m.label;
    }
    EXPECT_NE(html.find("shadow_pass"), std::string::npos);          // a stage timing row
    EXPECT_NE(html.find(formatDuration(43.0)), std::string::npos);   // raster total 40 + 3
    EXPECT_NE(html.find("reference 900 ms"), std::string::npos);     // the plot's marker
    EXPECT_NE(html.find("any-hit shadow rays"), std::string::npos);  // the plan
    EXPECT_EQ(count(html, "<svg"), 1u);
}

TEST(Report, ImagesCarryTheirShadowSettingsAndThePagesChoicesInFull) {
    // Under each image, one line of the settings that decide its shadows (not every attribute,
    // cut off: those are in the Settings section), fractions to three digits, whole numbers as
    // they are; the program's choices of view and sun whole, once; a ray tracer's aliasing cell
    // says it has none rather than a 0 that reads as "all its error is away from edges".
    ReportInput in = syntheticRun();
    const std::string why =
        "searched, from outside, azimuth 30, elevation 20 degrees (the best of 576 view x sun "
        "pairs at 64x36, then moved back to hold the whole shadow)";
    in.reference.frame.attributes["choice.view"] = why;
    in.reference.frame.attributes["scene_hash"] = "56a073b50afe5bcb";
    in.methods[1].frame.attributes["shadow_map_size"] = "2048";
    in.methods[1].frame.attributes["depth_bias"] = "0.000305175781";
    in.methods[1].frame.attributes["gpu_lit_pass_ms"] = "182.879232";
    in.methods[0].frame.attributes["ray_bias"] = "0.000339756029";
    in.methods[0].metrics.pointSampled = true;
    const std::string html = renderReportHtml(in);
    const std::string images =
        html.substr(html.find("<h2>Images</h2>"), html.find("<h2>Difference") - html.find("<h2>Images</h2>"));
    EXPECT_NE(images.find("shadow_map_size 2048 · depth_bias 0.000305"), std::string::npos) << images;
    EXPECT_NE(images.find("ray_bias 0.00034"), std::string::npos) << images;
    EXPECT_EQ(images.find("gpu_lit_pass_ms"), std::string::npos) << images;
    EXPECT_EQ(images.find("scene_hash"), std::string::npos) << images;
    EXPECT_EQ(images.find("..."), std::string::npos) << images;
    EXPECT_NE(images.find("<b>view</b>: " + why), std::string::npos) << images;
    EXPECT_NE(html.find("gpu_lit_pass_ms"), std::string::npos);  // in the Settings section
    EXPECT_NE(html.find("none <span class=\"small\">(point-sampled)</span>"), std::string::npos);
}

TEST(Report, FindingsNameTheDominantErrorAndWhere) {
    const ReportInput in = syntheticRun();
    // Construction: the shadow map's lit floor gets 8% acne speckles blocked by the floor
    // itself, far more than its detached-shadow errors; the ray tracer only has acne on the
    // sphere's terminator.
    const std::string text = describeFindings(in);
    std::istringstream lines(text);
    std::string ray, raster, overall;
    std::getline(lines, ray);
    std::getline(lines, raster);
    std::getline(lines, overall);
    EXPECT_NE(ray.find("The ray tracer"), std::string::npos) << ray;
    EXPECT_NE(ray.find("self-shadow acne on the sphere"), std::string::npos) << ray;
    EXPECT_NE(raster.find("The shadow map"), std::string::npos) << raster;
    EXPECT_NE(raster.find("self-shadow acne on the plane"), std::string::npos) << raster;
    EXPECT_NE(raster.find("missed shadow"), std::string::npos) << raster;
    EXPECT_NE(raster.find(formatPercent(in.methods[1].metrics.falseShadowRate)), std::string::npos) << raster;
    EXPECT_NE(overall.find("the ray tracer is closer"), std::string::npos) << overall;
}

TEST(Report, FindingsRankNoMethodWhoseErrorIsWithinATenthOfTheOthers) {
    ReportInput in = syntheticRun();
    auto overall = [&] {
        std::istringstream lines(describeFindings(in));
        std::string line, last;
        while (std::getline(lines, line))
            if (line.rfind("Overall", 0) == 0) last = line;
        return last;
    };
    // 0.0486% and 0.0526% both print as 0.05%: no winner, and the digits that tell them apart.
    in.methods[0].metrics.mismatchRate = 0.000486;
    in.methods[1].metrics.mismatchRate = 0.000526;
    std::string text = overall();
    EXPECT_NE(text.find("about as close to the reference as each other"), std::string::npos) << text;
    EXPECT_NE(text.find("(0.049% and 0.053% wrong"), std::string::npos) << text;
    EXPECT_EQ(text.find("is closer"), std::string::npos) << text;
    // 11% apart: ranked, with digits that differ although both round to 0.05% at two decimals.
    in.methods[1].metrics.mismatchRate = 0.000499;
    in.methods[0].metrics.mismatchRate = 0.000451;
    text = overall();
    EXPECT_NE(text.find("the ray tracer is closer to the reference (0.045% against 0.05% wrong)"), std::string::npos)
        << text;
}

TEST(Report, FindingsSayAThinShadowLostToTheBiasIsBiasAndARayTracerDoesNotAlias) {
    // Reference: two columns of shadow on a lit floor (N·L = 0.5), the blocker 0.01 away along
    // the ray. A shadow map (texel 0.01, bias 0.005, slope 1; D = 0.005 + 5·0.01·√3 = 0.092 at
    // this pixel) misses all of it: a bias leak, though every missed pixel lies within 2 px of
    // the strip's edges. Its frame says the receivers and casters asked for 4096 texels where the
    // default capped the map at 2048. A ray tracer misses the same strip: no aliasing there.
    scene::Frame ref = test::uniformFrame(20, 20, 1, 0.5f, 1);
    ref.blockerId.assign(ref.pixelCount(), 0.0f);
    ref.blockerDistance.assign(ref.pixelCount(), 0.0f);
    for (int y = 0; y < 20; ++y)
        for (const int x : {10, 11}) {
            ref.visibility[std::size_t(y) * 20 + x] = 0.0f;
            ref.blockerId[std::size_t(y) * 20 + x] = 2.0f;
            ref.blockerDistance[std::size_t(y) * 20 + x] = 0.01f;
        }
    scene::Frame map = test::uniformFrame(20, 20, 1, 0.5f, 1), ray = map;
    map.attributes = {{"backend", "raster"}, {"texel_world_size", "0.01"}, {"depth_bias", "0.005"},
                      {"slope_bias", "1"},   {"shadow_map_size", "2048"},  {"shadow_map_size_needed", "4096"}};
    ray.attributes = {{"backend", "raytrace"}, {"ray_bias", "0.001"}};
    ReportInput in;
    in.sceneName = "strip";
    in.objectNames = {"floor", "trim"};
    in.reference = {"reference", "reference.png", ref};
    in.methods.push_back({"raytrace", "raytrace.png", "diff-raytrace.png", ray, compareFrames(ray, ref).metrics});
    in.methods.push_back({"raster", "raster.png", "diff-raster.png", map, compareFrames(map, ref).metrics});
    std::istringstream lines(describeFindings(in));
    std::string rayText, mapText;
    std::getline(lines, rayText);
    std::getline(lines, mapText);
    EXPECT_EQ(rayText.find("aliasing rather than bias"), std::string::npos) << rayText;
    EXPECT_NE(rayText.find("none of this is aliasing"), std::string::npos) << rayText;
    EXPECT_EQ(mapText.find("aliasing rather than bias"), std::string::npos) << mapText;
    EXPECT_NE(mapText.find("100% of it within the contact distance of its blocker"), std::string::npos) << mapText;
    EXPECT_NE(mapText.find("ask for 4,096 texels"), std::string::npos) << mapText;
    EXPECT_NE(mapText.find("caps it at 2,048"), std::string::npos) << mapText;
    // Without the cap (the map as large as asked for) the contact-distance words stay, the size
    // advice goes.
    in.methods[1].frame.attributes["shadow_map_size"] = "4096";
    std::istringstream again(describeFindings(in));
    std::getline(again, rayText);
    std::getline(again, mapText);
    EXPECT_NE(mapText.find("within the contact distance"), std::string::npos) << mapText;
    EXPECT_EQ(mapText.find("--shadow-map-size"), std::string::npos) << mapText;
}

TEST(Report, FindingsNameANormalOffsetWhereTheAcneIsLitNearGrazing) {
    // A shadow map darkens columns 0-5 of a lit mesh (id 1) with its own texels (blocker id 1):
    // self-shadow acne. At N·L 0.1 it is the grazing band a normal offset clears; at 0.6 it is
    // plain acne, and the sentence says nothing of grazing.
    for (const float ndotl : {0.1f, 0.6f}) {
        scene::Frame ref = test::uniformFrame(20, 20, 1, ndotl, 1);
        ref.blockerId.assign(ref.pixelCount(), 0.0f);
        scene::Frame map = test::uniformFrame(20, 20, 1, ndotl, 1);
        map.blockerId.assign(map.pixelCount(), 0.0f);
        for (int y = 0; y < 20; ++y)
            for (int x = 0; x <= 5; ++x) {
                map.visibility[std::size_t(y) * 20 + x] = 0.0f;
                map.blockerId[std::size_t(y) * 20 + x] = 1.0f;
            }
        map.attributes = {{"backend", "raster"}, {"texel_world_size", "0.01"}, {"depth_bias", "0.005"}};
        ReportInput in;
        in.sceneName = "bumper";
        in.objectNames = {"truck"};
        in.reference = {"reference", "reference.png", ref};
        in.methods.push_back({"raster", "raster.png", "diff-raster.png", map, compareFrames(map, ref).metrics});
        std::istringstream lines(describeFindings(in));
        std::string text;
        std::getline(lines, text);
        EXPECT_NE(text.find("mostly self-shadow acne on truck"), std::string::npos) << text;
        EXPECT_EQ(text.find("(100% of it lit near grazing") != std::string::npos, ndotl < 0.2f) << text;
        EXPECT_EQ(text.find("normal offset") != std::string::npos, ndotl < 0.2f) << text;
    }
}

TEST(Report, FindingsCallMissedShadowAtAMeshsOwnTerminatorATessellationEffect) {
    // Reference: a mesh (id 1) at grazing light, N·L 0.1, whose columns 4-7 are shadowed by the
    // mesh itself (its flat facets); a ray tracer offsets along the interpolated normal and
    // lights them. Then columns 12-19 are shadowed by a second object (id 2) the method also
    // misses: a third of the missed shadow left at the terminator is named, not the cause.
    scene::Frame ref = test::uniformFrame(20, 20, 1, 0.1f, 1);
    ref.blockerId.assign(ref.pixelCount(), 0.0f);
    auto shadow = [&](int x0, int x1, float by) {
        for (int y = 0; y < 20; ++y)
            for (int x = x0; x <= x1; ++x) {
                ref.visibility[std::size_t(y) * 20 + x] = 0.0f;
                ref.blockerId[std::size_t(y) * 20 + x] = by;
            }
    };
    shadow(4, 7, 1.0f);
    scene::Frame ray = test::uniformFrame(20, 20, 1, 0.1f, 1);
    ray.attributes = {{"backend", "raytrace"}, {"ray_bias", "0.001"}};
    ReportInput in;
    in.sceneName = "grazing";
    in.objectNames = {"Suzanne", "post"};
    in.reference = {"reference", "reference.png", ref};
    in.methods.push_back({"raytrace", "raytrace.png", "diff-raytrace.png", ray, compareFrames(ray, ref).metrics});
    auto firstLine = [&] {
        std::istringstream lines(describeFindings(in));
        std::string line;
        std::getline(lines, line);
        return line;
    };
    std::string text = firstLine();
    EXPECT_NE(text.find("100% of it at a smooth-shaded mesh's terminator on Suzanne"), std::string::npos) << text;
    EXPECT_NE(text.find("rather than a leak"), std::string::npos) << text;
    EXPECT_NE(text.find("the ray's offset along that normal"), std::string::npos) << text;
    // The same pixels from a shadow map: its bias, not an offset along the normal, hides them.
    scene::Frame map = ray;
    map.attributes = {{"backend", "raster"}, {"texel_world_size", "0.01"}, {"depth_bias", "0.005"}};
    in.methods[0] = {"raster", "raster.png", "diff-raster.png", map, compareFrames(map, ref).metrics};
    text = firstLine();
    EXPECT_NE(text.find("the map's bias reaches past the neighbouring facet"), std::string::npos) << text;
    in.methods[0] = {"raytrace", "raytrace.png", "diff-raytrace.png", ray, compareFrames(ray, ref).metrics};

    shadow(12, 19, 2.0f);
    in.reference.frame = ref;
    in.methods[0].metrics = compareFrames(ray, ref).metrics;
    text = firstLine();
    EXPECT_NE(text.find("light leaking"), std::string::npos) << text;
    EXPECT_NE(text.find("; " + formatPercent(1.0 / 3.0) + " of it lies at a smooth-shaded mesh's terminator"),
              std::string::npos)
        << text;

    // From a shadow map, with the reference's blocker distances: the terminator's facets are 0.001
    // from their receivers, within any contact distance, and the post's shadow 5 away. The
    // terminator's pixels are not named a second time as peter-panning: no bias leak is left once
    // they are set aside.
    ref.blockerDistance.assign(ref.pixelCount(), 0.0f);
    for (std::size_t i = 0; i < ref.pixelCount(); ++i)
        if (ref.blockerId[i] > 0) ref.blockerDistance[i] = ref.blockerId[i] == 1.0f ? 0.001f : 5.0f;
    map.attributes["slope_bias"] = "1";
    in.reference.frame = ref;
    in.methods[0] = {"raster", "raster.png", "diff-raster.png", map, compareFrames(map, ref).metrics};
    ASSERT_EQ(in.methods[0].metrics.biasLeak, 80u);  // the 4 terminator columns
    ASSERT_EQ(in.methods[0].metrics.terminatorBiasLeak, 80u);
    text = firstLine();
    EXPECT_NE(text.find("of it lies at a smooth-shaded mesh's terminator"), std::string::npos) << text;
    EXPECT_EQ(text.find("peter-panning, the shadow cut off"), std::string::npos) << text;
    EXPECT_EQ(text.find("within the contact distance of its blocker"), std::string::npos) << text;
    EXPECT_EQ(text.find("beside the bias's peter-panning"), std::string::npos) << text;
    // The metrics table says the same: the 80 terminator pixels in their own row, none of them a
    // bias leak.
    const std::string html = renderReportHtml(in);
    const std::string table = html.substr(html.find("<table class=\"metrics\">"));
    const auto rowOf = [&](const std::string& name) {
        const std::size_t at = table.find(name);
        return at == std::string::npos ? std::string() : table.substr(at, table.find("</tr>", at) - at);
    };
    EXPECT_NE(rowOf("at a smooth mesh's terminator").find("<td>80<"), std::string::npos) << table;
    EXPECT_NE(rowOf("terminators aside").find("<td>0<"), std::string::npos) << table;
    // And the metrics JSON: bias_leak holds both, bias_leak_beside_terminator the row's count.
    const auto j = toJson(in.methods[0].metrics);
    EXPECT_EQ(j.at("bias_leak"), 80);
    EXPECT_EQ(j.at("bias_leak_beside_terminator"), 0);
    EXPECT_EQ(j.at("bias_leak_beside_terminator_rate"), 0.0);
}

TEST(Report, FindingsLeadWithPartialShadowWhereItOutnumbersTheWrongPixels) {
    // Reference: a lit floor. The shadow map darkens every pixel to V = 0.6 (filtered acne: |ΔV|
    // 0.4, past 0.25 but not past τ) and shadows 2 of them outright: 0.5% wrong, mean |ΔV| about
    // (398·0.4 + 2)/400 = 0.403. The ray tracer shadows 10 pixels outright and nothing else: 2.5%
    // wrong, mean |ΔV| 0.025. By the wrong pixels the map wins; by what a viewer sees it does not.
    const scene::Frame ref = test::uniformFrame(20, 20, 1, 0.5f, 1);
    scene::Frame map = test::uniformFrame(20, 20, 1, 0.5f, 0.6f), ray = test::uniformFrame(20, 20, 1, 0.5f, 1);
    map.visibility[0] = map.visibility[1] = 0.0f;
    for (int i = 0; i < 10; ++i) ray.visibility[std::size_t(40 * i)] = 0.0f;
    map.attributes = {{"backend", "raster"}, {"texel_world_size", "0.01"}, {"depth_bias", "0.005"}};
    ray.attributes = {{"backend", "raytrace"}, {"ray_bias", "0.001"}};
    ReportInput in;
    in.sceneName = "floor";
    in.objectNames = {"floor"};
    in.reference = {"reference", "reference.png", ref};
    in.methods.push_back({"raytrace", "raytrace.png", "diff-raytrace.png", ray, compareFrames(ray, ref).metrics});
    in.methods.push_back({"raster", "raster.png", "diff-raster.png", map, compareFrames(map, ref).metrics});
    const Metrics& mm = in.methods[1].metrics;
    ASSERT_EQ(mm.softErrorPixels, 398u);
    ASSERT_TRUE(softErrorDominates(mm));
    ASSERT_FALSE(softErrorDominates(in.methods[0].metrics));
    std::istringstream lines(describeFindings(in));
    std::string rayText, mapText, overall;
    std::getline(lines, rayText);
    std::getline(lines, mapText);
    std::getline(lines, overall);
    EXPECT_EQ(rayText.find("partly wrong"), std::string::npos) << rayText;
    EXPECT_EQ(
        mapText.rfind("The shadow map (raster) is partly wrong on " + formatPercent(398.0 / 400.0) + " of the 400", 0),
        0u)
        << mapText;
    EXPECT_NE(mapText.find("outright it disagrees with the reference on 0.50%"), std::string::npos) << mapText;
    EXPECT_NE(overall.find("the shadow map gets fewer pixels wrong outright (0.50% against 2.50%), but the ray "
                           "tracer is closer to the reference by mean |ΔV|"),
              std::string::npos)
        << overall;
    EXPECT_NE(summaryLine(mm).find("SOFT ERROR dominates"), std::string::npos) << summaryLine(mm);
    EXPECT_EQ(summaryLine(in.methods[0].metrics).find("SOFT ERROR"), std::string::npos);

    // Off by 0.2 everywhere instead: under the 0.25 of soft error too, so no pixel is counted as
    // partly wrong, but the mean |ΔV| ((398·0.2 + 2)/400 = 0.204) is still 8 times the ray tracer's.
    scene::Frame dim = test::uniformFrame(20, 20, 1, 0.5f, 0.8f);
    dim.visibility[0] = dim.visibility[1] = 0.0f;
    dim.attributes = map.attributes;
    in.methods[1] = {"raster", "raster.png", "diff-raster.png", dim, compareFrames(dim, ref).metrics};
    ASSERT_EQ(in.methods[1].metrics.softErrorPixels, 0u);
    std::istringstream again(describeFindings(in));
    std::getline(again, rayText);
    std::getline(again, mapText);
    std::getline(again, overall);
    EXPECT_NE(overall.find("gets fewer pixels wrong outright (0.50% against 2.50%), but the ray tracer is closer to "
                           "the reference by mean |ΔV| (0.0250 against 0.2040)"),
              std::string::npos)
        << overall;
    EXPECT_NE(overall.find("off over more of the image by less than τ"), std::string::npos) << overall;
}

TEST(Report, FindingsNamePeterPanningThatIsAMinorityOfTheMissedShadow) {
    // Reference: a lit floor (N·L 0.5) with two shadows the shadow map misses whole. Columns 2-3
    // are a thin caster's contact shadow, its blocker 0.01 away (within the contact distance
    // D = 0.005 + 5·0.01·√3 = 0.092): 40 px of bias leak. Columns 8-12 are a far caster's shadow
    // (blocker 5 away): 100 px, of which column 10 lies more than 2 px from the shadow's edges
    // (20 px of bleeding) and the rest next to them. The leak is 40 of 140 missed pixels, 28.6%:
    // short of most, but a fifth or more, so it is named as the peter-panning it is.
    scene::Frame ref = test::uniformFrame(20, 20, 1, 0.5f, 1);
    ref.blockerId.assign(ref.pixelCount(), 0.0f);
    ref.blockerDistance.assign(ref.pixelCount(), 0.0f);
    for (int y = 0; y < 20; ++y)
        for (int x = 0; x < 20; ++x) {
            const bool contact = x == 2 || x == 3, far = x >= 8 && x <= 12;
            if (!contact && !far) continue;
            const std::size_t i = std::size_t(y) * 20 + x;
            ref.visibility[i] = 0.0f;
            ref.blockerId[i] = 2.0f;
            ref.blockerDistance[i] = contact ? 0.01f : 5.0f;
        }
    scene::Frame map = test::uniformFrame(20, 20, 1, 0.5f, 1);
    map.attributes = {
        {"backend", "raster"}, {"texel_world_size", "0.01"}, {"depth_bias", "0.005"}, {"slope_bias", "1"}};
    ReportInput in;
    in.sceneName = "poles";
    in.objectNames = {"ground", "pole"};
    in.reference = {"reference", "reference.png", ref};
    in.methods.push_back({"raster", "raster.png", "diff-raster.png", map, compareFrames(map, ref).metrics});
    const Metrics& m = in.methods[0].metrics;
    ASSERT_EQ(m.missedShadow, 140u);
    ASSERT_EQ(m.biasLeak, 40u);
    std::istringstream lines(describeFindings(in));
    std::string text;
    std::getline(lines, text);
    EXPECT_NE(text.find(formatPercent(40.0 / 140.0) + " of it (40 px) within the contact distance of its blocker"),
              std::string::npos)
        << text;
    EXPECT_NE(text.find("peter-panning, the shadow cut off where its caster meets the receiver"), std::string::npos)
        << text;
    EXPECT_EQ(text.find("rather than bias"), std::string::npos) << text;
}

TEST(Report, FindingsSayAnExactMatchAndAFailure) {
    ReportInput in = syntheticRun();
    in.methods.resize(1);
    test::SyntheticOptions o;
    o.width = 120;
    o.height = 68;
    const scene::Frame f = test::syntheticFrame(o);
    in.methods[0].metrics = compareFrames(f, f).metrics;
    in.failures.push_back({"raster", "no Vulkan device"});
    const std::string text = describeFindings(in);
    EXPECT_NE(text.find("matches the reference on all"), std::string::npos) << text;
    EXPECT_NE(text.find("The raster backend failed: no Vulkan device"), std::string::npos) << text;
    EXPECT_NE(renderReportHtml(in).find("no Vulkan device"), std::string::npos);
}

TEST(Report, WriteReportWritesReportHtmlAndNoTemporaryFile) {
    const fs::path dir = fs::path(::testing::TempDir()) / "compare_report_test";
    fs::remove_all(dir);
    fs::create_directories(dir);
    const ReportInput in = syntheticRun();
    writeReport(dir, in);
    std::ifstream file(dir / "report.html");
    std::stringstream text;
    text << file.rdbuf();
    EXPECT_EQ(text.str(), renderReportHtml(in));
    EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
    fs::remove_all(dir);
}

TEST(FrameInfo, KeepsSizeMetadataAndTimingsOfAFrame) {
    scene::Frame f = scene::Frame::allocate(7, 3, false);
    f.attributes["backend"] = "raster";
    f.timingsMs = {{"a", 1.0}, {"b", 2.5}};
    const FrameInfo info = f;
    EXPECT_EQ(info.width, 7);
    EXPECT_EQ(info.height, 3);
    EXPECT_EQ(info.attributes.at("backend"), "raster");
    EXPECT_DOUBLE_EQ(info.totalTimeMs(), 3.5);
}

}  // namespace
}  // namespace shadowlab::compare

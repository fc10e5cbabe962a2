// tests/app/browser_test.cpp: every HTML page shadowlab writes, opened in headless Chromium by
// tools/browser-check.sh (console errors, missing images and links, empty SVG plots, overflowing
// text), and hand-written bad pages that prove each of its checks fails when it should. The pages
// and their screenshots stay in BUILD/browser-check/ for CI to keep (docs/ci.md).
#include <sys/wait.h>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/app/cli.h"

namespace fs = std::filesystem;

namespace shadowlab {
namespace {

const fs::path kSource = SHADOWLAB_SOURCE_DIR;
const fs::path kBuild = SHADOWLAB_BINARY_DIR;

using test::shellQuote;

struct CheckResult {
    int exitCode = -1;
    std::vector<std::string> lines;  // one per problem, "PAGE: KIND: ELEMENT: detail"
    std::string err;
};

// Runs tools/browser-check.sh on the inputs, screenshots into shots.
CheckResult browserCheck(const std::vector<fs::path>& inputs, const fs::path& shots) {
    test::TempDir io;
    std::string cmd = "SHADOWLAB_BUILD_DIR=" + shellQuote(kBuild.string()) +
                      " SHADOWLAB_BROWSER_SCREENSHOTS=" + shellQuote(shots.string()) + " " +
                      shellQuote((kSource / "tools" / "browser-check.sh").string());
    for (const auto& p : inputs) {
        cmd += ' ';
        cmd += shellQuote(p.string());
    }
    cmd += " >" + shellQuote((io.path() / "out").string()) + " 2>" + shellQuote((io.path() / "err").string());
    const int status = std::system(cmd.c_str());
    CheckResult r;
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    std::istringstream out(test::slurpFile(io.path() / "out"));
    for (std::string line; std::getline(out, line);)
        if (!line.empty()) r.lines.push_back(line);
    r.err = test::slurpFile(io.path() / "err");
    return r;
}

std::string joined(const std::vector<std::string>& lines) {
    std::string s;
    for (const auto& l : lines) s += l + "\n";
    return s;
}

// The problem lines about one page (by file name).
std::vector<std::string> linesOf(const CheckResult& r, const std::string& page) {
    std::vector<std::string> out;
    for (const auto& l : r.lines)
        if (l.find("/" + page + ": ") != std::string::npos) out.push_back(l);
    return out;
}

TEST(BrowserCheck, EachKindOfBadPageFailsWithItsOwnProblem) {
    const fs::path pages = kSource / "tests" / "app" / "browser_pages";
    test::TempDir shots;
    const CheckResult r = browserCheck({pages}, shots.path());
    ASSERT_EQ(r.exitCode, 1) << r.err << joined(r.lines);

    // page -> what its one problem line must say ("KIND: ...detail").
    const std::map<std::string, std::vector<std::string>> expected = {
        {"missing-image.html", {": image: img", "no-such-image.png: no such file"}},
        {"missing-svg-image.html", {": image: svg > image", "no-such-frame.png: no such file"}},
        {"missing-css-image.html", {": image: style sheet", "no-such-texture.png: no such file"}},
        {"undecodable-image.html", {": image: img", "corrupt.png: did not load or decode"}},
        {"broken-link.html", {": link: p > a", "sweep/no-such-report.html: no such file"}},
        {"broken-anchor.html", {": link: p > a", "#no-such-section: no element with that id"}},
        {"empty-svg.html", {": svg: svg", "draws nothing"}},
        {"zero-size-svg.html", {": svg: svg", "zero-size box 0x0"}},
        {"overflowing-cell.html", {": overflow: table > tbody > tr > td", "text \"a_name_far_too_long", "sticks out"}},
        {"overflowing-table.html", {": overflow: div.box", "div > table", "sticks out by"}},
        {"overflowing-text.html", {": overflow: div.label", "text \"a caption that does not fit", "sticks out"}},
        {"overflowing-height.html", {": overflow: div.note", "div > p \"Second line, below the box.\" sticks out by"}},
        {"clipped-text.html", {": overflow: div.cap", "text \"a caption cut off", "is clipped by"}},
        {"svg-text-outside.html",
         {": overflow: svg > text \"a label running off the plot\"", "sticks out of its plot"}},
        {"console-error.html", {": console: error: plot data missing"}},
        {"page-error.html", {": console: page error: undefinedFunctionOfThePlot is not defined"}},
    };
    for (const auto& [page, words] : expected) {
        SCOPED_TRACE(page);
        const auto lines = linesOf(r, page);
        ASSERT_EQ(lines.size(), 1u) << joined(r.lines);
        for (const auto& w : words) EXPECT_NE(lines[0].find(w), std::string::npos) << w << " in " << lines[0];
    }
    // A NaN in a plot's points is named by the SVG check; Chromium's own parser complains too.
    const auto nan = linesOf(r, "nan-svg.html");
    EXPECT_EQ(nan.size(), 2u) << joined(nan);
    EXPECT_NE(joined(nan).find(": svg: svg > polyline: points=\"0,10 NaN,nan 300,20\" is not a number"),
              std::string::npos)
        << joined(nan);
    // The control page (an image, links, a plot, a wide table in a scroll box) passes.
    EXPECT_TRUE(linesOf(r, "good.html").empty()) << joined(linesOf(r, "good.html"));
    EXPECT_EQ(r.lines.size(), expected.size() + 2) << joined(r.lines);
    // Every page gets its screenshot, named after it.
    for (const auto& e : fs::directory_iterator(pages))
        if (e.path().extension() == ".html") {
            const fs::path png = shots.path() / e.path().filename().replace_extension(".png");
            EXPECT_TRUE(fs::is_regular_file(png)) << png;
        }
}

TEST(BrowserCheck, AGoodPagePassesAndBadUsageIsExitTwo) {
    test::TempDir shots;
    const CheckResult good = browserCheck({kSource / "tests" / "app" / "browser_pages" / "good.html"}, shots.path());
    EXPECT_EQ(good.exitCode, 0) << good.err << joined(good.lines);
    EXPECT_TRUE(fs::is_regular_file(shots.path() / "good.png"));
    const CheckResult none = browserCheck({shots.path() / "no-such-folder"}, shots.path());
    EXPECT_EQ(none.exitCode, 2);
    EXPECT_NE(none.err.find("no-such-folder: no such file or folder"), std::string::npos) << none.err;
}

// Writes every kind of page at a small size into BUILD/browser-check/pages and checks them all;
// screenshots go to BUILD/browser-check/screenshots (or $SHADOWLAB_BROWSER_SCREENSHOTS).
TEST(BrowserCheck, EveryPageShadowlabWritesLoadsRendersAndFits) {
    const fs::path pages = kBuild / "browser-check" / "pages";
    fs::remove_all(pages);
    fs::create_directories(pages);
    const auto run = [&](const std::vector<std::string>& args) {
        const test::CliResult r = test::runShadowlab(args);
        EXPECT_EQ(r.exitCode, 0) << args[0] << ": " << r.err;
    };
    const std::string res = "128x72";
    // `run` writes report.html and, with its quick sweep, sweep/report.html.
    run({"run", "seed", "-o", (pages / "run").string(), "--resolution", res, "--shadow-map-size", "512"});
    run({"sweep", "seed", "-o", (pages / "sweep").string(), "--quick", "--resolution", "64x36", "--repetitions", "1"});
    run({"stability", "extreme/straight-down", "extreme/grazing-1deg", "-o", (pages / "stability").string(),
         "--resolution", "48x27", "--no-search"});
    run({"path", "seed", "-o", (pages / "path").string(), "--frames", "3", "--resolution", "64x36", "--shadow-map-size",
         "512"});
    // `check`: summary.html, with the difference image of the case that fails (no ray bias: acne).
    const fs::path suite = pages / "suite.json";
    {
        std::ofstream(suite) << R"({"description": "browser check", "resolution": "64x36",
            "cases": [{"name": "seed.raster", "scene": "seed", "backend": "raster"},
                      {"name": "seed.raytrace.acne", "scene": "seed", "backend": "raytrace",
                       "settings": {"ray_bias": 0}, "budgets": {"max_false_shadow": "0px"}}]})";
    }
    const test::CliResult check = test::runShadowlab({"check", suite.string(), "-o", (pages / "check").string()});
    EXPECT_EQ(check.exitCode, 3) << check.err;
    EXPECT_TRUE(fs::is_regular_file(pages / "check" / "cases" / "seed.raytrace.acne-diff.png"));

    // The demos' synthetic reports reach what small real runs may not: a hotspot zoom on every
    // method, the default sweep grid, configurations that failed.
    for (const auto& [exe, folder] : {std::pair{REPORT_DEMO, "demo-run"}, std::pair{SWEEP_REPORT_DEMO, "demo-sweep"}}) {
        const std::string cmd = shellQuote(exe) + " " + shellQuote((pages / folder).string()) + " >/dev/null 2>&1";
        EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
    }

    std::set<std::string> html;
    for (const auto& e : fs::recursive_directory_iterator(pages))
        if (e.path().extension() == ".html") html.insert(fs::relative(e.path(), pages).string());
    for (const char* p : {"run/report.html", "run/sweep/report.html", "sweep/report.html", "stability/stability.html",
                          "path/report.html", "check/summary.html", "demo-run/report.html", "demo-sweep/report.html",
                          "demo-sweep/sweep/report.html"})
        EXPECT_TRUE(html.count(p)) << p << " was not written";

    const char* env = std::getenv("SHADOWLAB_BROWSER_SCREENSHOTS");
    const fs::path shots = env && *env ? fs::path(env) : kBuild / "browser-check" / "screenshots";
    fs::remove_all(shots);
    const CheckResult r = browserCheck({pages}, shots);
    EXPECT_EQ(r.exitCode, 0) << r.err << joined(r.lines);
    for (const auto& p : html) {
        std::string name = p;
        for (std::size_t i; (i = name.find('/')) != std::string::npos;) name.replace(i, 1, "__");
        EXPECT_TRUE(fs::is_regular_file(shots / fs::path(name).replace_extension(".png"))) << name;
    }

    // The same check fails on a copy of a real report that lost an image (the pages above stay
    // whole: they are CI's artifacts): the page and the file are named.
    test::TempDir copy;
    fs::copy(pages / "run", copy.path() / "run", fs::copy_options::recursive);
    fs::remove(copy.path() / "run" / "diff-raster.png");
    const CheckResult broken = browserCheck({copy.path() / "run" / "report.html"}, copy.path() / "shots");
    EXPECT_EQ(broken.exitCode, 1) << broken.err;
    bool named = false;
    for (const auto& l : broken.lines)
        named = named || (l.find("run/report.html: image: ") != std::string::npos &&
                          l.find("diff-raster.png: no such file") != std::string::npos);
    EXPECT_TRUE(named) << joined(broken.lines);
}

}  // namespace
}  // namespace shadowlab

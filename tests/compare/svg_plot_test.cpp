// tests/compare/svg_plot_test.cpp: axis ticks and the placement of points on linear and log
// axes, checked against positions derived from the axis mapping, not from the program's output.
#include "compare/svg_plot.h"

#include <regex>

#include <gtest/gtest.h>

namespace shadowlab::compare {
namespace {

// The cx of every <circle> in document order.
std::vector<double> circleX(const std::string& svg) {
    std::vector<double> xs;
    const std::regex re("<circle cx=\"([-0-9.]+)\"");
    for (auto it = std::sregex_iterator(svg.begin(), svg.end(), re); it != std::sregex_iterator(); ++it)
        xs.push_back(std::stod((*it)[1]));
    return xs;
}

std::size_t count(const std::string& s, const std::string& what) {
    std::size_t n = 0;
    for (auto p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
    return n;
}

TEST(AxisTicks, LinearTicksAreNiceSteps) {
    const auto u = axisTicks(0.0, 1.0, false);  // range 1 over ~5 ticks: step 0.2
    ASSERT_EQ(u.size(), 6u);
    for (std::size_t i = 0; i < u.size(); ++i) EXPECT_NEAR(u[i], 0.2 * double(i), 1e-12);
    const auto t = axisTicks(0.0, 0.1, false);  // step 0.02
    ASSERT_EQ(t.size(), 6u);
    EXPECT_NEAR(t[1], 0.02, 1e-12);
    EXPECT_EQ(t.front(), 0.0);
}

TEST(AxisTicks, LogTicksAreDecadesWithTwoAndFiveOnShortRanges) {
    EXPECT_EQ(axisTicks(1.0, 100.0, true), (std::vector<double>{1, 2, 5, 10, 20, 50, 100}));
    EXPECT_EQ(axisTicks(1.0, 10000.0, true), (std::vector<double>{1, 10, 100, 1000, 10000}));
    EXPECT_TRUE(axisTicks(0.0, 10.0, true).empty());  // no log axis through zero
}

TEST(RenderSvg, LogAxisSpacesDecadesEquallyAndLinearDoesNot) {
    ScatterPlot p;
    PlotSeries s;
    s.name = "m";
    s.color = "#123456";
    s.points = {{1, 0.5}, {10, 0.5}, {100, 0.5}};
    p.series = {s};
    p.y.min = 0.0;
    p.y.max = 1.0;
    p.x.log = true;
    p.x.min = 1.0;
    p.x.max = 100.0;
    const auto lx = circleX(renderSvg(p));
    ASSERT_EQ(lx.size(), 4u);  // the legend dot first, then the three points
    // log10: 1, 10, 100 are 0, 1, 2 decades: equal gaps.
    EXPECT_NEAR(lx[2] - lx[1], lx[3] - lx[2], 0.02);
    EXPECT_GT(lx[2], lx[1]);
    p.x.log = false;
    const auto xs = circleX(renderSvg(p));
    // Linear: the gaps are 9 and 90 units, a ratio of 10.
    EXPECT_NEAR((xs[3] - xs[2]) / (xs[2] - xs[1]), 10.0, 0.01);
}

TEST(RenderSvg, ZeroOnALogAxisIsDrawnAsAnEdgeTriangleNotDropped) {
    ScatterPlot p;
    p.y.log = true;
    PlotSeries s;
    s.name = "zero error";
    s.color = "teal";
    s.points = {{1, 0.0, "zero"}, {2, 0.01, "some"}};
    p.series = {s};
    const std::string svg = renderSvg(p);
    EXPECT_EQ(count(svg, "<path d="), 1u);
    EXPECT_EQ(count(svg, "<circle"), 2u);  // legend + the positive point
}

TEST(RenderSvg, AWholeNumberAxisTicksOnlyWholeNumbers) {
    // Frame pairs 0..1 (a 3-frame path): a linear axis would tick 0, 0.2 .. 1; pair 0.4 is no pair.
    ScatterPlot p;
    p.x.min = 0.0;
    p.x.max = 1.0;
    p.x.integer = true;
    p.y.min = 0.0;
    p.y.max = 10.0;
    p.series.push_back({"a", "#123456", {{0.0, 1.0, "", ""}, {1.0, 2.0, "", ""}}});
    const std::string svg = renderSvg(p);
    EXPECT_EQ(count(svg, "text-anchor=\"middle\">0<"), 1u) << svg;
    EXPECT_EQ(count(svg, "text-anchor=\"middle\">1<"), 1u) << svg;
    EXPECT_EQ(count(svg, ">0.2<") + count(svg, ">0.4<") + count(svg, ">0.5<"), 0u) << svg;
    // A long range keeps its nice steps (all whole): 0, 20 .. 100.
    p.x.max = 100.0;
    const std::string wide = renderSvg(p);
    EXPECT_EQ(count(wide, "text-anchor=\"middle\">20<"), 1u) << wide;
    EXPECT_EQ(count(wide, "text-anchor=\"middle\">1<"), 0u) << wide;
}

TEST(RenderSvg, IsSelfContainedEscapedAndBalanced) {
    ScatterPlot p;
    p.title = "A < B & \"C\"";
    p.x.title = "time";
    p.y.title = "error";
    PlotSeries s;
    s.name = "raster";
    s.color = "#7048e8";
    s.connect = true;
    s.showLabels = true;
    s.points = {{1, 0.1, "a<b"}, {3, 0.05, "c"}};
    p.series = {s};
    p.markers = {{2.0, "reference"}};
    p.bands = {{1.5, 2.5, "window"}};
    p.note = "stiff";
    const std::string svg = renderSvg(p);
    EXPECT_EQ(svg.rfind("<svg xmlns=\"http://www.w3.org/2000/svg\"", 0), 0u);
    EXPECT_NE(svg.find("</svg>"), std::string::npos);
    EXPECT_NE(svg.find("A &lt; B &amp; &quot;C&quot;"), std::string::npos);
    EXPECT_NE(svg.find("a&lt;b"), std::string::npos);
    EXPECT_EQ(svg.find("a<b"), std::string::npos);
    EXPECT_EQ(count(svg, "<polyline"), 1u);
    EXPECT_EQ(count(svg, "class=\"band\""), 1u);
    EXPECT_EQ(count(svg, "class=\"marker\""), 1u);
    EXPECT_NE(svg.find(">window<"), std::string::npos);
    EXPECT_NE(svg.find(">reference<"), std::string::npos);
    EXPECT_EQ(count(svg, "<g"), count(svg, "</g>"));
    EXPECT_EQ(count(svg, "<text"), count(svg, "</text>"));
    EXPECT_EQ(svg.find("<script"), std::string::npos);
}

}  // namespace
}  // namespace shadowlab::compare

namespace shadowlab::compare {
namespace {

TEST(ErrorTimePlot, OneSeriesAndOneFrontPerBackendAndTheReferenceMarker) {
    const std::vector<SweepPoint> pts = {{"raster", 10, 0.05, "1024"},
                                         {"raster", 20, 0.01, "2048"},
                                         {"raster", 30, 0.02, "4096"},
                                         {"raytrace", 100, 0.001, "float"},
                                         {"raytrace", 200, 0.0, "double"}};
    const ScatterPlot p = errorTimePlot(pts, 900.0);
    ASSERT_EQ(p.series.size(), 4u);  // raster, raster front, raytrace, raytrace front
    EXPECT_EQ(p.series[0].name, "raster");
    EXPECT_EQ(p.series[0].points.size(), 3u);
    // Raster front: (10, 5%) and (20, 1%); (30, 2%) is slower and worse than (20, 1%).
    ASSERT_EQ(p.series[1].points.size(), 2u);
    EXPECT_TRUE(p.series[1].connect);
    EXPECT_EQ(p.series[1].points[1].x, 20);
    EXPECT_EQ(p.series[2].name, "raytrace");
    EXPECT_EQ(p.series[3].points.size(), 2u);
    ASSERT_EQ(p.markers.size(), 1u);
    EXPECT_EQ(p.markers[0].x, 900.0);
    EXPECT_TRUE(p.x.log);
    EXPECT_TRUE(p.y.log);
    for (const auto& s : p.series) {  // red and blue are reserved for the diff classes
        EXPECT_NE(s.color, "#e03131");
        EXPECT_NE(s.color, "#1c7ed6");
    }
    const std::string svg = renderSvg(p);
    EXPECT_EQ(count(svg, "<polyline"), 2u);
    EXPECT_EQ(count(svg, "<path d="), 1u);  // raytrace's zero error on the log axis
}

TEST(BiasPlot, ShadesTheWindowOrSaysStiff) {
    const std::vector<BiasSample> s = {{0.001, 0.1, 0}, {0.002, 0.0005, 0.0002}, {0.004, 0, 0.05}};
    const BiasWindow w = findBiasWindow(s, 0.001);
    const ScatterPlot p = biasPlot(s, w, "depth bias", true);
    ASSERT_EQ(p.bands.size(), 1u);
    EXPECT_EQ(p.bands[0].x0, 0.002);
    EXPECT_EQ(p.bands[0].x1, 0.002);
    EXPECT_EQ(p.series[0].points.size(), 3u);   // false shadow
    EXPECT_EQ(p.series[1].points.size(), 3u);   // missed shadow
    EXPECT_EQ(p.series[2].points[0].y, 0.001);  // threshold line
    EXPECT_TRUE(p.note.empty());
    BiasWindow stiff = w;
    stiff.stiff = true;
    const ScatterPlot q = biasPlot(s, stiff, "depth bias", true);
    EXPECT_TRUE(q.bands.empty());
    EXPECT_NE(renderSvg(q).find("stiff"), std::string::npos);
}

}  // namespace
}  // namespace shadowlab::compare

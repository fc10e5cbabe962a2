// compare/report.h: the one-page HTML report of `shadowlab run`: reference, each method's
// image and difference image with a legend, metrics, stage timings, an error-vs-time plot and a
// paragraph in words. Self-contained: inline CSS and SVG, images by relative file name.
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "compare/compare.h"
#include "scene/frame.h"

namespace shadowlab::compare {

// What the report needs from a Frame, without its pixels (converts implicitly from a Frame).
struct FrameInfo {
    FrameInfo() = default;
    FrameInfo(const scene::Frame& frame);  // NOLINT: implicit on purpose, {label, png, frame}
    int width = 0, height = 0;
    std::map<std::string, std::string> attributes;  // backend, settings, version...
    std::vector<std::pair<std::string, double>> timingsMs;
    double totalTimeMs() const;
};

struct ReportImage {
    std::string label;  // "reference"
    std::string png;    // file name beside report.html
    FrameInfo frame;
};

struct ReportMethod {
    std::string label;    // "raster", "raytrace"
    std::string png;      // its beauty image, beside report.html
    std::string diffPng;  // its difference image
    FrameInfo frame;
    Metrics metrics;
    std::string heatPng;                     // its |V_M − V_R| heat map; "" = none
    std::vector<std::string> lightHeatPngs;  // one per light (Metrics::perLight), may be empty
};

// A display image of the raster backend's shadow maps (`render --view`), with what it shows.
struct ReportView {
    std::string title;  // "light frustum"
    std::string png;    // file name beside report.html
    int width = 0, height = 0;
    std::string caption;
};

struct ReportFailure {
    std::string label;    // backend that failed
    std::string message;  // its error
};

// The small sweep `run` includes (studies/sweep_report.h summarizeSweep() fills it): shown as
// its own section with a link to the sweep's full report.
struct SweepSummary {
    std::string href;                // the sweep's report, relative to report.html: "sweep/report.html"
    std::string errorTimeSvg;        // inline SVG: error against per-frame time, with Pareto fronts
    std::vector<std::string> lines;  // findings in words: fastest under 1% per backend, bias windows
    std::string shadowBlockJson;     // the recommended scene-file "shadow" block, pretty-printed
    std::size_t configurations = 0;  // rows in the sweep, failed ones included
    std::size_t failed = 0;
    std::string resolution;  // "640x360", the sweep's render size
};

struct ReportInput {
    std::string sceneName;  // shown as the title
    std::string scenePath;
    std::string planText;  // RenderPlan::explain(), shown verbatim
    ReportImage reference;
    std::vector<ReportMethod> methods;
    std::vector<ReportFailure> failures;
    // Scene object names by index (object id - 1), to say "acne on the plane"; optional.
    std::vector<std::string> objectNames;
    // The raster backend's debug views; empty: no "Inside the shadow maps" section.
    std::vector<ReportView> shadowMapViews;
    // Warnings about the configuration (a light with a radius under a hard filter), shown in the
    // findings; `run` also prints them on stderr.
    std::vector<std::string> warnings;
    // The quick sweep `run` renders into DIR/sweep/; absent: no sweep section.
    std::optional<SweepSummary> sweep;
    // The factor the images were scaled by for display (scene::displayExposure); 1: none.
    double displayExposure = 1.0;
};

// The page as a string (what writeReport writes), for tests and other pages.
std::string renderReportHtml(const ReportInput& input);
// The paragraph in words summarising what the comparison found.
std::string describeFindings(const ReportInput& input);
// Writes dir/report.html atomically. The image files are not checked or copied.
void writeReport(const std::filesystem::path& dir, const ReportInput& input);

// Pieces of the page the sweep report (studies/sweep_report.cpp) reuses, so both pages look
// and zoom alike.
namespace html {
// The page's stylesheet (inline in <style>).
const char* css();
// An image with a caption; with a hotspot, the yellow square that marks the zoomed region.
std::string figure(const std::string& caption, const std::string& note, const std::string& png, const FrameInfo& frame,
                   const ErrorHotspot* hotspot);
// A square crop of `png` around the hotspot, magnified with hard pixel edges (pure CSS).
std::string zoomCrop(const std::string& png, const FrameInfo& frame, const ErrorHotspot& hotspot,
                     const std::string& alt);
// The color legend of the difference images.
std::string diffLegend();
// The color scale of the error heat maps (HeatScale), as a bar with its ticks.
std::string heatLegend();
}  // namespace html

}  // namespace shadowlab::compare

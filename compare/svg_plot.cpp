// compare/svg_plot.cpp: writes ScatterPlot as SVG text: axes with nice ticks (linear or log),
// series, markers and bands. Coordinates are clamped to the plot area instead of clip paths,
// so several plots can sit inline in one HTML page without id clashes.
#include "compare/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "compare/pareto.h"
#include "compare/text.h"

namespace shadowlab::compare {

namespace {

constexpr double kLeft = 74, kRight = 24, kTop = 58, kBottom = 54;  // margins in px
constexpr const char* kFont = "font-family=\"system-ui,-apple-system,'Segoe UI',Roboto,sans-serif\"";

std::string num(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2f", v);
    return buf;
}

std::string tickLabel(double v, bool percent) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", percent ? v * 100.0 : v);
    return std::string(buf) + (percent ? "%" : "");
}

double niceStep(double range, int targetTicks) {
    const double raw = range / std::max(1, targetTicks);
    const double mag = std::pow(10.0, std::floor(std::log10(raw)));
    const double f = raw / mag;
    const double nice = f <= 1.0 ? 1.0 : f <= 2.0 ? 2.0 : f <= 5.0 ? 5.0 : 10.0;
    return nice * mag;
}

struct Range {
    double lo = 0.0, hi = 1.0;
    bool log = false;
    // Position in 0..1 along the axis; values off a log axis (≤ 0) map below 0.
    double t(double v) const {
        if (log) {
            if (!(v > 0.0)) return -1.0;
            return (std::log10(v) - std::log10(lo)) / (std::log10(hi) - std::log10(lo));
        }
        return (v - lo) / (hi - lo);
    }
};

Range fitRange(const PlotAxis& axis, const std::vector<double>& values) {
    Range r;
    r.log = axis.log;
    double lo = INFINITY, hi = -INFINITY;
    for (const double v : values) {
        if (!std::isfinite(v) || (axis.log && !(v > 0.0))) continue;
        lo = std::min(lo, v);
        hi = std::max(hi, v);
    }
    if (axis.log) {
        if (!(lo <= hi)) {  // nothing positive: a placeholder range
            lo = axis.percent ? 1e-4 : 1.0;
            hi = lo * 100.0;
        }
        lo = std::pow(10.0, std::floor(std::log10(lo)));
        hi = std::pow(10.0, std::ceil(std::log10(hi)));
        if (hi <= lo) hi = lo * 10.0;
    } else {
        if (!(lo <= hi)) {
            lo = 0.0;
            hi = axis.percent ? 0.01 : 1.0;
        }
        // Rates and other non-negative data read best from zero.
        if (lo >= 0.0 && (axis.percent || lo < 0.5 * hi)) lo = 0.0;
        if (hi == lo) hi = lo + (lo == 0.0 ? (axis.percent ? 0.01 : 1.0) : std::fabs(lo) * 0.2);
        hi += 0.06 * (hi - lo);
        const double step = niceStep(hi - lo, 5);
        lo = std::floor(lo / step) * step;
        hi = std::ceil(hi / step) * step;
    }
    if (axis.min) lo = *axis.min;
    if (axis.max) hi = *axis.max;
    if (!(hi > lo) || (axis.log && !(lo > 0.0))) {  // a bad fixed range: fall back
        PlotAxis free = axis;
        free.min.reset();
        free.max.reset();
        return fitRange(free, values);
    }
    r.lo = lo;
    r.hi = hi;
    return r;
}

// The opening tag of a marker of `shape` centred on (x, y), without its ">" or "/>" (a tooltip
// may go inside). Shapes other than the circle are paths of equal area, so none looks heavier.
std::string markerShape(int shape, double x, double y, double r, const std::string& color, double stroke) {
    std::ostringstream o;
    const std::string paint = "\" fill=\"" + color + "\" stroke=\"#fff\" stroke-width=\"" + num(stroke) + "\"";
    const int k = ((shape % 5) + 5) % 5;
    if (k == 0) {
        o << "<circle cx=\"" << num(x) << "\" cy=\"" << num(y) << "\" r=\"" << num(r) << paint;
        return o.str();
    }
    std::vector<std::pair<double, double>> pts;
    if (k == 1) {  // square
        const double a = r * 0.886;
        pts = {{-a, -a}, {a, -a}, {a, a}, {-a, a}};
    } else if (k == 2) {  // diamond
        const double a = r * 1.25;
        pts = {{0, -a}, {a, 0}, {0, a}, {-a, 0}};
    } else if (k == 3) {  // plus
        const double a = r * 1.15, b = r * 0.42;
        pts = {{-b, -a}, {b, -a}, {b, -b}, {a, -b}, {a, b},   {b, b},
               {b, a},   {-b, a}, {-b, b}, {-a, b}, {-a, -b}, {-b, -b}};
    } else {  // hexagon
        for (int i = 0; i < 6; ++i)
            pts.push_back({r * 1.1 * std::cos(i * 1.0471975512), r * 1.1 * std::sin(i * 1.0471975512)});
    }
    o << "<path d=\"";
    for (std::size_t i = 0; i < pts.size(); ++i)
        o << (i ? " L" : "M") << num(x + pts[i].first) << "," << num(y + pts[i].second);
    o << " Z" << paint;
    return o.str();
}

std::string markerEnd(int shape) { return ((shape % 5) + 5) % 5 == 0 ? "</circle>" : "</path>"; }

}  // namespace

std::vector<double> axisTicks(double lo, double hi, bool log) {
    std::vector<double> ticks;
    if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi)) return ticks;
    if (log) {
        if (!(lo > 0.0)) return ticks;
        const int d0 = static_cast<int>(std::floor(std::log10(lo) + 1e-9));
        const int d1 = static_cast<int>(std::ceil(std::log10(hi) - 1e-9));
        const bool fine = hi / lo < 999.999;               // fewer than three decades
        const int every = std::max(1, (d1 - d0 + 7) / 8);  // at most ~8 decade labels
        for (int d = d0; d <= d1; ++d) {
            if ((d - d0) % every != 0) continue;
            const double base = std::pow(10.0, d);
            for (const double m : {1.0, 2.0, 5.0}) {
                if (m != 1.0 && !fine) continue;
                const double v = m * base;
                if (v >= lo * (1.0 - 1e-9) && v <= hi * (1.0 + 1e-9)) ticks.push_back(v);
            }
        }
        return ticks;
    }
    const double step = niceStep(hi - lo, 5);
    const long long k0 = static_cast<long long>(std::ceil(lo / step - 1e-9));
    const long long k1 = static_cast<long long>(std::floor(hi / step + 1e-9));
    for (long long k = k0; k <= k1; ++k) {
        double v = static_cast<double>(k) * step;
        if (std::fabs(v) < step * 1e-9) v = 0.0;  // no "-0" or 1e-17 from rounding
        ticks.push_back(v);
    }
    return ticks;
}

std::string renderSvg(const ScatterPlot& plot) {
    std::vector<double> xs, ys;
    for (const auto& s : plot.series)
        for (const auto& p : s.points) {
            xs.push_back(p.x);
            ys.push_back(p.y);
        }
    for (const auto& m : plot.markers) xs.push_back(m.x);
    for (const auto& b : plot.bands) {
        xs.push_back(b.x0);
        xs.push_back(b.x1);
    }
    const Range rx = fitRange(plot.x, xs), ry = fitRange(plot.y, ys);

    const double W = plot.width, H = plot.height;
    const double x0 = kLeft, x1 = W - kRight, y0 = H - kBottom, y1 = kTop;  // y0 is the bottom
    auto px = [&](double v) { return x0 + std::clamp(rx.t(v), 0.0, 1.0) * (x1 - x0); };
    auto py = [&](double v) { return y0 - std::clamp(ry.t(v), 0.0, 1.0) * (y0 - y1); };
    // Below the axis range (or ≤ 0 on a log axis): drawn as a triangle on the low edge.
    auto offLow = [](const Range& r, double v) { return r.t(v) < -1e-9; };

    std::ostringstream o;
    o << "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"plot\" width=\"" << plot.width << "\" height=\""
      << plot.height << "\" viewBox=\"0 0 " << plot.width << " " << plot.height << "\" role=\"img\" aria-label=\""
      << escapeHtml(plot.title) << "\" " << kFont << " font-size=\"12\">\n";
    o << "<rect x=\"0\" y=\"0\" width=\"" << plot.width << "\" height=\"" << plot.height << "\" fill=\"#ffffff\"/>\n";
    o << "<text x=\"" << num(x0) << "\" y=\"22\" font-size=\"14\" font-weight=\"600\" fill=\"#1f2933\">"
      << escapeHtml(plot.title) << "</text>\n";

    // Legend on one line under the title.
    double lx = x0;
    for (const auto& s : plot.series) {
        if (s.name.empty()) continue;
        o << "<g class=\"legend\">";
        if (s.connect)
            o << "<line x1=\"" << num(lx) << "\" y1=\"40\" x2=\"" << num(lx + 18) << "\" y2=\"40\" stroke=\""
              << escapeHtml(s.color) << "\" stroke-width=\"2\"" << (s.dashed ? " stroke-dasharray=\"5 3\"" : "")
              << "/>";
        if (s.markers) o << markerShape(s.shape, lx + 9, 40, 4.5, escapeHtml(s.color), 1.0) << "/>";
        o << "<text x=\"" << num(lx + 24) << "\" y=\"44\" fill=\"#3e4c59\">" << escapeHtml(s.name) << "</text></g>\n";
        lx += 24 + 7.0 * static_cast<double>(s.name.size()) + 18;
    }

    // Bands under everything else.
    for (const auto& b : plot.bands) {
        const double a = px(std::min(b.x0, b.x1)), c = px(std::max(b.x0, b.x1));
        o << "<rect class=\"band\" x=\"" << num(a) << "\" y=\"" << num(y1) << "\" width=\"" << num(std::max(c - a, 1.5))
          << "\" height=\"" << num(y0 - y1) << "\" fill=\"" << escapeHtml(b.color)
          << "\" fill-opacity=\"0.14\" stroke=\"" << escapeHtml(b.color) << "\" stroke-opacity=\"0.5\"/>\n";
        if (!b.label.empty())
            o << "<text x=\"" << num(0.5 * (a + c)) << "\" y=\"" << num(y1 + 14) << "\" text-anchor=\"middle\" fill=\""
              << escapeHtml(b.color) << "\">" << escapeHtml(b.label) << "</text>\n";
    }

    // Grid, ticks and tick labels.
    o << "<g class=\"axes\" fill=\"#52606d\">\n";
    // A whole-number axis keeps the whole ticks; with fewer than two left, every whole number.
    auto ticksOf = [](double lo, double hi, bool log, bool integer) {
        std::vector<double> all = axisTicks(lo, hi, log), whole;
        if (!integer) return all;
        for (const double t : all)
            if (t == std::round(t)) whole.push_back(t);
        if (whole.size() < 2) {
            whole.clear();
            for (double t = std::ceil(lo); t <= hi; t += 1.0) whole.push_back(t);
        }
        return whole;
    };
    for (const double t : ticksOf(rx.lo, rx.hi, rx.log, plot.x.integer)) {
        const double x = px(t);
        o << "<line x1=\"" << num(x) << "\" y1=\"" << num(y1) << "\" x2=\"" << num(x) << "\" y2=\"" << num(y0)
          << "\" stroke=\"#e4e7eb\"/>";
        o << "<text x=\"" << num(x) << "\" y=\"" << num(y0 + 17) << "\" text-anchor=\"middle\">"
          << tickLabel(t, plot.x.percent) << "</text>\n";
    }
    for (const double t : ticksOf(ry.lo, ry.hi, ry.log, plot.y.integer)) {
        const double y = py(t);
        o << "<line x1=\"" << num(x0) << "\" y1=\"" << num(y) << "\" x2=\"" << num(x1) << "\" y2=\"" << num(y)
          << "\" stroke=\"#e4e7eb\"/>";
        o << "<text x=\"" << num(x0 - 8) << "\" y=\"" << num(y + 4) << "\" text-anchor=\"end\">"
          << tickLabel(t, plot.y.percent) << "</text>\n";
    }
    o << "<rect x=\"" << num(x0) << "\" y=\"" << num(y1) << "\" width=\"" << num(x1 - x0) << "\" height=\""
      << num(y0 - y1) << "\" fill=\"none\" stroke=\"#9aa5b1\"/>\n";
    o << "<text x=\"" << num(0.5 * (x0 + x1)) << "\" y=\"" << num(H - 12)
      << "\" text-anchor=\"middle\" fill=\"#3e4c59\">" << escapeHtml(plot.x.title) << (plot.x.log ? " (log scale)" : "")
      << "</text>\n";
    o << "<text transform=\"translate(16 " << num(0.5 * (y0 + y1))
      << ") rotate(-90)\" text-anchor=\"middle\" fill=\"#3e4c59\">" << escapeHtml(plot.y.title)
      << (plot.y.log ? " (log scale)" : "") << "</text>\n";
    o << "</g>\n";

    for (const auto& m : plot.markers) {
        const double x = px(m.x);
        o << "<g class=\"marker\"><line x1=\"" << num(x) << "\" y1=\"" << num(y1) << "\" x2=\"" << num(x) << "\" y2=\""
          << num(y0) << "\" stroke=\"#616e7c\" stroke-dasharray=\"4 4\"/>";
        if (!m.label.empty())
            o << "<text x=\"" << num(x - 5) << "\" y=\"" << num(y1 + 14) << "\" text-anchor=\"end\" fill=\"#616e7c\">"
              << escapeHtml(m.label) << "</text>";
        o << "</g>\n";
    }

    for (const auto& s : plot.series) {
        const std::string color = escapeHtml(s.color);
        if (s.connect && s.points.size() > 1) {
            std::vector<PlotPoint> sorted = s.points;
            std::stable_sort(sorted.begin(), sorted.end(),
                             [](const PlotPoint& a, const PlotPoint& b) { return a.x < b.x; });
            o << "<polyline fill=\"none\" stroke=\"" << color << "\" stroke-width=\"2\""
              << (s.dashed ? " stroke-dasharray=\"5 3\"" : "") << " points=\"";
            for (const auto& p : sorted)
                if (std::isfinite(p.x) && std::isfinite(p.y)) o << num(px(p.x)) << "," << num(py(p.y)) << " ";
            o << "\"/>\n";
        }
        for (const auto& p : s.points) {
            if (!std::isfinite(p.x) || !std::isfinite(p.y)) continue;
            const double x = px(p.x), y = py(p.y);
            if (s.markers) {
                o << "<g class=\"point\">";
                if (offLow(rx, p.x) || offLow(ry, p.y)) {
                    // Below a log axis: a triangle pointing off the plot, at its edge.
                    o << "<path d=\"M" << num(x - 5) << "," << num(y - 7) << " L" << num(x + 5) << "," << num(y - 7)
                      << " L" << num(x) << "," << num(y) << " Z\" fill=\"" << color
                      << "\" stroke=\"#fff\" stroke-width=\"1\">";
                } else {
                    o << markerShape(s.shape, x, y, 5, color, 1.2) << ">";
                }
                const std::string tip = p.title.empty() ? p.label : p.title;
                if (!tip.empty()) o << "<title>" << escapeHtml(tip) << "</title>";
                o << (offLow(rx, p.x) || offLow(ry, p.y) ? "</path>" : markerEnd(s.shape)) << "</g>\n";
            }
            if (s.showLabels && !p.label.empty()) {
                const bool right = x < x1 - 120;
                o << "<text x=\"" << num(right ? x + 8 : x - 8) << "\" y=\"" << num(y - 8) << "\" text-anchor=\""
                  << (right ? "start" : "end") << "\" fill=\"" << color << "\" font-weight=\"600\">"
                  << escapeHtml(p.label) << "</text>\n";
            }
        }
    }
    if (!plot.note.empty())  // inside the plot, top right: a verdict, not a footnote
        o << "<text x=\"" << num(x1 - 8) << "\" y=\"" << num(y1 + 18)
          << "\" text-anchor=\"end\" font-size=\"13\" font-weight=\"600\" fill=\"#d9480f\">" << escapeHtml(plot.note)
          << "</text>\n";
    o << "</svg>\n";
    return o.str();
}

std::string backendColor(const std::string& backend, std::size_t index) {
    if (backend == "raster") return "#7048e8";    // violet
    if (backend == "raytrace") return "#0c8599";  // teal
    static const char* kOthers[] = {"#e67700", "#5c940d", "#a61e4d", "#495057"};
    return kOthers[index % 4];
}

ScatterPlot errorTimePlot(const std::vector<SweepPoint>& points, double referenceTimeMs,
                          const ErrorTimeOptions& options) {
    ScatterPlot p;
    p.title = options.title;
    p.x = {"run time per frame, ms", true, false, {}, {}};
    p.y = {options.errorName, options.logError, true, {}, {}};
    std::vector<std::string> backends;
    for (const auto& pt : points)
        if (std::find(backends.begin(), backends.end(), pt.backend) == backends.end()) backends.push_back(pt.backend);
    std::vector<std::string> machines;
    for (const auto& pt : points)
        if (std::find(machines.begin(), machines.end(), pt.machine) == machines.end()) machines.push_back(pt.machine);
    const bool perMachine = machines.size() > 1;
    for (std::size_t b = 0; b < backends.size(); ++b) {
        PlotSeries s;
        s.name = backends[b];
        s.color = backendColor(backends[b], b);
        s.showLabels = options.labels;
        std::vector<TimeErrorPoint> te;
        std::vector<PlotSeries> byMachine(perMachine ? machines.size() : 0, s);
        for (const auto& pt : points) {
            if (pt.backend != backends[b]) continue;
            const std::string tip = pt.backend + (pt.label.empty() || pt.label == pt.backend ? "" : " " + pt.label) +
                                    ": " + formatDuration(pt.timeMs) + ", " + formatPercent(pt.error) +
                                    (perMachine ? " (timed on " + pt.machine + ")" : "");
            s.points.push_back({pt.timeMs, pt.error, pt.label, tip});
            te.push_back({pt.timeMs, pt.error});
            if (perMachine) {
                const std::size_t m =
                    std::size_t(std::find(machines.begin(), machines.end(), pt.machine) - machines.begin());
                byMachine[m].points.push_back(s.points.back());
            }
        }
        if (perMachine) {
            for (std::size_t m = 0; m < machines.size(); ++m) {
                if (byMachine[m].points.empty()) continue;
                byMachine[m].name = backends[b] + " · " + (machines[m].empty() ? "unknown machine" : machines[m]);
                byMachine[m].shape = int(m);
                p.series.push_back(byMachine[m]);
            }
        } else {
            p.series.push_back(s);
        }
        if (options.fronts && s.points.size() > 1) {
            PlotSeries front;
            front.color = s.color;
            front.markers = false;
            front.connect = true;
            for (const std::size_t i : paretoFront(te)) front.points.push_back(s.points[i]);
            if (front.points.size() > 1) p.series.push_back(front);
        }
    }
    if (referenceTimeMs > 0.0) p.markers.push_back({referenceTimeMs, "reference " + formatDuration(referenceTimeMs)});
    return p;
}

ScatterPlot biasPlot(const std::vector<BiasSample>& samples, const BiasWindow& window, const std::string& biasName,
                     bool logBias) {
    ScatterPlot p;
    p.title = "False and missed shadow against " + biasName;
    p.x = {biasName, logBias, false, {}, {}};
    // Log rates: the window is decided around the threshold (0.1%), far below the acne peak.
    p.y = {"rate of counted pixels", true, true, {}, {}};
    // Rates far below the threshold all mean "clean"; a floor three decades under it keeps the
    // axis on the part that matters (lower values sit on the bottom edge as triangles).
    double lowest = window.threshold;
    for (const auto& s : samples)
        for (const double r : {s.falseShadowRate, s.missedShadowRate})
            if (r > 0.0 && std::isfinite(r)) lowest = std::min(lowest, r);
    const double floor = window.threshold > 0.0 ? window.threshold * 1e-3 : 1e-6;
    if (lowest < floor) p.y.min = floor;
    std::vector<BiasSample> sorted = samples;
    std::stable_sort(sorted.begin(), sorted.end(),
                     [](const BiasSample& a, const BiasSample& b) { return a.bias < b.bias; });
    PlotSeries f{"false shadow (acne)", "#e03131", {}, true, true, false, false};
    PlotSeries m{"missed shadow (leaks)", "#1c7ed6", {}, true, true, false, false};
    for (const auto& s : sorted) {
        const std::string at = biasName + " " + formatShort(s.bias) + ": ";
        f.points.push_back({s.bias, s.falseShadowRate, "", at + formatPercent(s.falseShadowRate) + " false shadow"});
        m.points.push_back({s.bias, s.missedShadowRate, "", at + formatPercent(s.missedShadowRate) + " missed shadow"});
    }
    p.series = {f, m};
    if (!sorted.empty()) {
        PlotSeries t{"threshold " + formatPercent(window.threshold), "#868e96", {}, false, true, false, true};
        t.points = {{sorted.front().bias, window.threshold}, {sorted.back().bias, window.threshold}};
        p.series.push_back(t);
    }
    if (!window.stiff)
        p.bands.push_back({window.lo, window.hi, "bias window", "#2f9e44"});
    else
        p.note = "stiff: no bias window";
    return p;
}

}  // namespace shadowlab::compare

// tests/studies/sweep_rows.h: hand-made sweep rows (no rendering) for the auto-bias and sweep
// report tests and the sweep report demo: bias series with chosen rates, timed configurations.
#pragma once

#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "studies/sweep.h"

namespace shadowlab::studies::test {

// Metrics JSON with the fields the sweep report and auto bias read (compare::toJson names).
inline nlohmann::json rowMetrics(double falseRate, double missedRate, int width = 64, int height = 36) {
    return {{"width", width},
            {"height", height},
            {"false_shadow_rate", falseRate},
            {"missed_shadow_rate", missedRate},
            {"mismatch_rate", falseRate + missedRate},
            {"shadow_iou", 1.0 - 2.0 * (falseRate + missedRate)},
            {"hotspot", {{"x", 8}, {"y", 4}, {"size", 16}, {"wrong_pixels", falseRate + missedRate > 0 ? 12 : 0}}}};
}

inline SweepRow finish(SweepConfig c, double falseRate, double missedRate, double frameMs) {
    SweepRow r;
    r.config = std::move(c);
    r.key = r.config.key();
    r.repetitions = 3;
    r.setupMs = 40.0;
    r.frameMs = frameMs;
    r.frameMsMin = 0.9 * frameMs;
    r.frameMsMax = 1.2 * frameMs;
    r.metrics = rowMetrics(falseRate, missedRate);
    return r;
}

// A raster row of a constant depth-bias series (slope bias held at 0, map 1024, no filter), as
// defaultGrid builds them.
inline SweepRow depthRow(double bias, double falseRate, double missedRate, int mapSize = 1024, double frameMs = 5.0) {
    SweepConfig c;
    c.backend = scene::Backend::Raster;
    c.overrides.shadowMapSize = mapSize;
    c.overrides.filter = "none";
    c.overrides.depthBias = bias;
    c.overrides.slopeBias = 0.0;
    c.biasKind = "depth";
    c.biasValue = bias;
    return finish(c, falseRate, missedRate, frameMs);
}

// A raster row of a slope-bias series (constant depth bias held at 0).
inline SweepRow slopeRow(double bias, double falseRate, double missedRate, double frameMs = 5.0) {
    SweepConfig c;
    c.backend = scene::Backend::Raster;
    c.overrides.shadowMapSize = 1024;
    c.overrides.filter = "none";
    c.overrides.depthBias = 0.0;
    c.overrides.slopeBias = bias;
    c.biasKind = "slope";
    c.biasValue = bias;
    return finish(c, falseRate, missedRate, frameMs);
}

// A raster row of a filterable map's parameter series (`kind` a sweep axis such as
// "min_variance"), map 1024, the filter's other parameters at their defaults.
inline SweepRow momentRow(const std::string& filter, const std::string& kind, double value, double falseRate,
                          double missedRate, double frameMs = 6.0) {
    SweepConfig c;
    c.backend = scene::Backend::Raster;
    c.overrides.shadowMapSize = 1024;
    c.overrides.filter = filter;
    momentOverride(c.overrides, kind) = value;
    c.biasKind = kind;
    c.biasValue = value;
    return finish(c, falseRate, missedRate, frameMs);
}

// A ray tracer row of the constant ray-bias series in float.
inline SweepRow rayRow(double bias, double falseRate, double missedRate, double frameMs = 100.0) {
    SweepConfig c;
    c.backend = scene::Backend::Raytrace;
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", bias);
    c.overrides.rayBias = buf;
    c.overrides.precision = "float";
    c.biasKind = "ray";
    c.biasValue = bias;
    return finish(c, falseRate, missedRate, frameMs);
}

// A ray tracer row with robust offsets (no bias parameter).
inline SweepRow robustRow(const std::string& precision, double falseRate, double missedRate, double frameMs = 120.0) {
    SweepConfig c;
    c.backend = scene::Backend::Raytrace;
    c.overrides.rayBias = "robust";
    c.overrides.precision = precision;
    return finish(c, falseRate, missedRate, frameMs);
}

// A raster row at the default biases with a given map size and filter.
inline SweepRow mapRow(int size, const std::string& filter, double falseRate, double missedRate, double frameMs) {
    SweepConfig c;
    c.backend = scene::Backend::Raster;
    c.overrides.shadowMapSize = size;
    c.overrides.filter = filter;
    return finish(c, falseRate, missedRate, frameMs);
}

// A configuration that failed: an error and no metrics, as runSweep records it.
inline SweepRow failedRow(SweepRow r, const std::string& error) {
    r.error = error;
    r.metrics = nullptr;
    return r;
}

}  // namespace shadowlab::studies::test

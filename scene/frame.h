// scene/frame.h: what a render produces and the only thing compare reads: per-pixel AOVs,
// metadata and stage timings. Row 0 is the top of the image.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace shadowlab::scene {

struct Frame {
    int width = 0;
    int height = 0;
    std::vector<float> beauty;      // linear RGB, 3 floats per pixel
    std::vector<float> visibility;  // 0..1, 1 = fully lit; the shadow test before shading
    std::vector<float> objectId;    // 0 = background, else object index + 1 (exact up to 2^24)
    std::vector<float> ndotl;       // N·L at the primary hit (max over lights), 0 on background
    std::vector<float> depth;       // view depth along the camera's forward axis, 0 on background
    // Object id (index + 1) of the first blocker the shadow test found, 0 = none. Empty when
    // the backend cannot tell.
    std::vector<float> blockerId;
    // Metadata written as EXR header attributes: "backend", "scene", "version", settings...
    std::map<std::string, std::string> attributes;
    // Stage timings in milliseconds, in the order they ran ("setup", "shadow_pass", ...).
    std::vector<std::pair<std::string, double>> timingsMs;

    static Frame allocate(int width, int height, bool withBlockerId);
    std::size_t pixelCount() const { return std::size_t(width) * std::size_t(height); }
    double timing(const std::string& stage) const;  // 0 when absent
    double totalTimeMs() const;                      // sum of all stages
};

}  // namespace shadowlab::scene

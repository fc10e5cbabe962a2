// scene/frame.h: what a render produces and the only thing compare reads: per-pixel AOVs,
// metadata and stage timings. Row 0 is the top of the image.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

namespace shadowlab::scene {

// Which Frame channels a render is asked for (a bit mask). A backend fills at least these;
// the vectors of channels not asked for may stay empty. `render -o x.png` needs the beauty
// only; compare needs visibility, object id, N·L, Z (and blocker ids where a backend has them).
using ChannelMask = unsigned;
inline constexpr ChannelMask kChannelBeauty = 1u << 0;
inline constexpr ChannelMask kChannelVisibility = 1u << 1;
inline constexpr ChannelMask kChannelObjectId = 1u << 2;
inline constexpr ChannelMask kChannelNdotL = 1u << 3;
inline constexpr ChannelMask kChannelDepth = 1u << 4;
inline constexpr ChannelMask kChannelBlockerId = 1u << 5;
inline constexpr ChannelMask kChannelLightVisibility = 1u << 6;  // per light, > 1 light only
inline constexpr ChannelMask kAllChannels = (1u << 7) - 1;
// Not a channel but a promise about kChannelBeauty: it will only be written as an 8-bit sRGB
// image (`render -o x.png`). A backend may then deliver the beauty already quantized to the sRGB
// codes (decoded back to linear with srgbCodeToLinear, so that writing the PNG gives those codes
// again) and skip its float precision; the raster backend renders into an 8-bit sRGB target.
inline constexpr ChannelMask kBeautyForDisplay = 1u << 7;

// A typed metadata value, written as the EXR attribute type of its own: int, float, v3f, m44f.
// A matrix is held as GLM holds it (column vectors: p' = M·p); written to EXR, where matrices
// act on row vectors (p' = p·M), it is the transpose, which is GLM's memory order as it is.
using AttributeValue = std::variant<int, float, glm::vec3, glm::mat4>;

struct Frame {
    int width = 0;
    int height = 0;
    std::vector<float> beauty;      // linear RGB, 3 floats per pixel
    std::vector<float> visibility;  // 0..1, 1 = fully lit; the shadow test before shading
    std::vector<float> objectId;    // 0 = background, else object index + 1 (exact up to 2^24)
    std::vector<float> ndotl;       // N·L at the primary hit (max over the lights that reach it; -1 where none
                                    // does), 0 on background
    std::vector<float> depth;       // view depth along the camera's forward axis, 0 on background
    // Object id (index + 1) of the first blocker the shadow test found, 0 = none. Empty when
    // the backend cannot tell.
    std::vector<float> blockerId;
    // World distance along the shadow ray from its origin (the receiver, offset by the ray bias)
    // to the nearest blocker of the light that named blockerId, where blockerId > 0; 0 elsewhere.
    // The ray tracers and the reference write it (EXR channel "blocker_distance"); empty when the
    // backend cannot tell (raster) and in frames written before it. compare tells light bleeding
    // from bias leaks with it (docs/compare.md).
    std::vector<float> blockerDistance;
    // Per-light visibility (0..1, the shadow test of light i alone; 0 where light i does not
    // reach the point: N·L <= 0 or outside a spot's cone), one vector per light in scene order.
    // Only when the scene has more than one light (with one it equals `visibility`); written to
    // EXR as channels visibility.0, visibility.1, ...
    std::vector<std::vector<float>> lightVisibility;
    // Metadata written as EXR header attributes: "backend", "scene", "version", settings...
    std::map<std::string, std::string> attributes;
    // Numbers as typed EXR attributes: the camera as OpenEXR's standard "worldToCamera" and
    // "worldToNDC", each light's parameters ("light.0.intensity", ...); see frame_identity.h.
    std::map<std::string, AttributeValue> typedAttributes;
    // Stage timings in milliseconds, in the order they ran ("setup", "shadow_pass", ...).
    std::vector<std::pair<std::string, double>> timingsMs;

    static Frame allocate(int width, int height, bool withBlockerId);
    std::size_t pixelCount() const { return std::size_t(width) * std::size_t(height); }
    double timing(const std::string& stage) const;  // 0 when absent
    double totalTimeMs() const;                     // sum of all stages
};

}  // namespace shadowlab::scene

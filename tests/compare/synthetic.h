// tests/compare/synthetic.h: hand-made Frames for compare/ tests and the report demo: a disk
// ("sphere") above a floor ("plane") with a cast shadow, and method frames with the typical
// faults (speckled self-shadow acne, a shifted cast shadow, jagged shadow-map edges).
#pragma once

#include <cmath>
#include <cstdint>
#include <string>

#include "scene/frame.h"

namespace shadowlab::compare::test {

// A frame of w×h with every AOV set to `id`, `ndotl`, `visibility`; beauty follows the shading.
inline scene::Frame uniformFrame(int w, int h, float id, float ndotl, float visibility, bool withBlocker = false) {
    scene::Frame f = scene::Frame::allocate(w, h, withBlocker);
    for (std::size_t i = 0; i < f.pixelCount(); ++i) {
        f.objectId[i] = id;
        f.ndotl[i] = ndotl;
        f.visibility[i] = visibility;
        f.depth[i] = id > 0 ? 5.0f : 0.0f;
        const float c = 0.05f + 0.8f * std::fmax(0.0f, ndotl) * visibility;
        f.beauty[3 * i] = f.beauty[3 * i + 1] = f.beauty[3 * i + 2] = c;
    }
    return f;
}

struct SyntheticOptions {
    int width = 320, height = 180;
    bool acne = false;              // speckled self-shadow on the lit floor and the disk's terminator
    bool shiftShadow = false;       // the cast shadow detaches (peter-panning): false + missed
    bool jaggies = false;           // the floor's shadow test snaps to texelPx-sized texels
    bool rayAcne = false;           // a few self-shadowed pixels at the disk's grazing terminator
    double acneProbability = 0.08;  // share of lit plane pixels turned into acne speckles
    int shadowShiftPx = 6;          // peter-panning: the cast shadow moves right by this much
    int texelPx = 4;                // shadow-map texel size on screen for jagged edges
};

// Deterministic hash noise in 0..1 so tests and demo images do not depend on a RNG library.
inline double hashNoise(int x, int y) {
    std::uint32_t h = std::uint32_t(x) * 73856093u ^ std::uint32_t(y) * 19349663u;
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    h ^= h >> 15;
    return double(h & 0xffffffu) / double(0x1000000);
}

// Scene in screen space: rows above the horizon are background (id 0); the floor (id 1) is
// below it with N·L = 0.6; the "sphere" (id 2) is a disk whose N·L follows a light from the
// upper left (negative on its lower right, not counted). The cast shadow is an ellipse on the
// floor to the lower right of the disk.
inline scene::Frame syntheticFrame(const SyntheticOptions& o) {
    scene::Frame f = scene::Frame::allocate(o.width, o.height, true);
    const double w = o.width, h = o.height;
    const double horizon = 0.35 * h;
    const double cx = 0.42 * w, cy = 0.45 * h, r = 0.2 * h;
    const double sx = 0.56 * w, sy = 0.8 * h, sa = 0.24 * w, sb = 0.1 * h;  // shadow ellipse
    const double lx = -0.55, ly = 0.6, lz = 0.58;                           // toward the light
    for (int y = 0; y < o.height; ++y)
        for (int x = 0; x < o.width; ++x) {
            const std::size_t i = std::size_t(y) * o.width + x;
            const double px = x + 0.5, py = y + 0.5;
            float id = 0, ndotl = 0, vis = 1, blocker = 0, albedo = 0;
            const double dx = (px - cx) / r, dy = (py - cy) / r;
            if (dx * dx + dy * dy < 1.0) {
                id = 2;
                const double nz = std::sqrt(1.0 - dx * dx - dy * dy);
                ndotl = float(dx * lx - dy * ly + nz * lz);
                albedo = 0.75f;
                if (o.acne && ndotl > 0 && ndotl < 0.25 && hashNoise(x, y) < 3 * o.acneProbability) {
                    vis = 0;
                    blocker = 2;
                }
                if (o.rayAcne && ndotl > 0 && ndotl < 0.08 && hashNoise(x, y) < 0.3) {
                    vis = 0;
                    blocker = 2;
                }
            } else if (py > horizon) {
                id = 1;
                ndotl = 0.6f;
                albedo = 0.8f;
                double qx = px, qy = py;
                if (o.jaggies) {
                    // Shadow-map lookups happen per texel: snap to the texel grid (jaggies).
                    qx = (std::floor(px / o.texelPx) + 0.5) * o.texelPx;
                    qy = (std::floor(py / o.texelPx) + 0.5) * o.texelPx;
                }
                if (o.shiftShadow) qx -= o.shadowShiftPx;
                const double ex = (qx - sx) / sa, ey = (qy - sy) / sb;
                if (ex * ex + ey * ey < 1.0) {
                    vis = 0;
                    blocker = 2;
                }
                if (o.acne && vis > 0 && hashNoise(x, y) < o.acneProbability) {
                    vis = 0;
                    blocker = 1;
                }
            }
            f.objectId[i] = id;
            f.ndotl[i] = ndotl;
            f.visibility[i] = vis;
            f.blockerId[i] = blocker;
            f.depth[i] = id > 0 ? float(5.0 + py / h) : 0.0f;
            const float c = id > 0 ? albedo * (0.05f + 3.0f * 0.3f * std::fmax(0.0f, ndotl) * vis) : 0.05f;
            f.beauty[3 * i] = c * (id == 2 ? 1.0f : 0.9f);
            f.beauty[3 * i + 1] = c * 0.95f;
            f.beauty[3 * i + 2] = id > 0 ? c * (id == 2 ? 0.8f : 1.0f) : 0.08f;
        }
    return f;
}

}  // namespace shadowlab::compare::test

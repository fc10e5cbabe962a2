// raster/debug_views.cpp: the shadow-map, cascade, texel-density and light-frustum views.
#include "raster/debug_views.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "raster/tolerances.h"
#include "scene/camera.h"
#include "scene/frame_io.h"

namespace shadowlab::raster {

namespace {

// A 3x5 pixel font for the tile labels: each glyph is five rows of three bits, top row first.
struct Glyph {
    char c;
    unsigned char rows[5];
};
constexpr Glyph kGlyphs[] = {
    {'0', {7, 5, 5, 5, 7}}, {'1', {2, 6, 2, 2, 7}}, {'2', {7, 1, 7, 4, 7}}, {'3', {7, 1, 7, 1, 7}},
    {'4', {5, 5, 7, 1, 1}}, {'5', {7, 4, 7, 1, 7}}, {'6', {7, 4, 7, 5, 7}}, {'7', {7, 1, 1, 2, 2}},
    {'8', {7, 5, 7, 5, 7}}, {'9', {7, 5, 7, 1, 7}}, {'L', {4, 4, 4, 4, 7}}, {'C', {7, 4, 4, 4, 7}},
    {'X', {5, 5, 2, 5, 5}}, {'Y', {5, 5, 2, 2, 2}}, {'Z', {7, 1, 2, 4, 7}}, {'+', {0, 2, 7, 2, 0}},
    {'-', {0, 0, 7, 0, 0}}, {'O', {2, 5, 5, 5, 2}}, {'U', {5, 5, 5, 5, 7}}, {'T', {7, 2, 2, 2, 2}},
};

void fill(DisplayImage& img, int x0, int y0, int w, int h, const std::array<float, 3>& color) {
    for (int y = std::max(y0, 0); y < std::min(y0 + h, img.height); ++y)
        for (int x = std::max(x0, 0); x < std::min(x0 + w, img.width); ++x)
            for (int k = 0; k < 3; ++k)
                img.rgb[3 * (std::size_t(y) * std::size_t(img.width) + std::size_t(x)) + std::size_t(k)] =
                    color[std::size_t(k)];
}

// White text on a black box at (x0, y0), each font pixel `scale` image pixels.
void drawLabel(DisplayImage& img, int x0, int y0, const std::string& text, int scale) {
    const int advance = 4 * scale;
    fill(img, x0, y0, int(text.size()) * advance + scale, 7 * scale, {0.0f, 0.0f, 0.0f});
    for (std::size_t i = 0; i < text.size(); ++i) {
        const Glyph* g = nullptr;
        for (const Glyph& candidate : kGlyphs)
            if (candidate.c == text[i]) g = &candidate;
        if (!g) continue;  // space or unknown: blank
        for (int row = 0; row < 5; ++row)
            for (int col = 0; col < 3; ++col)
                if (g->rows[row] & (4 >> col))
                    fill(img, x0 + scale + int(i) * advance + col * scale, y0 + scale + row * scale, scale, scale,
                         {1.0f, 1.0f, 1.0f});
    }
}

float luminance(const float* linearRgb) {
    const float l = 0.2126f * linearRgb[0] + 0.7152f * linearRgb[1] + 0.0722f * linearRgb[2];
    return scene::linearToSrgb(std::clamp(l, 0.0f, 1.0f));
}

std::array<float, 3> mix(const std::array<float, 3>& a, const std::array<float, 3>& b, double t) {
    return {float(a[0] + (b[0] - a[0]) * t), float(a[1] + (b[1] - a[1]) * t), float(a[2] + (b[2] - a[2]) * t)};
}

}  // namespace

int shadowMapTileSize(std::uint32_t mapSize) { return int(std::min<std::uint32_t>(std::max(mapSize, 1u), 512u)); }

DisplayImage shadowMapView(const RenderDebug& debug) {
    const int layers = int(debug.layerDepths.size());
    const int n = std::max(layers, 1);
    const int cols = int(std::ceil(std::sqrt(double(n))));
    const int rows = (n + cols - 1) / cols;
    const int tile = shadowMapTileSize(debug.mapSize);
    DisplayImage img;
    img.width = cols * tile + (cols - 1) * kShadowMapViewGap;
    img.height = rows * tile + (rows - 1) * kShadowMapViewGap;
    img.rgb.assign(std::size_t(img.width) * std::size_t(img.height) * 3, 0.25f);
    const int size = int(debug.mapSize);
    const int block = (size + tile - 1) / tile;  // map texels per tile pixel, per side
    for (int l = 0; l < layers; ++l) {
        const std::vector<float>& d = debug.layerDepths[std::size_t(l)];
        float lo = std::numeric_limits<float>::infinity(), hi = -lo;
        for (const float v : d)
            if (v < 1.0f) {
                lo = std::min(lo, v);
                hi = std::max(hi, v);
            }
        const int x0 = (l % cols) * (tile + kShadowMapViewGap), y0 = (l / cols) * (tile + kShadowMapViewGap);
        for (int ty = 0; ty < tile; ++ty)
            for (int tx = 0; tx < tile; ++tx) {
                // The block of texels this tile pixel covers; its minimum depth (nearest the light).
                const int sx = tx * size / tile, sy = ty * size / tile;
                float m = 1.0f;
                for (int y = sy; y < std::min(sy + block, size); ++y)
                    for (int x = sx; x < std::min(sx + block, size); ++x)
                        m = std::min(m, d[std::size_t(y) * std::size_t(size) + std::size_t(x)]);
                std::array<float, 3> c{0.05f, 0.05f, 0.3f};
                if (m < 1.0f) {
                    const float t = hi > lo ? (m - lo) / (hi - lo) : 0.0f;
                    const float g = 1.0f - 0.85f * t;
                    c = {g, g, g};
                }
                fill(img, x0 + tx, y0 + ty, 1, 1, c);
            }
        if (std::size_t(l) < debug.layers.size())
            drawLabel(img, x0 + 2, y0 + 2, debug.layers[std::size_t(l)].label, std::max(1, tile / 128));
    }
    return img;
}

std::vector<int> cascadeIndices(const scene::Frame& frame, const RenderDebug& debug) {
    std::vector<int> out(frame.pixelCount(), -1);
    const std::vector<double> splits = cascadeSplits(debug.layers);
    const std::size_t count = splits.empty() ? 1 : splits.size() - 1;
    for (std::size_t i = 0; i < out.size(); ++i) {
        if (!(frame.objectId[i] > 0.0f)) continue;
        int c = 0;
        for (std::size_t k = 0; k + 1 < count; ++k)
            if (frame.depth[i] > float(splits[k + 1])) c = int(k) + 1;
        out[i] = c;
    }
    return out;
}

std::array<float, 3> cascadeTint(int cascade) {
    static const std::array<float, 3> kTints[] = {
        {1.0f, 0.3f, 0.3f}, {0.3f, 1.0f, 0.3f}, {0.35f, 0.5f, 1.0f}, {1.0f, 0.9f, 0.2f}};
    return kTints[std::size_t(std::clamp(cascade, 0, 3))];
}

DisplayImage cascadeView(const scene::Frame& frame, const RenderDebug& debug) {
    DisplayImage img{frame.width, frame.height, std::vector<float>(frame.pixelCount() * 3)};
    const std::vector<int> index = cascadeIndices(frame, debug);
    for (std::size_t i = 0; i < index.size(); ++i) {
        const float* b = &frame.beauty[3 * i];
        if (index[i] < 0) {
            for (int k = 0; k < 3; ++k)
                img.rgb[3 * i + std::size_t(k)] = scene::linearToSrgb(std::clamp(b[k], 0.0f, 1.0f));
            continue;
        }
        const std::array<float, 3> t = cascadeTint(index[i]);
        const float shade = 0.3f + 0.7f * luminance(b);
        for (int k = 0; k < 3; ++k) img.rgb[3 * i + std::size_t(k)] = t[std::size_t(k)] * shade;
    }
    return img;
}

double pixelWorldSize(const scene::CameraBasis& cam, double z) { return 2.0 * z * cam.tanHalfFovY / cam.height; }

std::vector<double> texelToPixelRatios(const scene::Frame& frame, const scene::Scene& scene, const RenderDebug& debug) {
    std::vector<double> out(frame.pixelCount(), std::numeric_limits<double>::quiet_NaN());
    if (debug.layers.empty()) return out;
    scene::Camera camera = scene.camera;
    camera.width = frame.width;
    camera.height = frame.height;
    const scene::CameraBasis cam = scene::cameraBasis(camera);
    const int light = debug.layers[0].light;
    const scene::Light& l = scene.lights[std::size_t(light)];
    const std::vector<int> cascade = cascadeIndices(frame, debug);
    const std::vector<double> texels = cascadeTexels(debug.layers);
    const bool cascaded = l.type == scene::LightType::Directional && !texels.empty();
    for (int y = 0; y < frame.height; ++y)
        for (int x = 0; x < frame.width; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(frame.width) + std::size_t(x);
            if (!(frame.objectId[i] > 0.0f)) continue;
            const double z = frame.depth[i];
            const scene::Vec3 p = cam.position + z * scene::pixelDirection(cam, x, y);
            double texel = 0.0;
            if (l.type == scene::LightType::Directional) {
                texel =
                    cascaded ? texels[std::size_t(std::max(cascade[i], 0))] : debug.layers[0].frustum.texelWorldSize();
            } else if (l.type == scene::LightType::Spot) {
                texel = debug.layers[0].frustum.texelWorldSize() *
                        glm::dot(p - l.position, debug.layers[0].frustum.direction);
            } else {
                const scene::Vec3 d = glm::abs(p - l.position);
                texel = debug.layers[0].frustum.texelWorldSize() * std::max(d.x, std::max(d.y, d.z));
            }
            out[i] = texel / pixelWorldSize(cam, z);
        }
    return out;
}

std::array<float, 3> densityColor(double ratio) {
    const std::array<float, 3> green{0.1f, 0.8f, 0.1f}, yellow{0.95f, 0.85f, 0.1f}, red{0.95f, 0.1f, 0.1f},
        cyan{0.1f, 0.8f, 0.85f}, blue{0.15f, 0.25f, 1.0f};
    const double t = std::clamp(std::log2(ratio) / 3.0, -1.0, 1.0);
    if (t >= 0.0) return t < 0.5 ? mix(green, yellow, t / 0.5) : mix(yellow, red, (t - 0.5) / 0.5);
    return t > -0.5 ? mix(green, cyan, -t / 0.5) : mix(cyan, blue, (-t - 0.5) / 0.5);
}

DisplayImage texelDensityView(const scene::Frame& frame, const scene::Scene& scene, const RenderDebug& debug) {
    DisplayImage img{frame.width, frame.height, std::vector<float>(frame.pixelCount() * 3, 0.15f)};
    const std::vector<double> ratio = texelToPixelRatios(frame, scene, debug);
    for (std::size_t i = 0; i < ratio.size(); ++i) {
        if (!std::isfinite(ratio[i]) || !(ratio[i] > 0.0)) continue;
        const std::array<float, 3> c = densityColor(ratio[i]);
        for (int k = 0; k < 3; ++k) img.rgb[3 * i + std::size_t(k)] = c[std::size_t(k)];
    }
    return img;
}

// --- The light-frustum view ---

bool insideLightMap(const LightFrustum& f, const scene::Vec3& p) {
    if (!f.perspective) {
        const scene::Vec3 q = p - f.center;
        const double along = glm::dot(q, f.direction);
        return std::abs(glm::dot(q, f.right)) <= f.halfWidth && std::abs(glm::dot(q, f.up)) <= f.halfWidth &&
               along >= f.nearDepth && along <= f.farDepth;
    }
    const scene::Vec3 q = p - f.position;
    const double d = glm::dot(q, f.direction);
    const double across = d * f.tanHalfFov;
    return d >= f.near && d <= f.far && std::abs(glm::dot(q, f.right) - d * f.windowU) <= across &&
           std::abs(glm::dot(q, f.up) - d * f.windowV) <= across;
}

std::array<scene::Vec3, 8> frustumCorners(const LightFrustum& f) {
    std::array<scene::Vec3, 8> c;
    for (int k = 0; k < 8; ++k) {
        const double su = (k & 1) ? 1.0 : -1.0, sv = (k & 2) ? 1.0 : -1.0;
        if (f.perspective) {
            const double d = (k & 4) ? f.far : f.near;
            c[std::size_t(k)] = f.position + d * (f.direction + (f.windowU + su * f.tanHalfFov) * f.right +
                                                  (f.windowV + sv * f.tanHalfFov) * f.up);
        } else {
            const double d = (k & 4) ? f.farDepth : f.nearDepth;
            c[std::size_t(k)] = f.center + su * f.halfWidth * f.right + sv * f.halfWidth * f.up + d * f.direction;
        }
    }
    return c;
}

ScreenPoint projectPoint(const scene::CameraBasis& cam, const scene::Vec3& p) {
    const scene::Vec3 d = p - cam.position;
    const double z = glm::dot(d, cam.forward);
    const double sx = glm::dot(d, cam.right) / (z * cam.tanHalfFovY * cam.aspect);
    const double sy = glm::dot(d, cam.up) / (z * cam.tanHalfFovY);
    return {(1.0 + sx) * 0.5 * cam.width, (1.0 - sy) * 0.5 * cam.height, z};
}

std::optional<ScreenSegment> projectSegment(const scene::CameraBasis& cam, double near, const scene::Vec3& a,
                                            const scene::Vec3& b) {
    const double za = glm::dot(a - cam.position, cam.forward), zb = glm::dot(b - cam.position, cam.forward);
    if (!(za >= near) && !(zb >= near)) return std::nullopt;
    // Clip in world space, where depth is linear along the segment.
    scene::Vec3 p = a, q = b;
    if (za < near) p = a + (b - a) * ((near - za) / (zb - za));
    if (zb < near) q = b + (a - b) * ((near - zb) / (za - zb));
    return ScreenSegment{projectPoint(cam, p), projectPoint(cam, q)};
}

std::array<float, 3> lightTint(const scene::Light& light) {
    const double m = std::max({light.color.r, light.color.g, light.color.b});
    if (!(m > 0.0)) return {1.0f, 1.0f, 1.0f};
    return {float(light.color.r / m), float(light.color.g / m), float(light.color.b / m)};
}

namespace {

// The layers of one shadowed light: debug.layers[first .. first + count).
struct LightLayers {
    int light = 0;
    int first = 0;
    int count = 0;
};
std::vector<LightLayers> shadowedLights(const RenderDebug& debug) {
    std::vector<LightLayers> out;
    for (std::size_t k = 0; k < debug.layers.size(); ++k) {
        if (out.empty() || out.back().light != debug.layers[k].light) out.push_back({debug.layers[k].light, int(k), 0});
        ++out.back().count;
    }
    return out;
}

// The layer lit.frag reads for light `ll` at p: a point light's cube face of p's major axis from
// the light (ties as cubeFace: x before y before z), a cascaded light's cascade, else its one map.
int layerAt(const LightLayers& ll, const scene::Light& light, const scene::Vec3& p, int cascade) {
    if (light.type == scene::LightType::Point && ll.count == kCubeFaces) {
        const scene::Vec3 d = p - light.position, a = glm::abs(d);
        const int k = a.x >= a.y && a.x >= a.z ? 0 : a.y >= a.z ? 1 : 2;
        return ll.first + 2 * k + (d[k] < 0.0 ? 1 : 0);
    }
    return ll.first + std::clamp(cascade, 0, ll.count - 1);
}

bool reaches(const scene::Light& light, const scene::Vec3& p) {
    if (light.type != scene::LightType::Spot) return true;
    constexpr double kPi = 3.14159265358979323846;
    // lit.frag: outside when dot(−l, axis) < cos(cone), l the unit vector toward the light.
    return glm::dot(glm::normalize(p - light.position), glm::normalize(light.direction)) >=
           std::cos(light.coneAngleDegrees * kPi / 180.0);
}

struct PixelCoverage {
    Coverage coverage = Coverage::Background;
    std::array<float, 3> tint{0.0f, 0.0f, 0.0f};  // the mean tint of the lights whose maps hold it
};

// lightMapCoverage() and the tint for every pixel.
std::vector<PixelCoverage> coverage(const scene::Frame& frame, const scene::Scene& scene, const RenderDebug& debug) {
    std::vector<PixelCoverage> out(frame.pixelCount());
    scene::Camera camera = scene.camera;
    camera.width = frame.width;
    camera.height = frame.height;
    const scene::CameraBasis cam = scene::cameraBasis(camera);
    const std::vector<LightLayers> lights = shadowedLights(debug);
    const std::vector<int> cascade = cascadeIndices(frame, debug);
    const bool hasNdotL = frame.ndotl.size() == frame.pixelCount();
    // A directional map holds only the receivers some caster can shade (light_frustum.h,
    // shadowableReceiverBoxes); lit.frag lights a point outside it, which no caster reaches. The
    // boxes are padded by kCoverageBoxPad of the scene's size for the float depth p comes from.
    const double pad = kCoverageBoxPad * scene.bounds().diagonal();
    std::vector<std::vector<scene::Bounds>> shadowable(lights.size());
    for (std::size_t k = 0; k < lights.size(); ++k) {
        const scene::Light& light = scene.lights[std::size_t(lights[k].light)];
        if (light.type != scene::LightType::Directional) continue;
        for (scene::Bounds b : shadowableReceiverBoxes(scene, light.direction))
            if (!b.empty()) shadowable[k].push_back({b.min - scene::Vec3(pad), b.max + scene::Vec3(pad)});
    }
    auto canBeShaded = [&](std::size_t k, const scene::Vec3& p) {
        if (scene.lights[std::size_t(lights[k].light)].type != scene::LightType::Directional) return true;
        for (const scene::Bounds& b : shadowable[k])
            if (glm::all(glm::greaterThanEqual(p, b.min)) && glm::all(glm::lessThanEqual(p, b.max))) return true;
        return false;
    };
    for (int y = 0; y < frame.height; ++y)
        for (int x = 0; x < frame.width; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(frame.width) + std::size_t(x);
            PixelCoverage& c = out[i];
            if (!(frame.objectId[i] > 0.0f)) continue;
            c.coverage = Coverage::Outside;
            const bool facing = !hasNdotL || frame.ndotl[i] > 0.0f;
            const scene::Vec3 p = cam.position + double(frame.depth[i]) * scene::pixelDirection(cam, x, y);
            int inside = 0;
            bool uncovered = false;
            for (std::size_t li = 0; li < lights.size(); ++li) {
                const LightLayers& ll = lights[li];
                const scene::Light& light = scene.lights[std::size_t(ll.light)];
                const int layer = layerAt(ll, light, p, cascade[i]);
                if (!insideLightMap(debug.layers[std::size_t(layer)].frustum, p)) {
                    uncovered = uncovered || (facing && reaches(light, p) && canBeShaded(li, p));
                    continue;
                }
                const bool cascaded = light.type == scene::LightType::Directional && ll.count > 1;
                const std::array<float, 3> t = cascaded ? cascadeTint(layer - ll.first) : lightTint(light);
                for (int k = 0; k < 3; ++k) c.tint[std::size_t(k)] += t[std::size_t(k)];
                ++inside;
            }
            if (uncovered)
                c.coverage = Coverage::Uncovered;
            else if (inside > 0) {
                c.coverage = Coverage::Covered;
                for (float& t : c.tint) t /= float(inside);
            }
        }
    return out;
}

std::array<float, 3> pixel(const DisplayImage& img, int x, int y) {
    const std::size_t o = 3 * (std::size_t(y) * std::size_t(img.width) + std::size_t(x));
    return {img.rgb[o], img.rgb[o + 1], img.rgb[o + 2]};
}

// What the outline is drawn over: the frame's view depth per pixel (0 on the background).
struct DepthBuffer {
    const scene::Frame& frame;
    // Whether a line point at view depth z over pixel (x, y) is hidden by the visible surface.
    bool hides(int x, int y, double z) const {
        const std::size_t i = std::size_t(y) * std::size_t(frame.width) + std::size_t(x);
        return frame.objectId[i] > 0.0f && z > double(frame.depth[i]) * (1.0 + kFrustumEdgeDepthTolerance);
    }
};

// How drawSegment() draws: the samples in front of the visible surface or those behind it, and
// the dark halo around the line (one pixel each side, drawn for all edges before any line, so
// that a line stays visible on a surface of its own colour) or the line itself.
struct Stroke {
    bool hidden = false;
    bool halo = false;
};

// One stroke of the projected segment: in front of the surface solid, behind it dashed (3 px on,
// 3 off) and mixed half way into what is under it.
void drawSegment(DisplayImage& img, const DepthBuffer& depth, const ScreenSegment& s, const std::array<float, 3>& color,
                 int width, Stroke stroke) {
    // Liang–Barsky against the image rectangle, in the screen parameter t (0 at a, 1 at b).
    const double dx = s.b.x - s.a.x, dy = s.b.y - s.a.y;
    double t0 = 0.0, t1 = 1.0;
    const double p[4] = {-dx, dx, -dy, dy};
    const double q[4] = {s.a.x + 1.0, img.width + 1.0 - s.a.x, s.a.y + 1.0, img.height + 1.0 - s.a.y};
    for (int k = 0; k < 4; ++k) {
        if (p[k] == 0.0) {
            if (q[k] < 0.0) return;
            continue;
        }
        const double r = q[k] / p[k];
        if (p[k] < 0.0)
            t0 = std::max(t0, r);
        else
            t1 = std::min(t1, r);
    }
    if (!(t0 <= t1)) return;
    const double length = std::hypot(dx, dy) * (t1 - t0);
    const int steps = int(std::ceil(2.0 * length)) + 1;  // half-pixel steps: no gaps
    const bool steep = std::abs(dy) > std::abs(dx);
    const int from = stroke.halo ? -1 : 0, to = stroke.halo ? width : width - 1;
    for (int k = 0; k <= steps; ++k) {
        const double t = t0 + (t1 - t0) * double(k) / steps;
        const int x = int(std::floor(s.a.x + t * dx)), y = int(std::floor(s.a.y + t * dy));
        // Depth is not linear in screen space; its reciprocal is.
        const double z = 1.0 / ((1.0 - t) / s.a.z + t / s.b.z);
        if (stroke.hidden && (int(length * double(k) / steps) / 3) % 2) continue;
        for (int w = from; w <= to; ++w) {
            const int px = x + (steep ? w : 0), py = y + (steep ? 0 : w);
            if (px < 0 || py < 0 || px >= img.width || py >= img.height) continue;
            if (depth.hides(px, py, z) != stroke.hidden) continue;
            const std::array<float, 3> c = stroke.halo     ? std::array<float, 3>{0.0f, 0.0f, 0.0f}
                                           : stroke.hidden ? mix(pixel(img, px, py), color, 0.5)
                                                           : color;
            // A hidden line's halo only darkens, so the dashes stay faint.
            fill(img, px, py, 1, 1, stroke.halo && stroke.hidden ? mix(pixel(img, px, py), c, 0.5) : c);
        }
    }
}

// A ring (radius r) and a cross through it at a positional light, solid or faint as its center.
void drawMarker(DisplayImage& img, const DepthBuffer& depth, const scene::CameraBasis& cam, double near,
                const scene::Vec3& position, const std::array<float, 3>& color, int width) {
    const double z = glm::dot(position - cam.position, cam.forward);
    if (!(z >= near)) return;
    const ScreenPoint c = projectPoint(cam, position);
    const int cx = int(std::floor(c.x)), cy = int(std::floor(c.y));
    const bool onImage = cx >= 0 && cy >= 0 && cx < img.width && cy < img.height;
    const bool hidden = onImage && depth.hides(cx, cy, z);
    const int r = std::max(4, img.height / 60);
    for (int dy = -r - 1; dy <= r + 1; ++dy)
        for (int dx = -r - 1; dx <= r + 1; ++dx) {
            const int x = cx + dx, y = cy + dy;
            if (x < 0 || y < 0 || x >= img.width || y >= img.height) continue;
            const double dist = std::hypot(double(dx), double(dy));
            const bool ring = std::abs(dist - r) < 0.5 * width + 0.25;
            const bool cross = (std::abs(dx) < width || std::abs(dy) < width) && dist <= r;
            if (ring || cross) fill(img, x, y, 1, 1, hidden ? mix(pixel(img, x, y), color, 0.5) : color);
        }
}

// A swatch (`stripes`: the Uncovered mark) and a label, one legend row at (x0, y0).
void legendRow(DisplayImage& img, int x0, int y0, int scale, const std::array<float, 3>& color, bool stripes,
               const std::string& label) {
    const int side = 7 * scale;
    fill(img, x0, y0, side, side, {0.0f, 0.0f, 0.0f});
    for (int y = 0; y < side - 2 * scale; ++y)
        for (int x = 0; x < side - 2 * scale; ++x)
            if (!stripes || ((x + y) / kLeakStripeWidth) % 2 == 0)
                fill(img, x0 + scale + x, y0 + scale + y, 1, 1, color);
    drawLabel(img, x0 + side, y0, label, scale);
}

}  // namespace

std::vector<Coverage> lightMapCoverage(const scene::Frame& frame, const scene::Scene& scene, const RenderDebug& debug) {
    std::vector<Coverage> out;
    out.reserve(frame.pixelCount());
    for (const PixelCoverage& c : coverage(frame, scene, debug)) out.push_back(c.coverage);
    return out;
}

int frustumLineWidth(int imageHeight) { return imageHeight < 360 ? 1 : 2; }

DisplayImage lightFrustumView(const scene::Frame& frame, const scene::Scene& scene, const RenderDebug& debug) {
    DisplayImage img{frame.width, frame.height, std::vector<float>(frame.pixelCount() * 3)};
    const std::vector<PixelCoverage> cover = coverage(frame, scene, debug);
    for (int y = 0; y < frame.height; ++y)
        for (int x = 0; x < frame.width; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(frame.width) + std::size_t(x);
            const float* b = &frame.beauty[3 * i];
            std::array<float, 3> c;
            for (int k = 0; k < 3; ++k)
                c[std::size_t(k)] = kFrustumViewDim * scene::linearToSrgb(std::clamp(b[k], 0.0f, 1.0f));
            if (cover[i].coverage == Coverage::Covered) {
                const float shade = kCoveredShade[0] + kCoveredShade[1] * luminance(b);
                for (int k = 0; k < 3; ++k) c[std::size_t(k)] = cover[i].tint[std::size_t(k)] * shade;
            } else if (cover[i].coverage == Coverage::Uncovered && ((x + y) / kLeakStripeWidth) % 2 == 0) {
                c = kLeakColor;
            }
            fill(img, x, y, 1, 1, c);
        }

    scene::Camera camera = scene.camera;
    camera.width = frame.width;
    camera.height = frame.height;
    const scene::CameraBasis cam = scene::cameraBasis(camera);
    const DepthBuffer depth{frame};
    const int width = frustumLineWidth(frame.height);
    const int scale = std::max(1, frame.height / 240);
    // Every map's edges, stroke by stroke: hidden parts first, so that a solid edge crossing a
    // dashed one stays solid; halos before lines.
    for (const Stroke stroke : {Stroke{true, true}, Stroke{true, false}, Stroke{false, true}, Stroke{false, false}})
        for (const LightLayers& ll : shadowedLights(debug)) {
            const scene::Light& light = scene.lights[std::size_t(ll.light)];
            if (light.type == scene::LightType::Point) continue;
            const bool cascaded = light.type == scene::LightType::Directional && ll.count > 1;
            for (int k = 0; k < ll.count; ++k) {
                const std::array<float, 3> color = cascaded ? cascadeTint(k) : lightTint(light);
                const std::array<scene::Vec3, 8> corners =
                    frustumCorners(debug.layers[std::size_t(ll.first + k)].frustum);
                for (const auto& e : kFrustumEdges)
                    if (const auto s = projectSegment(cam, scene.camera.near, corners[std::size_t(e[0])],
                                                      corners[std::size_t(e[1])]))
                        drawSegment(img, depth, *s, color, width, stroke);
            }
        }
    int legendY = 2;
    for (const LightLayers& ll : shadowedLights(debug)) {
        const scene::Light& light = scene.lights[std::size_t(ll.light)];
        const bool point = light.type == scene::LightType::Point;
        const bool cascaded = light.type == scene::LightType::Directional && ll.count > 1;
        std::string name = "L";  // (not "L" + to_string: GCC 12 warns falsely, -Wrestrict)
        name += std::to_string(ll.light);
        if (!point)
            for (int k = 0; k < ll.count; ++k) {
                const std::array<float, 3> color = cascaded ? cascadeTint(k) : lightTint(light);
                legendRow(img, 2, legendY, scale, color, false, cascaded ? name + " C" + std::to_string(k) : name);
                legendY += 8 * scale;
            }
        if (point || light.type == scene::LightType::Spot)
            drawMarker(img, depth, cam, scene.camera.near, light.position, lightTint(light), width);
        if (point) {
            legendRow(img, 2, legendY, scale, lightTint(light), false, name);
            legendY += 8 * scale;
        }
    }
    if (legendY > 2) legendRow(img, 2, legendY, scale, kLeakColor, true, "OUT");
    return img;
}

}  // namespace shadowlab::raster

// raster/debug_views.cpp: the shadow-map, cascade and texel-density views.
#include "raster/debug_views.h"

#include <algorithm>
#include <cmath>
#include <limits>

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
    {'-', {0, 0, 7, 0, 0}},
};

void fill(DisplayImage& img, int x0, int y0, int w, int h, const std::array<float, 3>& color) {
    for (int y = std::max(y0, 0); y < std::min(y0 + h, img.height); ++y)
        for (int x = std::max(x0, 0); x < std::min(x0 + w, img.width); ++x)
            for (int k = 0; k < 3; ++k) img.rgb[3 * (std::size_t(y) * std::size_t(img.width) + std::size_t(x)) + std::size_t(k)] = color[std::size_t(k)];
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
        if (std::size_t(l) < debug.layerLabels.size())
            drawLabel(img, x0 + 2, y0 + 2, debug.layerLabels[std::size_t(l)], std::max(1, tile / 128));
    }
    return img;
}

std::vector<int> cascadeIndices(const scene::Frame& frame, const RenderDebug& debug) {
    std::vector<int> out(frame.pixelCount(), -1);
    const std::size_t count = debug.cascadeSplits.empty() ? 1 : debug.cascadeSplits.size() - 1;
    for (std::size_t i = 0; i < out.size(); ++i) {
        if (!(frame.objectId[i] > 0.0f)) continue;
        int c = 0;
        for (std::size_t k = 0; k + 1 < count; ++k)
            if (frame.depth[i] > float(debug.cascadeSplits[k + 1])) c = int(k) + 1;
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
            for (int k = 0; k < 3; ++k) img.rgb[3 * i + std::size_t(k)] = scene::linearToSrgb(std::clamp(b[k], 0.0f, 1.0f));
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
    if (debug.frusta.empty() || debug.layerLight.empty()) return out;
    scene::Camera camera = scene.camera;
    camera.width = frame.width;
    camera.height = frame.height;
    const scene::CameraBasis cam = scene::cameraBasis(camera);
    const int light = debug.layerLight[0];
    const scene::Light& l = scene.lights[std::size_t(light)];
    const std::vector<int> cascade = cascadeIndices(frame, debug);
    const bool cascaded = l.type == scene::LightType::Directional && !debug.cascadeTexels.empty();
    for (int y = 0; y < frame.height; ++y)
        for (int x = 0; x < frame.width; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(frame.width) + std::size_t(x);
            if (!(frame.objectId[i] > 0.0f)) continue;
            const double z = frame.depth[i];
            const scene::Vec3 p = cam.position + z * scene::pixelDirection(cam, x, y);
            double texel = 0.0;
            if (l.type == scene::LightType::Directional) {
                texel = cascaded ? debug.cascadeTexels[std::size_t(std::max(cascade[i], 0))]
                                 : debug.frusta[0].texelWorldSize();
            } else if (l.type == scene::LightType::Spot) {
                texel = debug.frusta[0].texelWorldSize() * glm::dot(p - l.position, debug.frusta[0].direction);
            } else {
                const scene::Vec3 d = glm::abs(p - l.position);
                texel = debug.frusta[0].texelWorldSize() * std::max(d.x, std::max(d.y, d.z));
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

}  // namespace shadowlab::raster

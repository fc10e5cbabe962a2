// raster/light_frustum.cpp: orthographic and perspective light frusta.
#include "raster/light_frustum.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <optional>
#include <span>
#include <variant>
#include <vector>

#include "raster/cascades.h"
#include "raster/tolerances.h"
#include "scene/camera.h"

namespace shadowlab::raster {

using scene::Vec3;

namespace {

constexpr double kPi = 3.14159265358979323846;

// A bounding-box tree over boxes, for the overlap queries of shadowableReceiverBoxes: a scene
// may hold up to a million objects, and testing every receiver against every caster is n².
class BoxTree {
public:
    explicit BoxTree(std::span<const scene::Bounds> boxes) : boxes_(boxes) {
        for (std::uint32_t i = 0; i < boxes.size(); ++i)
            if (!boxes[i].empty()) order_.push_back(i);
        if (order_.empty()) return;
        nodes_.resize(1);
        build(0, 0, std::uint32_t(order_.size()));
    }

    // Calls visit(j) for each box j overlapping `query` (touching counts) until visit returns false.
    template <class Visit>
    void overlapping(const scene::Bounds& query, Visit&& visit) const {
        if (nodes_.empty()) return;
        std::uint32_t stack[64];
        int top = 0;
        stack[top++] = 0;
        while (top > 0) {
            const Node& node = nodes_[stack[--top]];
            if (!overlaps(node.box, query)) continue;
            if (node.count > 0) {
                for (std::uint32_t k = node.first; k < node.first + node.count; ++k)
                    if (overlaps(boxes_[order_[k]], query) && !visit(order_[k])) return;
            } else {
                stack[top++] = node.first;
                stack[top++] = node.first + 1;
            }
        }
    }

private:
    struct Node {
        scene::Bounds box;
        std::uint32_t first = 0;  // a leaf's first entry in order_, else its left child (right follows)
        std::uint32_t count = 0;  // entries of a leaf; 0 for an inner node
    };
    static constexpr std::uint32_t kLeafSize = 4;

    static bool overlaps(const scene::Bounds& a, const scene::Bounds& b) {
        return glm::all(glm::lessThanEqual(a.min, b.max)) && glm::all(glm::lessThanEqual(b.min, a.max));
    }

    // Fills node `at` with order_[begin, end): a median split on the centres' widest axis, so the
    // depth stays below log2(n) + 1, far under the query's stack. Children sit side by side.
    void build(std::uint32_t at, std::uint32_t begin, std::uint32_t end) {
        scene::Bounds box, centres;
        for (std::uint32_t k = begin; k < end; ++k) {
            box.extend(boxes_[order_[k]]);
            centres.extend(boxes_[order_[k]].center());
        }
        nodes_[at].box = box;
        if (end - begin <= kLeafSize) {
            nodes_[at].first = begin;
            nodes_[at].count = end - begin;
            return;
        }
        const Vec3 e = centres.extent();
        const int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
        const std::uint32_t mid = begin + (end - begin) / 2;
        std::nth_element(
            order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
            [&](std::uint32_t l, std::uint32_t r) { return boxes_[l].center()[axis] < boxes_[r].center()[axis]; });
        const std::uint32_t left = std::uint32_t(nodes_.size());
        nodes_.resize(nodes_.size() + 2);
        nodes_[at].first = left;
        build(left, begin, mid);
        build(left + 1, mid, end);
    }

    std::span<const scene::Bounds> boxes_;
    std::vector<std::uint32_t> order_;
    std::vector<Node> nodes_;
};

}  // namespace

void setBasis(LightFrustum& f, const Vec3& direction) {
    f.direction = glm::normalize(direction);
    // Any axis not parallel to the light makes a basis; world Y unless the light is vertical.
    const Vec3 ref = std::abs(f.direction.y) < 0.99 ? Vec3(0, 1, 0) : Vec3(1, 0, 0);
    f.right = glm::normalize(glm::cross(f.direction, ref));
    f.up = glm::cross(f.right, f.direction);
}

namespace {

std::array<Vec3, 8> corners(const scene::Bounds& b) {
    std::array<Vec3, 8> c;
    for (int k = 0; k < 8; ++k)
        c[k] = Vec3((k & 1) ? b.max.x : b.min.x, (k & 2) ? b.max.y : b.min.y, (k & 4) ? b.max.z : b.min.z);
    return c;
}

// Both a box's and the receivers' extent in f's map and their depth along its axis. Orthographic:
// u, v are world offsets across the light from f.center; perspective: tangents x/d, y/d of the
// direction from f.position.
struct MapExtent {
    double minU = INFINITY, maxU = -INFINITY, minV = INFINITY, maxV = -INFINITY;
    double minDepth = INFINITY, maxDepth = -INFINITY;
    bool empty() const { return !(minU <= maxU && minV <= maxV); }
};

MapExtent orthographicExtent(std::span<const Vec3> points, const LightFrustum& f) {
    MapExtent e;
    for (const Vec3& c : points) {
        const Vec3 d = c - f.center;
        e.minU = std::min(e.minU, glm::dot(d, f.right));
        e.maxU = std::max(e.maxU, glm::dot(d, f.right));
        e.minV = std::min(e.minV, glm::dot(d, f.up));
        e.maxV = std::max(e.maxV, glm::dot(d, f.up));
        e.minDepth = std::min(e.minDepth, glm::dot(d, f.direction));
        e.maxDepth = std::max(e.maxDepth, glm::dot(d, f.direction));
    }
    return e;
}

struct Plane {
    Vec3 n;    // inward normal
    double d;  // inside: dot(n, p) + d >= 0
};

// Sutherland–Hodgman: the part of convex polygon `poly` on the inner side of `plane`.
std::vector<Vec3> clipPolygon(const std::vector<Vec3>& poly, const Plane& plane) {
    std::vector<Vec3> out;
    for (std::size_t i = 0; i < poly.size(); ++i) {
        const Vec3& a = poly[i];
        const Vec3& b = poly[(i + 1) % poly.size()];
        const double da = glm::dot(plane.n, a) + plane.d, db = glm::dot(plane.n, b) + plane.d;
        if (da >= 0) out.push_back(a);
        if ((da >= 0) != (db >= 0)) out.push_back(a + (b - a) * (da / (da - db)));
    }
    return out;
}

// The vertices of box ∩ {the inner side of every plane} that lie on the box's faces: each face
// clipped in turn. (The planes' own vertices inside the box, if any, are the caller's.)
std::vector<Vec3> clipBoxFaces(const scene::Bounds& box, const Plane* planes, std::size_t count) {
    const std::array<Vec3, 8> c = corners(box);
    // Faces as corner indices (bit 0: x, bit 1: y, bit 2: z), each in order around the face.
    const int faces[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};
    std::vector<Vec3> out;
    for (const auto& face : faces) {
        std::vector<Vec3> poly{c[face[0]], c[face[1]], c[face[2]], c[face[3]]};
        for (std::size_t k = 0; k < count && !poly.empty(); ++k) poly = clipPolygon(poly, planes[k]);
        out.insert(out.end(), poly.begin(), poly.end());
    }
    return out;
}

// The vertices of box ∩ camera frustum (between view depths nearD and farD); none when disjoint.
std::vector<Vec3> clipBoxToFrustum(const scene::Bounds& box, const scene::CameraBasis& cam, double nearD, double farD) {
    const Vec3 e = cam.position;
    const double tx = cam.tanHalfFovY * cam.aspect, ty = cam.tanHalfFovY;
    const Plane planes[] = {
        {cam.forward, -glm::dot(cam.forward, e) - nearD},
        {-cam.forward, glm::dot(cam.forward, e) + farD},
        {tx * cam.forward - cam.right, -glm::dot(tx * cam.forward - cam.right, e)},
        {tx * cam.forward + cam.right, -glm::dot(tx * cam.forward + cam.right, e)},
        {ty * cam.forward - cam.up, -glm::dot(ty * cam.forward - cam.up, e)},
        {ty * cam.forward + cam.up, -glm::dot(ty * cam.forward + cam.up, e)},
    };
    std::vector<Vec3> out = clipBoxFaces(box, planes, std::size(planes));
    // The frustum's own corners inside the box are vertices too (a camera inside the box).
    for (const double z : {nearD, farD})
        for (const double sx : {-1.0, 1.0})
            for (const double sy : {-1.0, 1.0}) {
                const Vec3 p = e + z * (cam.forward + sx * tx * cam.right + sy * ty * cam.up);
                if (glm::all(glm::greaterThanEqual(p, box.min)) && glm::all(glm::lessThanEqual(p, box.max)))
                    out.push_back(p);
            }
    return out;
}

}  // namespace

double LightFrustum::texelWorldSize() const {
    return perspective ? 2.0 * tanHalfFov / mapSize : 2.0 * halfWidth / mapSize;
}

LightFrustum fitDirectionalLight(const scene::Bounds& bounds, const Vec3& direction, int mapSize) {
    LightFrustum f;
    f.center = bounds.empty() ? Vec3(0.0) : bounds.center();
    const double radius = bounds.empty() ? 0.0 : 0.5 * bounds.diagonal();
    // A point-like scene still needs a non-zero depth range; scale the floor with the position
    // so it stays representable.
    const double floor = 1e-6 * std::max(1.0, bounds.empty() ? 0.0 : bounds.maxAbsCoordinate());
    f.halfWidth = std::max(radius, floor) * kLightFrustumMargin;
    f.nearDepth = -f.halfWidth;
    f.farDepth = f.halfWidth;
    setBasis(f, direction);
    f.mapSize = std::max(mapSize, 1);
    return f;
}

std::vector<Vec3> visibleReceiverPoints(const scene::Scene& scene) {
    return visibleReceiverPoints(scene, scene.bounds());
}

std::vector<Vec3> visibleReceiverPoints(const scene::Scene& scene, const scene::Bounds& sceneBounds) {
    if (sceneBounds.empty()) return {};
    // Receivers: the scene box clipped to the camera frustum (far plane pulled in to the
    // scene's farthest corner). Each face of the box is clipped against the frustum's six
    // planes; the clipped polygons' vertices are the vertices of box ∩ frustum.
    const scene::CameraBasis cam = scene::cameraBasis(scene.camera);
    double farthest = 0.0;
    for (const Vec3& c : corners(sceneBounds)) farthest = std::max(farthest, glm::dot(c - cam.position, cam.forward));
    const double nearD = scene.camera.near, farD = std::min(scene.camera.far, farthest);
    if (!(farD > nearD)) return {};  // the scene is behind the camera
    return clipBoxToFrustum(sceneBounds, cam, nearD, farD);
}

std::vector<Vec3> visibleReceiverPointsInSlice(const scene::Scene& scene, double minDepth, double maxDepth) {
    const scene::Bounds sceneBounds = scene.bounds();
    if (sceneBounds.empty()) return {};
    const scene::CameraBasis cam = scene::cameraBasis(scene.camera);
    double farthest = 0.0;
    for (const Vec3& c : corners(sceneBounds)) farthest = std::max(farthest, glm::dot(c - cam.position, cam.forward));
    const double nearD = std::max(scene.camera.near, minDepth);
    const double farD = std::min({scene.camera.far, farthest, maxDepth});
    if (!(farD > nearD)) return {};
    return clipBoxToFrustum(sceneBounds, cam, nearD, farD);
}

bool shadesItself(const scene::Object& object) {
    const scene::Mesh* mesh = std::get_if<scene::Mesh>(&object.shape);
    if (!mesh) return false;  // convex: see the header
    // The placed vertices, and the normal of the largest placed triangle as the candidate plane's.
    std::vector<Vec3> points;
    Vec3 normal(0.0), origin(0.0);
    double largest = 0.0;
    for (const scene::MeshInstance& inst : mesh->instances) {
        const scene::TriangleMesh& g = *inst.geometry;
        const std::size_t base = points.size();
        for (const Vec3& p : g.positions) points.push_back(scene::transformPoint(inst.transform, p));
        for (std::size_t t = 0; t + 2 < g.indices.size(); t += 3) {
            const Vec3 a = points[base + g.indices[t]], b = points[base + g.indices[t + 1]],
                       c = points[base + g.indices[t + 2]];
            const Vec3 n = glm::cross(b - a, c - a);
            if (glm::length(n) > largest) largest = glm::length(n), normal = n, origin = a;
        }
    }
    if (!(largest > 0.0)) return false;  // no area: nothing to shade
    normal /= largest;
    scene::Bounds b;
    for (const Vec3& p : points) b.extend(p);
    const double tolerance = kPlanarMeshTolerance * b.diagonal();
    for (const Vec3& p : points)
        if (std::abs(glm::dot(p - origin, normal)) > tolerance) return true;
    return false;  // planar: a plane cannot shade itself
}

std::vector<scene::Bounds> shadowableReceiverBoxes(const scene::Scene& scene, const Vec3& direction) {
    const scene::Bounds sceneBounds = scene.bounds();
    const std::size_t n = scene.objects.size();
    std::vector<scene::Bounds> boxes(n);
    if (sceneBounds.empty()) return boxes;
    const Vec3 d = glm::normalize(direction);
    const double pad = kShadowSweepPad * std::max(sceneBounds.diagonal(), sceneBounds.maxAbsCoordinate());
    std::vector<scene::Bounds> bounds(n), swept(n);
    for (std::size_t j = 0; j < n; ++j) {
        const scene::Bounds b = scene::boundsOf(scene.objects[j].shape);
        bounds[j] = b;
        if (b.empty()) continue;
        // The time at which the box has crossed the scene's far face on some axis: past it, the
        // swept box lies wholly outside the scene, where nothing is to shade.
        double t = INFINITY;
        for (int k = 0; k < 3; ++k) {
            if (d[k] > 0.0) t = std::min(t, (sceneBounds.max[k] - b.min[k]) / d[k]);
            if (d[k] < 0.0) t = std::min(t, (sceneBounds.min[k] - b.max[k]) / d[k]);
        }
        t = std::max(t, 0.0);
        scene::Bounds s = b;
        s.extend(scene::Bounds{b.min + t * d, b.max + t * d});
        s.min -= Vec3(pad);
        s.max += Vec3(pad);
        swept[j] = s;
    }
    const BoxTree tree(swept);
    for (std::size_t i = 0; i < n; ++i) {
        if (bounds[i].empty()) continue;
        tree.overlapping(bounds[i], [&](std::uint32_t j) {
            if (j == i && !shadesItself(scene.objects[i])) return true;
            boxes[i].extend(
                scene::Bounds{glm::max(bounds[i].min, swept[j].min), glm::min(bounds[i].max, swept[j].max)});
            // Once the whole object can be shaded, no other caster adds to its box.
            return !(boxes[i].min == bounds[i].min && boxes[i].max == bounds[i].max);
        });
    }
    return boxes;
}

std::vector<Vec3> visibleShadowableReceiverPoints(const scene::Scene& scene, const Vec3& direction) {
    std::vector<Vec3> points;
    for (const scene::Bounds& b : shadowableReceiverBoxes(scene, direction)) {
        if (b.empty()) continue;
        const std::vector<Vec3> v = visibleReceiverPoints(scene, b);
        points.insert(points.end(), v.begin(), v.end());
    }
    return points;
}

double nearestCasterDepth(const scene::Scene& scene, const LightFrustum& f, double minU, double maxU, double minV,
                          double maxV) {
    double minDepth = INFINITY;
    for (const scene::Object& object : scene.objects) {
        const scene::Bounds b = scene::boundsOf(object.shape);
        if (b.empty()) continue;
        const MapExtent o = orthographicExtent(corners(b), f);
        if (o.maxU < minU || o.minU > maxU || o.maxV < minV || o.minV > maxV) continue;
        minDepth = std::min(minDepth, o.minDepth);
    }
    return minDepth;
}

LightFrustum fitDirectionalLightToReceivers(const scene::Scene& scene, const Vec3& direction, int mapSize, bool snap,
                                            const std::vector<Vec3>* shadowable) {
    const scene::Bounds sceneBounds = scene.bounds();
    LightFrustum f = fitDirectionalLight(sceneBounds, direction, mapSize);
    if (sceneBounds.empty()) return f;
    std::vector<Vec3> receivers = shadowable ? *shadowable : visibleShadowableReceiverPoints(scene, direction);
    if (receivers.empty()) receivers = visibleReceiverPoints(scene);  // nothing visible can be shaded
    if (receivers.empty()) return f;                                  // the camera sees none of the scene

    // Receivers' extent across the light and their farthest depth along it.
    double minU = INFINITY, maxU = -INFINITY, minV = INFINITY, maxV = -INFINITY, maxDepth = -INFINITY;
    for (const Vec3& c : receivers) {
        const Vec3 d = c - f.center;
        minU = std::min(minU, glm::dot(d, f.right));
        maxU = std::max(maxU, glm::dot(d, f.right));
        minV = std::min(minV, glm::dot(d, f.up));
        maxV = std::max(maxV, glm::dot(d, f.up));
        maxDepth = std::max(maxDepth, glm::dot(d, f.direction));
    }
    // Casters: every object whose extent across the light overlaps the receivers'; the map
    // must reach back to the nearest of them.
    const double minDepth = nearestCasterDepth(scene, f, minU, maxU, minV, maxV);
    if (!(minDepth < maxDepth)) return f;

    // Square texels: the larger extent sets the half-width; the map is centered on the
    // receivers across the light. Same margin as the bounding-sphere fit.
    // Snapped so that the map does not swim as the camera moves (as each cascade's, fitCascade):
    // - the half-width is rounded up to 1/16 of its power of two, so a small move keeps the
    //   texel size; the center then moves by up to half a texel on each axis, so the window
    //   needed grows by that: h·(1 − 1/N) ≥ the receivers' half extent, h ≥ half·N/(N − 1);
    // - the center lies on the world-fixed texel grid (multiples of the texel along right and
    //   up from the world origin), so the map moves by whole texels only;
    // - near and far are rounded outward to 1/16 of the power of two of their range, from the
    //   bounding sphere's center (fixed for the scene), so stored depths keep their values.
    const double size = f.mapSize;
    double half = 0.5 * std::max(maxU - minU, maxV - minV) * kLightFrustumMargin * size / std::max(size - 1.0, 1.0);
    if (!(half > 0.0)) return f;
    const double quantum = std::exp2(std::floor(std::log2(half)) - 4.0);
    if (snap) half = std::ceil(half / quantum) * quantum;
    if (half >= f.halfWidth) return f;  // no gain over the bounding sphere
    const double pad = (kLightFrustumMargin - 1.0) * (maxDepth - minDepth);
    const Vec3 receiversCenter = f.center + 0.5 * (minU + maxU) * f.right + 0.5 * (minV + maxV) * f.up;
    f.halfWidth = half;
    if (!snap) {
        f.center = receiversCenter;
        f.nearDepth = minDepth - pad;
        f.farDepth = maxDepth + pad;
        return f;
    }
    const double texel = f.texelWorldSize();
    const double u = glm::dot(receiversCenter, f.right), v = glm::dot(receiversCenter, f.up);
    // From the grid indices alone (and the bounding sphere's depth, fixed for the scene): a map
    // whose indices did not change is the same to the last bit, not carrying the rounding of the
    // receivers' extent (docs/temporal.md tests this).
    f.center = (std::round(u / texel) * texel) * f.right + (std::round(v / texel) * texel) * f.up +
               glm::dot(f.center, f.direction) * f.direction;
    const double nearDepth = minDepth - pad, farDepth = maxDepth + pad;
    const double depthQuantum = std::exp2(std::floor(std::log2(farDepth - nearDepth)) - 4.0);
    f.nearDepth = std::floor(nearDepth / depthQuantum) * depthQuantum;
    f.farDepth = std::ceil(farDepth / depthQuantum) * depthQuantum;
    return f;
}

LightFrustum fitSpotLight(const scene::Bounds& bounds, const Vec3& position, const Vec3& direction, double coneDegrees,
                          int mapSize) {
    LightFrustum f;
    f.perspective = true;
    setBasis(f, direction);
    f.position = position;
    f.mapSize = std::max(mapSize, 1);
    const double half = std::min(coneDegrees * kSpotFovMargin, kMaxSpotHalfAngleDegrees) * kPi / 180.0;
    f.tanHalfFov = std::tan(half);
    const Vec3 c = bounds.empty() ? position + f.direction : bounds.center();
    const double radius = bounds.empty() ? 1.0 : 0.5 * bounds.diagonal() * kLightFrustumMargin;
    const double along = glm::dot(c - position, f.direction);
    f.far = std::max(along + radius, 1e-6);
    f.near = std::max(along - radius, f.far * kSpotMinNearOverFar);
    return f;
}

Vec3 cubeFaceDirection(int face) {
    Vec3 d(0.0);
    d[face / 2] = (face % 2) ? -1.0 : 1.0;
    return d;
}

double cubeFaceTanHalfFov(int mapSize) {
    // The face's 90° edge sits at tan = 1, i.e. (size/2)/t texels from the center; ask for
    // margin more texels: (size/2)(1 − 1/t) = margin  =>  t = size / (size − 2·margin).
    const double size = std::max(mapSize, 1);
    const double usable = size - 2.0 * kPointFaceMarginTexels;
    return usable <= 0.5 * size ? 2.0 : size / usable;
}

LightFrustum fitPointLightFace(const scene::Bounds& bounds, const Vec3& position, int face, int mapSize) {
    LightFrustum f;
    f.perspective = true;
    setBasis(f, cubeFaceDirection(face));
    f.position = position;
    f.mapSize = std::max(mapSize, 1);
    f.tanHalfFov = cubeFaceTanHalfFov(mapSize);
    const Vec3 c = bounds.empty() ? position : bounds.center();
    const double radius = bounds.empty() ? 1.0 : 0.5 * bounds.diagonal() * kLightFrustumMargin;
    // Any direction may hold geometry, so the range comes from the distance band of the bounding
    // sphere, not its extent along this face's axis: one near/far serves all six faces (unfitted;
    // fitPointLightFaceToReceivers gives each face its own). Near and far are planes across the axis: a point at distance r in a direction θ off
    // the axis has depth r·cos θ, as little as r/√(1 + 2t²) in the window's corners (tan θ = t√2),
    // so the near plane is the nearest distance scaled by that (the radial distance itself clipped
    // the corner of a box seen down its diagonal); a depth never exceeds the distance, so far is it.
    const double dist = glm::length(c - position);
    const double t = f.tanHalfFov;
    f.far = std::max(dist + radius, 1e-6);
    f.near = std::max((dist - radius) / std::sqrt(1.0 + 2.0 * t * t), f.far * kSpotMinNearOverFar);
    return f;
}

glm::dmat4 LightFrustum::toClip(const Vec3& origin) const {
    glm::dmat4 m(0.0);
    if (!perspective) {
        // x = (q − c')·right / h, y = (q − c')·up / h, z = ((q − c')·dir − nearDepth) / range,
        // with q = p − origin and c' = center − origin: the large parts cancel in double.
        const Vec3 c = center - origin;
        const double h = halfWidth, range = depthRange();
        for (int k = 0; k < 3; ++k) {
            m[k][0] = right[k] / h;
            m[k][1] = up[k] / h;
            m[k][2] = direction[k] / range;
        }
        m[3][0] = -glm::dot(c, right) / h;
        m[3][1] = -glm::dot(c, up) / h;
        m[3][2] = -(glm::dot(c, direction) + nearDepth) / range;
        m[3][3] = 1.0;
        return m;
    }
    // Perspective with d = (q − o')·dir: x = ((q − o')·right − windowU·d) / t, y likewise with up
    // and windowV (x/w = (u − windowU)/t: the window's center at 0, its edges at ±1), w = d,
    // z = A·(d − near), A = far/(far − near), so z/w = far/(far − near)·(1 − near/d).
    const Vec3 o = position - origin;
    const double a = far / (far - near);
    const Vec3 rightW = right - windowU * direction, upW = up - windowV * direction;
    for (int k = 0; k < 3; ++k) {
        m[k][0] = rightW[k] / tanHalfFov;
        m[k][1] = upW[k] / tanHalfFov;
        m[k][2] = a * direction[k];
        m[k][3] = direction[k];
    }
    m[3][0] = -glm::dot(o, rightW) / tanHalfFov;
    m[3][1] = -glm::dot(o, upW) / tanHalfFov;
    m[3][2] = -a * (glm::dot(o, direction) + near);
    m[3][3] = -glm::dot(o, direction);
    return m;
}

glm::dmat4 LightFrustum::toTexture(const Vec3& origin) const {
    // u = 0.5·x + 0.5·w, v = 0.5·y + 0.5·w (divided by w in the shader): Vulkan's viewport puts
    // clip y = −w on framebuffer row 0, which is texture row 0, so v needs no flip.
    // (x, y, z, w) -> (0.5x + 0.5w, 0.5y + 0.5w, z, w); column 3 multiplies w.
    glm::dmat4 b(0.0);
    b[0][0] = 0.5;
    b[1][1] = 0.5;
    b[2][2] = 1.0;
    b[3][0] = 0.5;
    b[3][1] = 0.5;
    b[3][3] = 1.0;
    return b * toClip(origin);
}

std::string LightFrustum::describe() const {
    char buf[400];
    if (perspective && windowU == 0.0 && windowV == 0.0)
        std::snprintf(
            buf, sizeof buf,
            "perspective position=(%.9g,%.9g,%.9g) direction=(%.9g,%.9g,%.9g) half_fov_deg=%.9g near=%.9g far=%.9g",
            position.x, position.y, position.z, direction.x, direction.y, direction.z,
            std::atan(tanHalfFov) * 180.0 / kPi, near, far);
    else if (perspective)  // an off-center window: its tangent ranges across the axis
        std::snprintf(buf, sizeof buf,
                      "perspective position=(%.9g,%.9g,%.9g) direction=(%.9g,%.9g,%.9g) half_fov_deg=%.9g "
                      "window_u=%.9g..%.9g window_v=%.9g..%.9g near=%.9g far=%.9g",
                      position.x, position.y, position.z, direction.x, direction.y, direction.z,
                      std::atan(tanHalfFov) * 180.0 / kPi, windowU - tanHalfFov, windowU + tanHalfFov,
                      windowV - tanHalfFov, windowV + tanHalfFov, near, far);
    else
        std::snprintf(
            buf, sizeof buf,
            "orthographic center=(%.9g,%.9g,%.9g) half_width=%.9g direction=(%.9g,%.9g,%.9g) depth=%.9g..%.9g",
            center.x, center.y, center.z, halfWidth, direction.x, direction.y, direction.z, nearDepth, farDepth);
    return buf;
}

double casterFeatureSize(const scene::Object& object) {
    struct Feature {
        double operator()(const scene::Sphere& s) const { return 2.0 * s.radius; }
        double operator()(const scene::Quad& q) const { return std::min(q.size.x, q.size.y); }
        double operator()(const scene::Box& b) const {
            const Vec3 e = b.max - b.min;
            return std::min({e.x, e.y, e.z});
        }
        double operator()(const scene::Mesh& m) const {
            // At most ~64k triangles are looked at (evenly strided): the median of a sample that
            // size is within a fraction of a percentile of the whole mesh's, and it stays cheap.
            std::size_t total = 0;
            for (const scene::MeshInstance& inst : m.instances) total += inst.geometry->triangleCount();
            const std::size_t stride = std::max<std::size_t>(1, total / 65536);
            std::vector<double> widths;
            std::size_t k = 0;
            for (const scene::MeshInstance& inst : m.instances) {
                const scene::TriangleMesh& g = *inst.geometry;
                for (std::size_t t = 0; t < g.triangleCount(); ++t, ++k) {
                    if (k % stride) continue;
                    const Vec3 a = scene::transformPoint(inst.transform, g.positions[g.indices[3 * t]]);
                    const Vec3 b = scene::transformPoint(inst.transform, g.positions[g.indices[3 * t + 1]]);
                    const Vec3 c = scene::transformPoint(inst.transform, g.positions[g.indices[3 * t + 2]]);
                    const double area2 = glm::length(glm::cross(b - a, c - a));
                    const double longest = std::max({glm::length(b - a), glm::length(c - b), glm::length(a - c)});
                    if (longest > 0.0) widths.push_back(area2 / longest);
                }
            }
            if (widths.empty()) return INFINITY;
            auto mid = widths.begin() + std::ptrdiff_t(widths.size() / 2);
            std::nth_element(widths.begin(), mid, widths.end());
            return *mid;
        }
    };
    return std::visit(Feature{}, object.shape);
}

ShadowMapSizeChoice chooseShadowMapSize(const scene::Scene& scene, const scene::RasterSettings& settings,
                                        const scene::RenderPlan* plan) {
    const int size = settings.shadowMapSize;
    // Only the lights that get a map ask for texels.
    auto mapped = [&](std::size_t i) {
        if (!plan) return true;
        for (const scene::LightPlan& lp : plan->lights)
            if (std::size_t(lp.light) == i) return lp.needsShadowTest;
        return false;
    };
    auto keep = [&](const std::string& why) {
        return ShadowMapSizeChoice{size, std::to_string(size) + " (" + why + ")"};
    };
    // A size set after resolveSettings() (a test, the sweep) is forced too.
    if (!settings.shadowMapSizeIsDefault || size != scene::kDefaultShadowMapSize)
        return keep("set by --shadow-map-size or the scene");
    bool directional = false;
    for (std::size_t i = 0; i < scene.lights.size(); ++i)
        directional = directional || (mapped(i) && scene.lights[i].type == scene::LightType::Directional);
    if (settings.cascades > 1 && directional) return keep("default: cascades size their texels per slice");
    // The visible receivers: each object's bounds clipped to the camera frustum (the scene's box
    // would reach up to the camera), a convex polytope each, between the near and far planes.
    const scene::CameraBasis cam = scene::cameraBasis(scene.camera);
    std::vector<std::vector<Vec3>> visible;
    for (const scene::Object& o : scene.objects) {
        std::vector<Vec3> v = visibleReceiverPoints(scene, scene::boundsOf(o.shape));
        if (!v.empty()) visible.push_back(std::move(v));
    }
    if (visible.empty()) return keep("default: the camera sees no receiver");
    // A pixel's world size on a receiver facing the camera at view depth zc (raster/debug_views.h
    // pixelWorldSize); tilted receivers have larger footprints, so this is the finest detail the
    // image can show.
    auto pixelAt = [&](double zc) { return 2.0 * cam.tanHalfFovY * zc / std::max(scene.camera.height, 1); };
    auto viewDepth = [&](const Vec3& p) {
        return std::max(glm::dot(p - cam.position, cam.forward), scene.camera.near);
    };
    // The largest distance(p) / view depth over the visible polytopes' vertices (and 0).
    auto maxOverViewDepth = [&](auto distance) {
        double ratio = 0.0;
        for (const std::vector<Vec3>& v : visible)
            for (const Vec3& p : v) ratio = std::max(ratio, distance(p) / viewDepth(p));
        return ratio;
    };
    // Each object's smallest feature as a caster, and the most texels any caster asks for.
    std::vector<double> features;
    for (const scene::Object& o : scene.objects) features.push_back(std::max(casterFeatureSize(o), 1e-300));
    double casterNeeded = 0.0;
    std::size_t casterObject = scene.objects.size();
    auto noteCaster = [&](std::size_t o, double texels) {
        if (texels > casterNeeded) casterNeeded = texels, casterObject = o;
    };
    double needed = 0.0;  // texels, rounded up to a power of two below
    double asked = 0.0;   // the same before a fitted spot's own size bounds it: what the cap cuts
    int neededSize = 0;   // a size some light needs as it is (fitted spot windows)
    std::string why;
    char buf[320];
    if (directional) {
        // The nearest view depth of any visible receiver, at a vertex (a linear function).
        double zMin = INFINITY;
        for (const std::vector<Vec3>& v : visible)
            for (const Vec3& p : v) zMin = std::min(zMin, viewDepth(p));
        const double pixel = pixelAt(zMin);
        // Each mapped directional light's map. A fitted map's snapped width shrinks (weakly) as N
        // grows (its N/(N − 1) factor, then rounding up), so its width at the smallest candidate
        // size bounds the width at the size chosen below.
        std::vector<LightFrustum> maps;
        for (std::size_t i = 0; i < scene.lights.size(); ++i) {
            const scene::Light& l = scene.lights[i];
            if (l.type != scene::LightType::Directional || !mapped(i)) continue;
            maps.push_back(settings.fitLightFrustum
                               ? fitDirectionalLightToReceivers(scene, l.direction, kMinAutoShadowMapSize)
                               : fitDirectionalLight(scene.bounds(), l.direction, size));
        }
        double widest = 0.0;
        for (const LightFrustum& f : maps) widest = std::max(widest, 2.0 * f.halfWidth);
        needed = widest / pixel;
        std::snprintf(buf, sizeof buf,
                      "map width %.4g / smallest pixel footprint %.4g at view depth %.4g = %.0f texels", widest, pixel,
                      zMin, needed);
        why = buf;
        // The casters' detail: k texels across the smallest feature of any object that can shade a
        // visible receiver, in the widest map.
        for (const LightFrustum& f : maps) {
            const std::vector<bool> casts = castsIntoView(scene, f, kCullMarginTexels);
            for (std::size_t o = 0; o < scene.objects.size(); ++o)
                if (casts[o]) noteCaster(o, kTexelsPerCasterFeature * 2.0 * f.halfWidth / features[o]);
        }
    }
    for (std::size_t i = 0; i < scene.lights.size(); ++i) {
        const scene::Light& l = scene.lights[i];
        if (l.type != scene::LightType::Spot || !mapped(i)) continue;
        // A texel at distance z along the axis is z·2t/N wide, a pixel at view depth zc is
        // pixelAt(zc): N ≥ 2t·z/pixelAt(zc) = 2t·(z/zc)/pixelAt(1). Both z and zc are affine in the
        // point, and zc > 0 on each visible polytope K, so r = z/zc is quasi-linear there: if
        // r(v) ≤ m at every vertex v, then z − m·zc ≤ 0 at the vertices, hence (affine) on all of
        // K, i.e. r ≤ m on K. Its maximum over K is at a vertex.
        const Vec3 axis = glm::normalize(l.direction);
        const double ratio = maxOverViewDepth([&](const Vec3& p) { return glm::dot(p - l.position, axis); });
        // A fitted window depends on N (margin in texels, snapped size): the smallest power of two
        // whose own window is fine enough. The cone's does not, and this is then the rounding below.
        int n = kMinAutoShadowMapSize;
        double spotNeeded = 0.0, window = 0.0;
        for (;; n *= 2) {
            window = 2.0 * spotLightFrustum(scene, settings, l, n).tanHalfFov;
            spotNeeded = window * ratio / pixelAt(1.0);
            if (spotNeeded <= n || n >= size) break;
        }
        std::snprintf(
            buf, sizeof buf,
            "%sspot %zu: 2·tan(half %s) %.4g x (distance / view depth) %.4g / pixel %.4g at view depth 1 = %.0f texels",
            why.empty() ? "" : "; ", i, settings.fitLightFrustum ? "window" : "fov", window, ratio, pixelAt(1.0),
            spotNeeded);
        why += buf;
        needed = std::max(needed, std::min(spotNeeded, double(n)));
        asked = std::max(asked, spotNeeded);
        neededSize = std::max(neededSize, n);
        // Casters: a texel at distance d is d·window/N, so N ≥ k·window·d/feature at the object's
        // farthest distance along the axis (its box's farthest corner, where its texels are widest).
        const LightFrustum f = spotLightFrustum(scene, settings, l, size);
        const std::vector<bool> casts = castsIntoView(scene, f, kCullMarginTexels);
        for (std::size_t o = 0; o < scene.objects.size(); ++o) {
            if (!casts[o]) continue;
            double far = 0.0;
            for (const Vec3& c : corners(scene::boundsOf(scene.objects[o].shape)))
                far = std::max(far, glm::dot(c - l.position, axis));
            noteCaster(o, kTexelsPerCasterFeature * window * std::max(far, f.near) / features[o]);
        }
    }
    for (std::size_t i = 0; i < scene.lights.size(); ++i) {
        const scene::Light& l = scene.lights[i];
        if (l.type != scene::LightType::Point || !mapped(i)) continue;
        // A receiver uses the face of its major axis, at axial distance ‖p − light‖∞, where a texel
        // is 2t/N = 2/(N − 2·margin) per unit (t = N/(N − 2·margin), cubeFaceTanHalfFov): N ≥
        // 2·max(‖p − light‖∞ / pixelAt(zc)) + 2·margin. ‖p − light‖∞ is convex and zc affine and
        // positive, so their ratio is quasi-convex: on each visible polytope, largest at a vertex.
        const double ratio = maxOverViewDepth([&](const Vec3& p) {
            const Vec3 d = glm::abs(p - l.position);
            return std::max({d.x, d.y, d.z});
        });
        const double pointNeeded = 2.0 * ratio / pixelAt(1.0) + 2.0 * kPointFaceMarginTexels;
        std::snprintf(buf, sizeof buf,
                      "%spoint %zu: 2 x (axial distance / view depth) %.4g / pixel %.4g at view depth 1 + 2 x %.0f "
                      "margin = %.0f texels",
                      why.empty() ? "" : "; ", i, ratio, pixelAt(1.0), kPointFaceMarginTexels, pointNeeded);
        why += buf;
        needed = std::max(needed, pointNeeded);
        // Casters: a face's texel is 2/(N − 24) per unit of axial distance, widest at the object's
        // farthest ‖corner − light‖∞ (a convex function on its box is largest at a corner).
        for (std::size_t o = 0; o < scene.objects.size(); ++o) {
            double far = 0.0;
            for (const Vec3& c : corners(scene::boundsOf(scene.objects[o].shape))) {
                const Vec3 d = glm::abs(c - l.position);
                far = std::max({far, d.x, d.y, d.z});
            }
            noteCaster(o, 2.0 * kTexelsPerCasterFeature * far / features[o] + 2.0 * kPointFaceMarginTexels);
        }
    }
    if (why.empty()) return keep("default: no light with a map");
    if (casterObject < scene.objects.size()) {
        std::snprintf(buf, sizeof buf, "; casters: %.0f texels across the smallest feature, %.4g of '%s' (%.0f texels)",
                      kTexelsPerCasterFeature, features[casterObject], scene.objects[casterObject].name.c_str(),
                      casterNeeded);
        why += buf;
        needed = std::max(needed, casterNeeded);
    }
    int chosen = std::max(kMinAutoShadowMapSize, neededSize);
    while (chosen < needed && chosen < size) chosen *= 2;
    chosen = std::min(chosen, size);
    asked = std::max(asked, needed);
    const bool capped = asked > size;
    return ShadowMapSizeChoice{chosen,
                               std::to_string(chosen) + " (" +
                                   (chosen < size ? "from receiver detail and caster features: " : "default: ") + why +
                                   (capped ? ", capped at the default" : ", rounded up to a power of two") + ")",
                               asked};
}

namespace {

// The receivers' extent in a perspective map: of their hull's part in front of the light (d > 0).
// The hull's vertices with d > 0 project to finite (u, v); the rest of that part lies near where
// an edge from such a vertex a to one behind, b, crosses the plane d = 0, at c. Along that edge
// u = x/d runs monotonically from u_a to +∞ when x_c > 0 (−∞ when x_c < 0; constant u_a when
// x_c = 0), and the hull's vertex pairs include all its edges (the other pairs cross inside the
// hull, which adds nothing false). Then clamped to the map's own window: a receiver outside it
// reads at most the border and the texels a filter reaches from there, which the margin covers.
MapExtent perspectiveReceiverExtent(const std::vector<Vec3>& receivers, const LightFrustum& f) {
    struct Local {
        double x, y, d;
    };
    std::vector<Local> front, behind;
    for (const Vec3& p : receivers) {
        const Vec3 r = p - f.position;
        const Local l{glm::dot(r, f.right), glm::dot(r, f.up), glm::dot(r, f.direction)};
        (l.d > 0.0 ? front : behind).push_back(l);
    }
    MapExtent e;
    for (const Local& a : front) {
        e.minU = std::min(e.minU, a.x / a.d);
        e.maxU = std::max(e.maxU, a.x / a.d);
        e.minV = std::min(e.minV, a.y / a.d);
        e.maxV = std::max(e.maxV, a.y / a.d);
        e.maxDepth = std::max(e.maxDepth, a.d);
    }
    for (const Local& a : front)
        for (const Local& b : behind) {
            const double s = a.d / (a.d - b.d);
            const double xc = a.x + s * (b.x - a.x), yc = a.y + s * (b.y - a.y);
            if (xc > 0.0) e.maxU = INFINITY;
            if (xc < 0.0) e.minU = -INFINITY;
            if (yc > 0.0) e.maxV = INFINITY;
            if (yc < 0.0) e.minV = -INFINITY;
        }
    const double t = f.tanHalfFov;
    e.minU = std::clamp(e.minU, f.windowU - t, f.windowU + t);
    e.maxU = std::clamp(e.maxU, f.windowU - t, f.windowU + t);
    e.minV = std::clamp(e.minV, f.windowV - t, f.windowV + t);
    e.maxV = std::clamp(e.maxV, f.windowV - t, f.windowV + t);
    return e;
}

}  // namespace

std::vector<bool> castsOnto(const scene::Scene& scene, const LightFrustum& f, const std::vector<Vec3>& receivers,
                            double reachTexels, double normalOffsetTexels) {
    std::vector<scene::Bounds> boxes;
    boxes.reserve(scene.objects.size());
    for (const scene::Object& o : scene.objects) boxes.push_back(scene::boundsOf(o.shape));
    return boxesCastOnto(boxes, f, receivers, reachTexels, normalOffsetTexels);
}

namespace {

// How far across f's map (in its u, v: world units, or tangents for a perspective map) a receiver's
// lookups reach from its own (u, v): the filter's reach and the normal offset. None where a
// perspective map's normal offset turns the lookup too far to bound.
std::optional<double> lookupReach(const LightFrustum& f, double reachTexels, double normalOffsetTexels) {
    // The normal offset moves an orthographic map's receiver by that many texels in any direction.
    if (!f.perspective) return (reachTexels + normalOffsetTexels) * f.texelWorldSize();
    // Perspective. The normal offset moves a receiver at distance d by k·d, k = offset · texel
    // angle: its direction turns by at most k·√(1 + u²)/(1 − k) in tangent units and its distance
    // grows by at most k·d. For k < 0.1 and |u| ≤ ~1.13·t (beyond, the offset point stays off the
    // map) that is under 2·k·√(1 + t²).
    const double texelAngle = f.texelWorldSize();  // 2·t/N: tangent units per texel
    const double k = normalOffsetTexels * texelAngle;
    if (!(k < 0.1)) return std::nullopt;
    // The widest tangent the map holds (an off-center fitted window reaches past its half-size).
    // The slope bias's first lifted texel (flat in reachTexels) is an offset along the normal too.
    const double t = std::max(std::abs(f.windowU), std::abs(f.windowV)) + f.tanHalfFov;
    const double offset = normalOffsetTexels + kCullLiftTexels;
    return (reachTexels - kCullLiftTexels + 2.0 * offset * std::sqrt(1.0 + t * t)) * texelAngle;
}

}  // namespace

std::optional<TexelRect> receiverTexels(const LightFrustum& f, const std::vector<Vec3>& receivers, double reachTexels,
                                        double normalOffsetTexels) {
    const std::optional<double> reach = lookupReach(f, reachTexels, normalOffsetTexels);
    if (receivers.empty() || !reach) return std::nullopt;
    const MapExtent r = f.perspective ? perspectiveReceiverExtent(receivers, f) : orthographicExtent(receivers, f);
    // A perspective map with no receiver in front of the light: none reads it.
    if (r.empty()) return f.perspective ? std::optional<TexelRect>(TexelRect{}) : std::nullopt;
    // Framebuffer texels of u: (x + 1) / 2 · N with x = u / halfWidth (orthographic, u from the
    // center) or (u − windowU) / tanHalfFov (perspective): the depth pass's viewport.
    const double n = double(std::max(f.mapSize, 1));
    const double scale = f.perspective ? f.tanHalfFov : f.halfWidth;
    const double du = f.perspective ? f.windowU : 0.0, dv = f.perspective ? f.windowV : 0.0;
    auto texel = [&](double u, double offset) { return ((u - offset) / scale + 1.0) * 0.5 * n; };
    // A lookup at texel coordinate x reads the texels whose centers lie within the reach of it.
    auto lo = [&](double u, double offset) {
        return std::uint32_t(std::clamp(std::floor(texel(u - *reach, offset)), 0.0, n));
    };
    auto hi = [&](double u, double offset) {
        return std::uint32_t(std::clamp(std::floor(texel(u + *reach, offset)) + 1.0, 0.0, n));
    };
    return TexelRect{lo(r.minU, du), lo(r.minV, dv), hi(r.maxU, du), hi(r.maxV, dv)};
}

std::vector<bool> boxesCastOnto(std::span<const scene::Bounds> boxes, const LightFrustum& f,
                                const std::vector<Vec3>& receivers, double reachTexels, double normalOffsetTexels) {
    std::vector<bool> casts(boxes.size(), true);
    if (receivers.empty()) return casts;
    const std::optional<double> reach = lookupReach(f, reachTexels, normalOffsetTexels);
    if (!reach) return casts;
    const double margin = *reach;
    if (!f.perspective) {
        const MapExtent r = orthographicExtent(receivers, f);
        for (std::size_t i = 0; i < boxes.size(); ++i) {
            const scene::Bounds& b = boxes[i];
            if (b.empty()) continue;
            const MapExtent o = orthographicExtent(corners(b), f);
            casts[i] = o.maxU >= r.minU - margin && o.minU <= r.maxU + margin && o.maxV >= r.minV - margin &&
                       o.minV <= r.maxV + margin && o.minDepth <= r.maxDepth + margin;
        }
        return casts;
    }
    // Perspective (lookupReach has the normal offset's bound).
    const MapExtent r = perspectiveReceiverExtent(receivers, f);
    if (r.empty()) return std::vector<bool>(boxes.size(), false);  // no receiver in front: none reads it
    const double farthest = r.maxDepth * (1.0 + margin);
    for (std::size_t i = 0; i < boxes.size(); ++i) {
        const scene::Bounds& b = boxes[i];
        if (b.empty()) continue;
        MapExtent o;
        int behind = 0;
        for (const Vec3& c : corners(b)) {
            const Vec3 q = c - f.position;
            const double d = glm::dot(q, f.direction);
            if (!(d > 0.0)) {
                ++behind;
                continue;
            }
            const double u = glm::dot(q, f.right) / d, v = glm::dot(q, f.up) / d;
            o.minU = std::min(o.minU, u);
            o.maxU = std::max(o.maxU, u);
            o.minV = std::min(o.minV, v);
            o.maxV = std::max(o.maxV, v);
            o.minDepth = std::min(o.minDepth, d);
        }
        if (behind == 8) {
            casts[i] = false;  // wholly behind the light: clipped from this map
        } else if (behind > 0) {
            casts[i] = true;  // across the light's plane (or around the light): its projection is unbounded
        } else {
            // All corners in front: the box projects into the rectangle of its corners' projections.
            casts[i] = o.maxU >= r.minU - margin && o.minU <= r.maxU + margin && o.maxV >= r.minV - margin &&
                       o.minV <= r.maxV + margin && o.minDepth <= farthest;
        }
    }
    return casts;
}

std::vector<bool> castsIntoView(const scene::Scene& scene, const LightFrustum& f, double reachTexels,
                                double normalOffsetTexels) {
    return castsOnto(scene, f, visibleReceiverPoints(scene), reachTexels, normalOffsetTexels);
}

double cullReachTexels(const scene::RasterSettings& settings, const scene::Light& light, int mapSize) {
    double reach = kCullMarginTexels;
    if (settings.filter == scene::ShadowFilter::Pcss && light.type != scene::LightType::Directional &&
        light.radius > 0.0)
        reach += (light.type == scene::LightType::Point ? kCubeWrapReachFactor : 1.0) * kPcssReachFraction * mapSize;
    return reach + momentBlurRadius(settings);
}

int momentBlurRadius(const scene::RasterSettings& settings) {
    return scene::isFilterable(settings.filter) ? (settings.moments.blurWidth - 1) / 2 : 0;
}

double lookupOffsetTexels(const scene::RasterSettings& settings) {
    return settings.normalOffset + std::max(0.0, settings.slopeBias - 1.0);
}

double fitMarginTexels(const scene::RasterSettings& settings, const scene::Light& light, int mapSize, double t) {
    return cullReachTexels(settings, light, mapSize) + 2.0 * lookupOffsetTexels(settings) * std::sqrt(1.0 + t * t);
}

double snapWindowHalfSize(double half) {
    // 2^(k/4), k the smallest integer with 2^(k/4) ≥ half (the 1e-9 keeps an exact power itself).
    return std::exp2(std::ceil(4.0 * std::log2(half) - 1e-9) / 4.0);
}

// The fitted near and far planes lie on a geometric grid, the powers of 2^(1/4) (near rounded
// down, far up: the range only grows, so whatever it held it still holds). Why this grid:
// - distances from the light have no natural unit and no origin but the light, so the grid must be
//   scale-invariant: the same scene scaled by 2 gets the same planes scaled by 2, and moving the
//   whole scene (light included) away from the origin changes nothing;
// - perspective depth resolution is set by near (a depth step δz is δd ≈ δz·d²·(1/near − 1/far)
//   at distance d), so near must move by a bounded factor, not a bounded amount: a step that is a
//   fraction of the range would round a near much smaller than the range down to 0 (then to
//   far/1000, a ~1000-fold loss);
// - 2^(1/4) is the window's step (snapWindowHalfSize): near/far change about as rarely as the
//   texel size, only when what the camera sees changes depth by 19%.
// The cost: 1/near − 1/far grows from (1 − r)/near to at most (s − r/s)/near (s = 2^(1/4), r =
// near/far unsnapped), so depth steps get at most 1.19× coarser when near ≪ far, 1.54× at r = 0.5
// and 2.6× at r = 0.8 (a range a quarter of near wide); never coarser than a map
// with far at infinity and near/1.19, nor than the unfitted map (the range stays inside its range).
// With D32 float that is under 1e-7·d²/near world units, far below any bias.
double snapDepthDown(double d) {
    return std::exp2(std::floor(kDepthGridStepsPerOctave * std::log2(d)) / kDepthGridStepsPerOctave);
}
double snapDepthUp(double d) {
    return std::exp2(std::ceil(kDepthGridStepsPerOctave * std::log2(d)) / kDepthGridStepsPerOctave);
}

namespace {

// The nearest distance along f's axis of any point of an object's box inside f's window pyramid
// (the directions the map holds): the part of the box the map's depth pass can draw. A linear
// function on box ∩ pyramid (a convex polytope) is least at a vertex: a clipped face's vertex, or
// the pyramid's apex (the light) when the box holds it, which gives 0. +infinity when no box
// reaches into the pyramid.
double nearestDepthInWindow(const scene::Scene& scene, const LightFrustum& f) {
    const double u0 = f.windowU - f.tanHalfFov, u1 = f.windowU + f.tanHalfFov;
    const double v0 = f.windowV - f.tanHalfFov, v1 = f.windowV + f.tanHalfFov;
    // u ≤ u1 ⇔ u1·d − x ≥ 0, u ≥ u0 ⇔ x − u0·d ≥ 0 (d > 0), likewise v; planes through the light.
    const Vec3 normals[] = {u1 * f.direction - f.right, f.right - u0 * f.direction, v1 * f.direction - f.up,
                            f.up - v0 * f.direction, f.direction};
    Plane planes[5];
    for (int k = 0; k < 5; ++k) planes[k] = {normals[k], -glm::dot(normals[k], f.position)};
    double nearest = INFINITY;
    for (const scene::Object& object : scene.objects) {
        const scene::Bounds b = scene::boundsOf(object.shape);
        if (b.empty()) continue;
        if (glm::all(glm::greaterThanEqual(f.position, b.min)) && glm::all(glm::lessThanEqual(f.position, b.max)))
            return 0.0;
        for (const Vec3& p : clipBoxFaces(b, planes, 5))
            nearest = std::min(nearest, glm::dot(p - f.position, f.direction));
    }
    return nearest;
}

// Near/far of perspective map f (its window already set) from the intersection of the casters'
// and the receivers' depth ranges: far = the farthest receiver in front (maxDepth) grown by the
// margin (the normal offset moves a point up to that fraction of its distance farther) and 1%;
// near = the nearest caster in the window less 1%. Both are then snapped outward to the depth grid
// (snapDepthDown/Up) so that a moving camera leaves them, and so the depth scale, unchanged until
// they cross a step of it. Both stay inside f's own range (the bounding sphere's, fixed for the
// scene) and near ≥ far · kSpotMinNearOverFar (of the snapped far); f is unchanged when they would
// not make a range.
void fitDepthRange(const scene::Scene& scene, LightFrustum& f, double maxDepth, double marginTexels) {
    const double fitFar = maxDepth * (1.0 + marginTexels * f.texelWorldSize()) * kLightFrustumMargin;
    const double far = std::min(snapDepthUp(fitFar), f.far);
    const double nearest = nearestDepthInWindow(scene, f);
    // (nearest may be a rounding below 0 at the apex: the snap takes a logarithm, so only of > 0.)
    const double near =
        std::max({std::isfinite(nearest) && nearest > 0.0 ? snapDepthDown(nearest / kLightFrustumMargin) : f.near,
                  f.near, far * kSpotMinNearOverFar});
    if (!(near < far)) return;
    f.near = near;
    f.far = far;
}

}  // namespace

LightFrustum fitSpotLightToReceivers(const scene::Scene& scene, const scene::Light& light, int mapSize,
                                     double marginTexels) {
    LightFrustum f = fitSpotLight(scene.bounds(), light.position, light.direction, light.coneAngleDegrees, mapSize);
    const std::vector<Vec3> receivers = visibleReceiverPoints(scene);
    if (receivers.empty()) return f;
    const MapExtent r = perspectiveReceiverExtent(receivers, f);  // clamped to the cone's square
    if (r.empty()) return f;                                      // no receiver in front of the light
    bool inFront = true;
    for (const Vec3& p : receivers) inFront = inFront && glm::dot(p - f.position, f.direction) > 0.0;
    // The window: half-size h with the receivers' half-extent e, margin m texels and half a texel
    // for the center's snapping inside it: h − (m + ½)·2h/N ≥ e, i.e. h ≥ e / (1 − (2m + 1)/N),
    // rounded up to a power of 2^(1/4); the center to a multiple of the texel 2h/N.
    const double n = f.mapSize;
    const double keep = 1.0 - (2.0 * marginTexels + 1.0) / n;
    if (inFront && keep > 0.0) {
        const double extent = 0.5 * std::max(r.maxU - r.minU, r.maxV - r.minV);
        const double half = snapWindowHalfSize(std::max(extent / keep, 1e-9 * f.tanHalfFov));
        if (half < f.tanHalfFov) {
            const double texel = 2.0 * half / n;
            f.windowU = std::round(0.5 * (r.minU + r.maxU) / texel) * texel;
            f.windowV = std::round(0.5 * (r.minV + r.maxV) / texel) * texel;
            f.tanHalfFov = half;
        }
    }
    fitDepthRange(scene, f, r.maxDepth, marginTexels);
    return f;
}

LightFrustum spotLightFrustum(const scene::Scene& scene, const scene::RasterSettings& settings,
                              const scene::Light& light, int mapSize) {
    const LightFrustum cone =
        fitSpotLight(scene.bounds(), light.position, light.direction, light.coneAngleDegrees, mapSize);
    if (!settings.fitLightFrustum) return cone;
    // The fitted window's center lies in the cone's square and its half-size is below the cone's,
    // so no direction it holds has a tangent beyond 2·t.
    return fitSpotLightToReceivers(scene, light, mapSize,
                                   fitMarginTexels(settings, light, mapSize, 2.0 * cone.tanHalfFov));
}

LightFrustum fitPointLightFaceToReceivers(const scene::Scene& scene, const scene::Light& light, int face, int mapSize,
                                          double marginTexels) {
    LightFrustum f = fitPointLightFace(scene.bounds(), light.position, face, mapSize);
    const std::vector<Vec3> receivers = visibleReceiverPoints(scene);
    if (receivers.empty()) return f;
    const MapExtent r = perspectiveReceiverExtent(receivers, f);
    if (r.empty()) return f;  // no receiver in front of this face: nothing reads it
    fitDepthRange(scene, f, r.maxDepth, marginTexels);
    return f;
}

LightFrustum pointLightFaceFrustum(const scene::Scene& scene, const scene::RasterSettings& settings,
                                   const scene::Light& light, int face, int mapSize) {
    if (!settings.fitLightFrustum) return fitPointLightFace(scene.bounds(), light.position, face, mapSize);
    const double t = cubeFaceTanHalfFov(mapSize);
    return fitPointLightFaceToReceivers(scene, light, face, mapSize, fitMarginTexels(settings, light, mapSize, t));
}

std::vector<bool> layerCasters(const scene::Scene& scene, const scene::RasterSettings& settings,
                               const scene::Light& light, const LightFrustum& f, const std::vector<Vec3>& receivers) {
    return castsOnto(scene, f, receivers, cullReachTexels(settings, light, f.mapSize), lookupOffsetTexels(settings));
}

}  // namespace shadowlab::raster

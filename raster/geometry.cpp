// raster/geometry.cpp: UV spheres, two-triangle quads, 12-triangle boxes, meshes as given.
#include "raster/geometry.h"

#include <algorithm>
#include <cmath>

#include "raster/tolerances.h"
#include "raster/vulkan_error.h"
#include "scene/camera.h"

namespace shadowlab::raster {

namespace {

constexpr double kPi = 3.14159265358979323846;
using scene::Vec3;

class Builder {
public:
    Builder(SceneGeometry& out, const Vec3& origin, std::uint32_t objectId, bool withUvs)
        : out_(out), origin_(origin), id_(objectId), withUvs_(withUvs) {}

    std::uint32_t vertex(const Vec3& p, const Vec3& n, const scene::Vec2& uv = scene::Vec2(0.0)) {
        // Subtract in double, then round once: the float keeps the precision of the offset.
        out_.vertices.push_back(Vertex{glm::vec3(p - origin_), glm::vec3(n), id_});
        if (withUvs_) out_.uvs.emplace_back(uv);
        return std::uint32_t(out_.vertices.size() - 1);
    }
    void triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
        out_.indices.insert(out_.indices.end(), {a, b, c});
    }
    void quad(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
        triangle(a, b, c);
        triangle(a, c, d);
    }

private:
    SceneGeometry& out_;
    Vec3 origin_;
    std::uint32_t id_;
    bool withUvs_;
};

void addSphere(Builder& b, const scene::Sphere& s, int segments) {
    const int rings = segments / 2;
    // Rows of vertices from the north pole (ring 0) to the south pole (ring `rings`); the seam
    // column is duplicated so every row has segments + 1 vertices. The pole rows are kept
    // (degenerate triangles are skipped) to keep indexing simple.
    std::vector<std::uint32_t> row(std::size_t(rings + 1) * std::size_t(segments + 1));
    for (int i = 0; i <= rings; ++i) {
        const double theta = kPi * i / rings;
        for (int j = 0; j <= segments; ++j) {
            const double phi = 2.0 * kPi * j / segments;
            const Vec3 n(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
            row[std::size_t(i) * (segments + 1) + j] = b.vertex(s.center + s.radius * n, n);
        }
    }
    auto at = [&](int i, int j) { return row[std::size_t(i) * (segments + 1) + j]; };
    for (int i = 0; i < rings; ++i)
        for (int j = 0; j < segments; ++j) {
            if (i != 0) b.triangle(at(i, j), at(i + 1, j), at(i, j + 1));
            if (i != rings - 1) b.triangle(at(i, j + 1), at(i + 1, j), at(i + 1, j + 1));
        }
}

void addQuad(Builder& b, const scene::Quad& q) {
    const Vec3 du = 0.5 * q.size.x * q.uAxis;
    const Vec3 dv = 0.5 * q.size.y * q.vAxis;
    b.quad(b.vertex(q.center - du - dv, q.normal, q.uvMin),
           b.vertex(q.center + du - dv, q.normal, {q.uvMax.x, q.uvMin.y}),
           b.vertex(q.center + du + dv, q.normal, q.uvMax),
           b.vertex(q.center - du + dv, q.normal, {q.uvMin.x, q.uvMax.y}));
}

void addBox(Builder& b, const scene::Box& box) {
    // Per face: its normal axis and sign, four corners in order around the face.
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            Vec3 n(0.0);
            n[axis] = side ? 1.0 : -1.0;
            const int u = (axis + 1) % 3, v = (axis + 2) % 3;
            std::uint32_t corner[4];
            for (int k = 0; k < 4; ++k) {
                Vec3 p;
                p[axis] = side ? box.max[axis] : box.min[axis];
                p[u] = (k == 1 || k == 2) ? box.max[u] : box.min[u];
                p[v] = (k >= 2) ? box.max[v] : box.min[v];
                corner[k] = b.vertex(p, n);
            }
            b.quad(corner[0], corner[1], corner[2], corner[3]);
        }
}

// Instances are expanded here (a copy per placement at upload): the raster backend draws one
// vertex buffer, and its cost is per placed triangle anyway.
void addMesh(Builder& b, const scene::Object& o, const scene::Mesh& m) {
    for (const scene::MeshInstance& inst : m.instances) {
        if (!inst.geometry) throw RasterError(o.name + ": mesh " + m.file.string() + " has no loaded geometry");
        const scene::TriangleMesh& g = *inst.geometry;
        const glm::dmat3 nm = scene::normalMatrix(inst.transform);
        auto uv = [&](std::uint32_t i) { return i < g.uvs.size() ? g.uvs[i] : scene::Vec2(0.0); };
        if (g.normals.size() != g.positions.size()) {
            // No vertex normals (a mesh built in code; the loaders always compute them): flat
            // triangles with the face normal, as the ray tracer shades such a mesh.
            for (std::size_t t = 0; t + 2 < g.indices.size(); t += 3) {
                const std::uint32_t i[3] = {g.indices[t], g.indices[t + 1], g.indices[t + 2]};
                const Vec3 face =
                    nm * glm::cross(g.positions[i[1]] - g.positions[i[0]], g.positions[i[2]] - g.positions[i[0]]);
                const double len = glm::length(face);
                const Vec3 n = len > 0.0 ? face / len : Vec3(0, 1, 0);  // degenerate: draws nothing
                std::uint32_t v[3];
                for (int k = 0; k < 3; ++k)
                    v[k] = b.vertex(scene::transformPoint(inst.transform, g.positions[i[k]]), n, uv(i[k]));
                b.triangle(v[0], v[1], v[2]);
            }
            continue;
        }
        std::uint32_t base = 0;
        for (std::size_t i = 0; i < g.positions.size(); ++i) {
            const std::uint32_t v = b.vertex(scene::transformPoint(inst.transform, g.positions[i]),
                                             glm::normalize(nm * g.normals[i]), uv(std::uint32_t(i)));
            if (i == 0) base = v;
        }
        for (std::size_t t = 0; t + 2 < g.indices.size(); t += 3)
            b.triangle(base + g.indices[t], base + g.indices[t + 1], base + g.indices[t + 2]);
    }
    if (m.instances.empty()) throw RasterError(o.name + ": mesh " + m.file.string() + " has no loaded geometry");
}

}  // namespace

int sphereSegments(double radius, double distance, double tanHalfFovY, int imageHeight) {
    const double pixelWorld = 2.0 * std::max(distance, 0.0) * tanHalfFovY / std::max(imageHeight, 1);
    const double maxError = kSphereChordErrorPixels * pixelWorld;
    // r·(1 − cos(π/n)) <= e  ⇔  n >= π / acos(1 − e/r)
    int n = kMaxSphereSegments;
    if (radius > 0.0 && maxError > 0.0 && maxError < radius) {
        const double exact = kPi / std::acos(1.0 - maxError / radius);
        if (exact < kMaxSphereSegments) n = int(std::ceil(exact));
    } else if (maxError >= radius) {
        n = kMinSphereSegments;
    }
    n = std::clamp(n, kMinSphereSegments, kMaxSphereSegments);
    return n + (n % 2);  // even, so rings = n / 2 spans the poles exactly
}

SceneGeometry tessellateScene(const scene::Scene& scene, const scene::Vec3& origin, bool withUvs) {
    SceneGeometry out;
    const scene::CameraBasis cam = scene::cameraBasis(scene.camera);
    for (std::size_t i = 0; i < scene.objects.size(); ++i) {
        const scene::Object& o = scene.objects[i];
        out.objectFirstIndex.push_back(std::uint32_t(out.indices.size()));
        Builder b(out, origin, std::uint32_t(i + 1), withUvs);
        if (const auto* s = std::get_if<scene::Sphere>(&o.shape)) {
            // Nearest distance from the camera to the sphere; inside it, the near plane.
            const double d = std::max(glm::length(s->center - cam.position) - s->radius, scene.camera.near);
            const int n = sphereSegments(s->radius, d, cam.tanHalfFovY, cam.height);
            out.maxSphereSegments = std::max(out.maxSphereSegments, n);
            addSphere(b, *s, n);
        } else if (const auto* q = std::get_if<scene::Quad>(&o.shape)) {
            addQuad(b, *q);
        } else if (const auto* box = std::get_if<scene::Box>(&o.shape)) {
            addBox(b, *box);
        } else if (const auto* m = std::get_if<scene::Mesh>(&o.shape)) {
            addMesh(b, o, *m);
        }
    }
    out.objectFirstIndex.push_back(std::uint32_t(out.indices.size()));
    return out;
}

}  // namespace shadowlab::raster

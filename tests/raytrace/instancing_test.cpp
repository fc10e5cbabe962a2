// tests/raytrace/instancing_test.cpp: meshes placed several times are traced through one shared
// bottom-level tree and a top-level tree over their instances, and give what the same triangles
// copied into world space give: the same renders, the same hits as brute force.
#include <random>

#include <glm/gtc/matrix_transform.hpp>

#include <gtest/gtest.h>

#include "raytrace/renderer.h"
#include "raytrace/tracer.h"
#include "scene/loader.h"
#include "scene/mesh_loader.h"
#include "tests/kit/test_scenes.h"
#include "tests/scene/gltf_files.h"
#include "tests/scene/test_files.h"

namespace shadowlab::raytrace {
namespace {

using test::Vec3;

// The box used by three nodes (tests/scene/gltf_files.h), in front of a ground quad; the light
// comes low from the side so the boxes shadow the ground and each other.
const char* kNodes = R"([{"mesh": 0, "translation": [-1.5, 0, 0]},
  {"mesh": 0, "translation": [0.3, 0, 0.2], "rotation": [0, 0.3826834323650898, 0, 0.9238795325112867],
   "children": [2]},
  {"mesh": 0, "translation": [0, 0.5, 0], "scale": [0.6, 1.5, 0.8]}])";

// The same three placements written out by hand from the numbers above (not from the loader):
// node 0 = T(−1.5, 0, 0); node 1 = T(0.3, 0, 0.2)·R_y(45°); node 2 = node 1·T(0, 0.5, 0)·S.
std::vector<glm::dmat4> handTransforms() {
    const glm::dmat4 n0 = glm::translate(glm::dmat4(1.0), Vec3(-1.5, 0, 0));
    const glm::dmat4 n1 =
        glm::translate(glm::dmat4(1.0), Vec3(0.3, 0, 0.2)) * glm::dmat4(test::rotation(Vec3(0, 1, 0), 45.0));
    const glm::dmat4 n2 =
        n1 * glm::translate(glm::dmat4(1.0), Vec3(0, 0.5, 0)) * glm::scale(glm::dmat4(1.0), Vec3(0.6, 1.5, 0.8));
    return {n0, n1, n2};
}

std::string sceneJson() {
    return R"({"camera": {"position": [0.5, 2.5, 5], "look_at": [0, 0.4, 0], "fov_y": 40, "resolution": [96, 64]},
      "materials": {"m": {}},
      "lights": [{"type": "directional", "direction": [-1, -0.8, -0.5]}],
      "objects": [
        {"type": "quad", "center": [0, 0, 0], "normal": [0, 1, 0], "size": [8, 8], "material": "m"},
        {"type": "mesh", "file": "three.gltf", "material": "m"}]})";
}

// Loads the JSON scene with the glTF next to it, and the same scene with the mesh object
// replaced by one world-space mesh built here from the hand-written transforms.
struct TwoScenes {
    scene::Scene instanced, flattened;
};

TwoScenes loadBoth(const shadowlab::test::TempDir& dir) {
    dir.write("three.gltf", shadowlab::test::boxGltf(kNodes, "[0, 1]"));
    TwoScenes t;
    t.instanced = scene::loadScene(dir.write("s.json", sceneJson()));
    const scene::Mesh& mesh = std::get<scene::Mesh>(t.instanced.objects[1].shape);
    const scene::TriangleMesh& g = *mesh.instances.at(0).geometry;  // object space
    auto flat = std::make_shared<scene::TriangleMesh>();
    for (const glm::dmat4& m : handTransforms()) {
        const std::uint32_t base = std::uint32_t(flat->positions.size());
        const glm::dmat3 nm = glm::transpose(glm::inverse(glm::dmat3(m)));
        // The file has no normals, so the loaded box is flat: three corners of its own per triangle.
        for (std::size_t k = 0; k < g.positions.size(); ++k) {
            flat->positions.push_back(Vec3(m * glm::dvec4(g.positions[k], 1.0)));
            flat->normals.push_back(glm::normalize(nm * g.normals.at(k)));
        }
        for (std::uint32_t i : g.indices) flat->indices.push_back(base + i);
    }
    t.flattened = t.instanced;
    t.flattened.objects[1].shape = scene::Mesh::single("by hand", flat);
    return t;
}

TEST(Instancing, OneTreeServesThePlacementsAndMemoryCountsUniqueTriangles) {
    shadowlab::test::TempDir dir;
    const TwoScenes t = loadBoth(dir);
    const Tracer<float> inst(t.instanced), flat(t.flattened);
    EXPECT_EQ(inst.blasCount(), 1u);  // one geometry, three placements
    EXPECT_EQ(inst.triangleCount(), 36u);
    EXPECT_EQ(inst.uniqueTriangleCount(), 12u);
    EXPECT_EQ(flat.blasCount(), 1u);
    EXPECT_EQ(flat.uniqueTriangleCount(), 36u);
}

TEST(Instancing, AGltfMeshUsedByThreeNodesRendersLikeTheSameSceneFlattenedByHand) {
    shadowlab::test::TempDir dir;
    const TwoScenes t = loadBoth(dir);
    const scene::RenderPlan plan = test::planFor(t.instanced);
    scene::RaytraceSettings robust = test::biasSettings(0, scene::Precision::Float);
    robust.robustOffset = true;
    for (int mode = 0; mode < 3; ++mode) {
        SCOPED_TRACE(mode);
        auto run = [&](const scene::Scene& s) {
            if (mode == 0) return renderReference(s, plan, robust);
            if (mode == 1) return render(s, plan, robust);
            return render(s, plan, test::biasSettings(1e-3, scene::Precision::Float));
        };
        const scene::Frame a = run(t.instanced), b = run(t.flattened);
        int boxPixels = 0, shadowed = 0, idDiff = 0, visDiff = 0;
        for (std::size_t i = 0; i < a.pixelCount(); ++i) {
            if (a.objectId[i] == 2.0f) ++boxPixels;
            if (a.objectId[i] != 0.0f && a.visibility[i] == 0.0f && a.ndotl[i] > 0) ++shadowed;
            if (a.objectId[i] != b.objectId[i]) ++idDiff;
            if (a.visibility[i] != b.visibility[i]) ++visDiff;
        }
        // The scene shows the boxes and their shadows (else the comparison proves nothing).
        EXPECT_GT(boxPixels, 300);
        EXPECT_GT(shadowed, 80);
        // Object-space and world-space triangles round differently, which can only matter
        // for a ray within a few ulps of an edge; at 96x64 no pixel center comes that close.
        EXPECT_EQ(idDiff, 0);
        EXPECT_EQ(visDiff, 0);
    }
}

// World-space copy of every placed triangle with where it came from, for brute force.
struct PlacedTriangle {
    Vec3 p[3];
    int object, instance, prim;
};

TEST(Instancing, ClosestAndAnyHitEqualBruteForceOverThePlacedTriangles) {
    std::mt19937_64 g(4242);
    std::uniform_real_distribution<double> u(-1, 1), scale(0.3, 2.0);
    const auto ball = test::icosphere(Vec3(0.2, -0.1, 0.3), 1.0, 1);  // 80 triangles, shared
    scene::Scene s;
    test::addMaterial(s, "m");
    std::vector<PlacedTriangle> placed;
    auto place = [&](int object, int instance, const scene::TriangleMesh& m, const glm::dmat4& t) {
        for (std::size_t k = 0; k < m.triangleCount(); ++k) {
            PlacedTriangle p{{}, object, instance, int(k)};
            for (int v = 0; v < 3; ++v) p.p[v] = Vec3(t * glm::dvec4(m.positions[m.indices[3 * k + v]], 1.0));
            placed.push_back(p);
        }
    };
    auto randomTransform = [&] {
        return glm::translate(glm::dmat4(1.0), 5.0 * Vec3(u(g), u(g), u(g))) *
               glm::dmat4(test::rotation(Vec3(u(g), u(g), u(g)), 180 * u(g))) *
               glm::scale(glm::dmat4(1.0), Vec3(scale(g), scale(g), scale(g)));
    };
    // Object 0: six placements of the ball; object 1: a mesh used once (world space);
    // object 2: two more placements of the same ball (shared across objects).
    for (int object = 0; object < 3; ++object) {
        scene::Mesh mesh;
        mesh.file = "generated";
        const int count = object == 0 ? 6 : (object == 1 ? 1 : 2);
        for (int i = 0; i < count; ++i) {
            const glm::dmat4 t = randomTransform();
            auto geometry = object == 1 ? test::icosphere(Vec3(0), 1.0, 2) : ball;
            mesh.instances.push_back({geometry, scene::Affine(t)});
            place(object, object == 1 ? -1 : i, *geometry, t);
        }
        s.objects.push_back({"objects[" + std::to_string(object) + "]", mesh, 0});
    }
    auto check = [&](auto tag) {
        using Real = decltype(tag);
        const Tracer<Real> tracer(s);
        EXPECT_EQ(tracer.blasCount(), 2u);  // the ball once, the single-use mesh once
        int hits = 0;
        for (int r = 0; r < 4000; ++r) {
            const PlacedTriangle& target = placed[g() % placed.size()];
            const Vec3 aim = (target.p[0] + target.p[1] + target.p[2]) / 3.0;
            const Vec3 from = 12.0 * Vec3(u(g), u(g), u(g));
            // Rays at a triangle's centroid, and (every fourth) past everything.
            const Vec3 dir = r % 4 == 3 ? Vec3(u(g), u(g), u(g)) : aim - from;
            double best = std::numeric_limits<double>::infinity();
            const PlacedTriangle* nearest = nullptr;
            const Ray<double> rd(from, dir);
            for (const PlacedTriangle& p : placed) {
                double t, b0, b1, b2;
                if (intersectTriangle(rd, p.p[0], p.p[1], p.p[2], best, false, t, b0, b1, b2)) {
                    best = t;
                    nearest = &p;
                }
            }
            const Ray<Real> ray{Vec3T<Real>(from), Vec3T<Real>(dir)};
            Hit<Real> h;
            const bool found = tracer.closestHit(ray, std::numeric_limits<Real>::infinity(), false, h);
            ASSERT_EQ(found, nearest != nullptr) << r;
            if (!found) continue;
            ++hits;
            EXPECT_EQ(h.object, nearest->object) << r;
            EXPECT_EQ(h.instance, nearest->instance) << r;
            EXPECT_EQ(h.prim, nearest->prim) << r;
            // Object space rounds the ray differently (~1e-6 of the origin's magnitude in
            // float); along a grazing ray that moves t by that much over the cosine.
            const Vec3 n = glm::normalize(glm::cross(nearest->p[1] - nearest->p[0], nearest->p[2] - nearest->p[0]));
            const double cosine = std::max(std::abs(glm::dot(n, glm::normalize(dir))), 1e-6);
            const double tol = 1e-5 / cosine;
            EXPECT_NEAR(double(h.t), best, tol * best) << r;
            int blocker = -1;
            EXPECT_FALSE(tracer.anyHit(ray, Real(0.5 * best), false, blocker)) << r;
            EXPECT_TRUE(tracer.anyHit(ray, Real(1.01 * best), false, blocker)) << r;
            // The surface point comes from the instance's triangle and transform.
            const SurfacePoint<Real> sp = tracer.surfacePoint(ray, h, true);
            const Vec3 exact = from + best * dir;
            EXPECT_LT(glm::length(Vec3(sp.p) - exact), tol * (glm::length(from) + glm::length(exact))) << r;
            EXPECT_GT(std::abs(glm::dot(Vec3(sp.ng), n)), 1 - 1e-4) << r;
        }
        EXPECT_GT(hits, 2500);
    };
    check(float{});
    check(double{});
}

}  // namespace
}  // namespace shadowlab::raytrace

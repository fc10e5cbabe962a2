// tests/raytrace/triangle4_test.cpp: the SSE four-triangle filter never drops a hit the scalar
// watertight test would take, and does reject most misses (or it would save nothing).
#include "raytrace/triangle4.h"

#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "tests/kit/test_scenes.h"

namespace shadowlab::raytrace {
namespace {

using V = Vec3T<float>;

TEST(Triangle4, FilterKeepsEveryScalarHitAndRejectsMostMisses) {
    // Packets of four triangles of a closed icosphere (shared edges and vertices), shot with
    // rays aimed at its vertices, edge points and random points, so edge functions of exactly
    // zero and hits on shared edges occur.
    const auto mesh = test::icosphere(test::Vec3(0.25, -0.5, 1.0), 2.0, 2);
    const std::size_t tris = mesh->triangleCount();
    std::vector<TrianglePacket> packets((tris + 3) / 4);
    for (std::size_t t = 0; t < packets.size() * 4; ++t)
        for (int k = 0; k < 3; ++k)
            for (int a = 0; a < 3; ++a)
                packets[t / 4].v[3 * k + a][t % 4] = t < tris ? float(mesh->positions[mesh->indices[3 * t + k]][a])
                                                              : std::numeric_limits<float>::quiet_NaN();
    std::vector<V> targets;
    for (const auto& p : mesh->positions) targets.emplace_back(p);
    for (std::size_t t = 0; t < tris; ++t) {
        const V a(mesh->positions[mesh->indices[3 * t]]), b(mesh->positions[mesh->indices[3 * t + 1]]);
        targets.push_back(0.5f * (a + b));
    }
    std::mt19937_64 g(17);
    std::uniform_real_distribution<float> u(-6, 6);
    for (int i = 0; i < 300; ++i) targets.emplace_back(u(g) / 3, u(g) / 3, u(g) / 3);
    int scalarHits = 0, kept = 0, lanes = 0, dropped = 0;
    for (const V& target : targets) {
        for (int k = 0; k < 3; ++k) {
            const V o(u(g), u(g), u(g));
            const Ray<float> ray(o, target - o);
            const float tMax = k == 2 ? 0.9f : std::numeric_limits<float>::infinity();
            const Triangle4Ray r4(ray);
            for (std::size_t pk = 0; pk < packets.size(); ++pk) {
                const int valid = pk * 4 + 4 <= tris ? 15 : (1 << (tris - pk * 4)) - 1;
                const int cand = triangle4Candidates(r4, packets[pk], tMax, valid);
                EXPECT_EQ(cand & ~valid, 0);
                for (int l = 0; l < 4; ++l) {
                    if (!(valid & (1 << l))) continue;
                    ++lanes;
                    kept += (cand >> l) & 1;
                    float t, b0, b1, b2;
                    const TrianglePacket& p = packets[pk];
                    for (bool conservative : {false, true}) {
                        if (!intersectTriangle(ray, p.vertex(l, 0), p.vertex(l, 1), p.vertex(l, 2), tMax, conservative,
                                               t, b0, b1, b2))
                            continue;
                        ++scalarHits;
                        dropped += !((cand >> l) & 1);
                    }
                }
            }
        }
    }
    EXPECT_EQ(dropped, 0) << "of " << scalarHits << " scalar hits";
    EXPECT_GT(scalarHits, 1000);
    // Each ray hits a convex mesh at most twice: nearly every lane must be rejected.
    EXPECT_LT(kept, lanes / 20) << kept << " of " << lanes << " lanes kept";
}

}  // namespace
}  // namespace shadowlab::raytrace

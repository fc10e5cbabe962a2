// tests/raytrace/shadow_ray_test.cpp: shadow rays at chosen points: exact hard shadows,
// transmittance through semi-transparent objects, and robust offsets that never self-hit at
// any scale while the lesson's unbiased origin does.
#include "raytrace/shadow_ray.h"

#include <random>

#include <glm/gtc/matrix_transform.hpp>

#include <gtest/gtest.h>

#include "raytrace/renderer.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raytrace {
namespace {

using test::Vec3;

scene::RaytraceSettings robustSettings(scene::Precision precision) {
    scene::RaytraceSettings r = test::biasSettings(0.0, precision);
    r.robustOffset = true;
    return r;
}

std::vector<scene::RaytraceSettings> allModes() {
    return {robustSettings(scene::Precision::Double), robustSettings(scene::Precision::Float),
            test::biasSettings(1e-4, scene::Precision::Double), test::biasSettings(1e-4, scene::Precision::Float)};
}

double visibility(const scene::Scene& s, const Vec3& p, const Vec3& n, const scene::RaytraceSettings& rs) {
    return rs.precision == scene::Precision::Double ? visibilityAt<double>(s, p, n, 0, rs)
                                                    : visibilityAt<float>(s, p, n, 0, rs);
}

TEST(ShadowRay, UnitSphereShadowsExactlyTheUnitDiskBelowIt) {
    // Sphere r=1 at (0,2,0), light straight down: the shadow on y=0 is x² + z² < 1.
    scene::Scene s;
    test::addMaterial(s, "matte");
    test::addDirectional(s, Vec3(0, -1, 0));
    test::addSphere(s, Vec3(0, 2, 0), 1.0);
    test::addQuad(s, Vec3(0), Vec3(0, 1, 0), 10, 10);
    for (const auto& rs : allModes()) {
        SCOPED_TRACE(std::string(scene::toString(rs.precision)) + (rs.robustOffset ? " robust" : " bias"));
        EXPECT_EQ(visibility(s, {0.99, 0, 0}, {0, 1, 0}, rs), 0.0);
        EXPECT_EQ(visibility(s, {0, 0, -0.99}, {0, 1, 0}, rs), 0.0);
        EXPECT_EQ(visibility(s, {1.01, 0, 0}, {0, 1, 0}, rs), 1.0);
        EXPECT_EQ(visibility(s, {0.75, 0, 0.75}, {0, 1, 0}, rs), 1.0);  // 0.75√2 > 1
        EXPECT_EQ(visibility(s, {0.7, 0, 0.7}, {0, 1, 0}, rs), 0.0);    // 0.7√2 < 1
        // Facing away from the light: 0 without tracing.
        EXPECT_EQ(visibility(s, {5, 0, 0}, {0, -1, 0}, rs), 0.0);
    }
}

scene::Scene panesScene(double opacity) {
    scene::Scene s;
    test::addMaterial(s, "matte");
    const int glass = test::addMaterial(s, "glass", opacity);
    test::addDirectional(s, Vec3(0, -1, 0));
    test::addQuad(s, Vec3(0), Vec3(0, 1, 0), 10, 10);
    test::addQuad(s, Vec3(0, 1, 0), Vec3(0, 1, 0), 4, 4, glass);
    test::addQuad(s, Vec3(0, 2, 0), Vec3(0, -1, 0), 4, 4, glass);
    return s;
}

TEST(Transmittance, TwoHalfOpaquePanesPassAQuarter) {
    // (1 − 0.5)·(1 − 0.5) = 0.25 under both panes; beside them (|x| > 2) nothing blocks.
    const scene::Scene s = panesScene(0.5);
    for (const auto& rs : allModes()) {
        EXPECT_DOUBLE_EQ(visibility(s, {0.3, 0, -1.2}, {0, 1, 0}, rs), 0.25);
        EXPECT_DOUBLE_EQ(visibility(s, {3, 0, 0}, {0, 1, 0}, rs), 1.0);
    }
    // Opacity 0.2 each: 0.8² = 0.64.
    EXPECT_DOUBLE_EQ(visibility(panesScene(0.2), {0, 0, 0}, {0, 1, 0}, allModes()[0]), 0.64);
}

TEST(Transmittance, AnObjectCrossedThroughTwoSurfacesAttenuatesOnce) {
    // The ray enters and leaves the box (two faces) and the sphere (two points): each object
    // multiplies by 1 − 0.5 once.
    for (int shape = 0; shape < 2; ++shape) {
        scene::Scene s;
        test::addMaterial(s, "matte");
        const int glass = test::addMaterial(s, "glass", 0.5);
        test::addDirectional(s, Vec3(0, -1, 0));
        test::addQuad(s, Vec3(0), Vec3(0, 1, 0), 10, 10);
        if (shape == 0)
            test::addBox(s, Vec3(-1, 1, -1), Vec3(1, 2, 1), glass);
        else
            test::addSphere(s, Vec3(0, 2, 0), 1.0, glass);
        for (const auto& rs : allModes()) {
            EXPECT_DOUBLE_EQ(visibility(s, {0.2, 0, 0.1}, {0, 1, 0}, rs), 0.5);
            EXPECT_DOUBLE_EQ(visibility(s, {1.5, 0, 0}, {0, 1, 0}, rs), 1.0);
        }
        // A second glass object on the same ray: 0.25; an opaque one: 0.
        test::addQuad(s, Vec3(0, 4, 0), Vec3(0, 1, 0), 1, 1, glass);
        EXPECT_DOUBLE_EQ(visibility(s, {0.2, 0, 0.1}, {0, 1, 0}, allModes()[0]), 0.25);
        test::addQuad(s, Vec3(0, 5, 0), Vec3(0, 1, 0), 1, 1, 0);
        EXPECT_DOUBLE_EQ(visibility(s, {0.2, 0, 0.1}, {0, 1, 0}, allModes()[1]), 0.0);
    }
}

TEST(Transmittance, RenderedVisibilityTakesTheTransmittedFraction) {
    // Camera below the panes looking at the floor: floor points under the 4x4 panes get
    // 0.5·0.5 = 0.25, the rest 1. The floor point of a pixel comes from ray–plane algebra.
    scene::Scene s = panesScene(0.5);
    s.camera.position = Vec3(0, 0.5, 5);
    s.camera.lookAt = Vec3(0, 0, 0);
    s.camera.width = 64;
    s.camera.height = 48;
    const scene::RenderPlan plan = test::planFor(s);
    ASSERT_FALSE(plan.anyHitShadowRays);
    const scene::CameraBasis cam = scene::cameraBasis(s.camera);
    for (const auto& rs : allModes()) {
        const scene::Frame f = render(s, plan, rs);
        EXPECT_EQ(f.attributes.at("shadow_rays"), "closest-hit");
        int under = 0, outside = 0;
        for (int y = 0; y < f.height; ++y)
            for (int x = 0; x < f.width; ++x) {
                const std::size_t i = std::size_t(y) * f.width + x;
                const Vec3 d = scene::pixelDirection(cam, x, y);
                if (d.y >= 0) continue;
                const Vec3 p = cam.position + (-cam.position.y / d.y) * d;
                if (std::abs(p.x) > 5 || std::abs(p.z) > 5) continue;
                ASSERT_EQ(f.objectId[i], 1.0f);
                const double m = std::max(std::abs(p.x), std::abs(p.z));
                if (std::abs(m - 2) < 1e-6) continue;
                if (m < 2) {
                    ++under;
                    EXPECT_FLOAT_EQ(f.visibility[i], 0.25f);
                    EXPECT_EQ(f.blockerId[i], 2.0f);  // the lower pane is the nearest
                } else {
                    ++outside;
                    EXPECT_FLOAT_EQ(f.visibility[i], 1.0f);
                }
            }
        EXPECT_GT(under, 200);
        EXPECT_GT(outside, 200);
    }
}

TEST(AreaLight, OnAxisPenumbraEqualsTheUnblockedFractionOfTheLightsSolidAngle) {
    // Receiver at the origin facing +y; spherical light of radius R centered at (0, H, 0);
    // opaque sphere of radius ρ centered at (0, h, 0) between them. Seen from the origin both
    // are coaxial cones: the light's half-angle α = asin(R/H), the occluder's β = asin(ρ/h).
    // A cone's solid angle is 2π(1 − cos), so the unblocked fraction is
    //   V = 1 − (1 − cos β) / (1 − cos α)   (β < α),   V = 0   (β >= α).
    // The sampler stratifies u1 = (1 − cos θ)/(1 − cos α) into ny rows; the occluder's edge is
    // the line u1 = (1 − cos β)/(1 − cos α), so only one row is split: |V − exact| <= 1/ny.
    // Small and wide lights: with a wide one (α ≈ 39°) sampling uniformly over the light's
    // disk instead of its solid angle would be off by ~0.1.
    struct Config {
        double H, R, h, rho;
    };
    const int samples = 4096;  // 64 x 64 strata
    for (const Config& c :
         {Config{10, 2, 4, 0.1}, Config{10, 2, 4, 0.3}, Config{10, 2, 4, 0.5}, Config{10, 2, 4, 0.79},
          Config{10, 2, 4, 0.9}, Config{4, 2.5, 1, 0.25}, Config{4, 2.5, 1, 0.5}, Config{4, 2.5, 1.2, 0.3}}) {
        const double H = c.H, R = c.R, h = c.h, rho = c.rho;
        scene::Scene s;
        test::addMaterial(s, "matte");
        scene::Light light;
        light.type = scene::LightType::Point;
        light.position = Vec3(0, H, 0);
        light.radius = R;
        light.intensity = 100;
        s.lights.push_back(light);
        test::addSphere(s, Vec3(0, h, 0), rho);
        const double cosA = std::sqrt(1 - (R / H) * (R / H));
        const double cosB = std::sqrt(1 - (rho / h) * (rho / h));
        const double exact = rho / h < R / H ? 1 - (1 - cosB) / (1 - cosA) : 0.0;
        for (scene::RaytraceSettings rs : allModes()) {
            rs.samples = samples;
            const double v = visibility(s, Vec3(0), Vec3(0, 1, 0), rs);
            EXPECT_NEAR(v, exact, 1.0 / 64) << "rho " << rho;
        }
    }
}

// Random points on one object of size ~scale placed ~distance·scale from the origin: shadow
// rays leave each point into its outer hemisphere. Robust offsets must never hit the object
// again; the lesson's unbiased origin must (or the harness could not see a self-hit).
struct SelfHits {
    int rays = 0;
    int robust = 0;
    int plain = 0;
};

Vec3 randomUnit(std::mt19937_64& g) {
    std::normal_distribution<double> n;
    for (;;) {
        const Vec3 v(n(g), n(g), n(g));
        const double l = glm::length(v);
        if (l > 1e-6) return v / l;
    }
}

template <typename Real>
void countSelfHits(int kind, double scale, double distance, std::mt19937_64& g, SelfHits& out) {
    std::uniform_real_distribution<double> u(-1, 1), size(0.1, 2.0);
    const scene::RaytraceSettings robust =
        robustSettings(std::is_same_v<Real, float> ? scene::Precision::Float : scene::Precision::Double);
    for (int object = 0; object < 12; ++object) {
        scene::Scene s;
        test::addMaterial(s, "matte");
        const Vec3 center = distance * scale * Vec3(u(g), u(g), u(g));
        const double a = scale * size(g), b = scale * size(g), c = scale * size(g);
        if (kind == 0) test::addSphere(s, center, a);
        if (kind == 1) test::addQuad(s, center, randomUnit(g), a, b);
        if (kind == 2) test::addBox(s, center - Vec3(a, b, c) / 2.0, center + Vec3(a, b, c) / 2.0);
        if (kind == 3) test::addMesh(s, test::icosphere(center, a, 2));
        glm::dmat4 placement(1.0);
        if (kind == 4) {
            // Instanced: a unit icosphere placed twice (so it is traced in object space), the
            // first time scaled by a, b, c on its axes, turned about a random axis and moved to
            // center; the second placement is far away and only makes the mesh multi-use.
            placement = glm::translate(glm::dmat4(1.0), center) *
                        glm::dmat4(test::rotation(randomUnit(g), 180 * u(g))) *
                        glm::scale(glm::dmat4(1.0), Vec3(a, b, c));
            const auto ball = test::icosphere(Vec3(0), 1.0, 2);
            scene::Mesh mesh;
            mesh.instances = {{ball, scene::Affine(placement)},
                              {ball, scene::Affine(glm::translate(glm::dmat4(1.0), center + Vec3(1e6 * scale)) *
                                                   glm::scale(glm::dmat4(1.0), Vec3(scale)))}};
            s.objects.push_back({"objects[0]", mesh, 0});
        }
        const Tracer<Real> tracer(s);
        for (int point = 0; point < 40; ++point) {
            // Aim at a point inside the object (or on the quad) from far outside it.
            Vec3 aim = center;
            if (kind == 0 || kind == 3) aim += 0.9 * a * std::abs(u(g)) * randomUnit(g);
            if (kind == 4) aim = Vec3(placement * glm::dvec4(0.9 * std::abs(u(g)) * randomUnit(g), 1.0));
            if (kind == 2) aim += 0.45 * Vec3(a * u(g), b * u(g), c * u(g));
            if (kind == 1) {
                const scene::Quad& q = std::get<scene::Quad>(s.objects[0].shape);
                aim += 0.45 * (a * u(g) * q.uAxis + b * u(g) * q.vAxis);
            }
            const Vec3 from = aim + 10.0 * scale * randomUnit(g);
            const Ray<Real> primary(Vec3T<Real>(from), Vec3T<Real>(aim - from));
            Hit<Real> hr, hp;
            if (!tracer.closestHit(primary, std::numeric_limits<Real>::infinity(), true, hr)) continue;
            if (!tracer.closestHit(primary, std::numeric_limits<Real>::infinity(), false, hp)) continue;
            const SurfacePoint<Real> spr = tracer.surfacePoint(primary, hr, true);
            const SurfacePoint<Real> spp = tracer.surfacePoint(primary, hp, false);
            for (int ray = 0; ray < 16; ++ray) {
                // A direction into the outer hemisphere, not within 0.6° of grazing (a grazing
                // ray could truly re-enter a sphere whose normal is off by rounding).
                Vec3 w = randomUnit(g);
                const Vec3 ng(spr.ng);
                if (glm::dot(w, ng) < 0) w = -w;
                if (glm::dot(w, ng) < 0.01) continue;
                const Vec3T<Real> wr(w);
                int blocker = -1;
                ++out.rays;
                if (tracer.anyHit(Ray<Real>(shadowOrigin(spr, wr, robust), wr), std::numeric_limits<Real>::infinity(),
                                  true, blocker))
                    ++out.robust;
                if (tracer.anyHit(Ray<Real>(spp.p, wr), std::numeric_limits<Real>::infinity(), false, blocker))
                    ++out.plain;
            }
        }
    }
}

template <typename Real>
void expectNoRobustSelfHits(int firstKind = 0, int lastKind = 3,
                            std::vector<double> scales = {1e-8, 1e-4, 1.0, 1e4, 1e8}) {
    const char* names[] = {"sphere", "quad", "box", "triangle mesh", "instanced mesh"};
    std::mt19937_64 g(12345);
    for (int kind = firstKind; kind <= lastKind; ++kind) {
        SelfHits total;
        for (double scale : scales) {
            for (double distance : {1.0, 1000.0}) {
                SelfHits h;
                countSelfHits<Real>(kind, scale, distance, g, h);
                EXPECT_EQ(h.robust, 0) << names[kind] << " scale " << scale << " distance " << distance << ": "
                                       << h.robust << " of " << h.rays;
                total.rays += h.rays;
                total.plain += h.plain;
            }
        }
        EXPECT_GT(total.rays, 10000) << names[kind];
        // The same points without an offset self-hit often: the harness can see a self-hit.
        EXPECT_GT(total.plain, total.rays / 50) << names[kind] << ": " << total.plain;
    }
}

TEST(RobustOffset, NoSelfHitsOnSpheresQuadsBoxesMeshesFrom1eMinus8To1e8InDouble) { expectNoRobustSelfHits<double>(); }

TEST(RobustOffset, NoSelfHitsOnSpheresQuadsBoxesMeshesFrom1eMinus8To1e8InFloat) { expectNoRobustSelfHits<float>(); }

// The instance transform is part of the error bound (docs/raytrace.md, "Instances"): scale
// 1e-3 and 1e4 (non-uniform within 0.1..2 of that), any rotation, placed 1x and 1000x its size
// from the origin (and 1e-8, 1, 1e8 as for the other shapes).
TEST(RobustOffset, NoSelfHitsOnInstancedMeshesScaledRotatedAndMovedInDoubleAndFloat) {
    expectNoRobustSelfHits<double>(4, 4, {1e-8, 1e-3, 1.0, 1e4, 1e8});
    expectNoRobustSelfHits<float>(4, 4, {1e-8, 1e-3, 1.0, 1e4, 1e8});
}

}  // namespace
}  // namespace shadowlab::raytrace

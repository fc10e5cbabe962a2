// raytrace/view_search.cpp: candidate views and suns for a model, scored at thumbnail size.
#include "raytrace/view_search.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "raytrace/shadow_ray.h"
#include "raytrace/tracer.h"
#include "scene/camera.h"
#include "scene/model_view.h"
#include "scene/settings.h"

namespace shadowlab::raytrace {

namespace {

using scene::Vec3;
using V = Vec3T<float>;
constexpr double kPi = 3.14159265358979323846;
constexpr double kDegrees = kPi / 180.0;

// Candidate grids (docs/decisions.md): 12 azimuths × 2 elevations around a model, 8 headings
// from each of at most 6 points inside an enclosing one; 8 sun azimuths × 3 elevations, all at
// least 35° up, so a shadow stays within a few model heights (and on the added ground).
constexpr int kOutsideAzimuths = 12;
constexpr double kOutsideElevations[] = {20.0, 40.0};
constexpr int kInsideHeadings = 8;
constexpr int kInsideEyes = 6;
constexpr int kSunAzimuths = 8;
constexpr double kSunElevations[] = {35.0, 55.0, 75.0};
// Interior test: a probe point is enclosed when this share of its directions (12 headings × 3
// elevations, −20°..+20°) meets a front face; the model encloses its space when a quarter of the
// probe points outside solids are enclosed.
constexpr double kEnclosedShare = 0.9;
constexpr double kInteriorAmbient = 0.15;
constexpr double kInteriorShare = 0.25;
// The variety of shadows in view is the effective number of casters whose shadow outlines are
// seen; a view that shows the outlines of kVarietyCasters casters evenly is varied enough.
constexpr int kVarietyCasters = 4;
// Thumbnail::legibility: a surface seen within 60° of head-on shows its shadows' shapes.
constexpr double kFullLegibility = 0.5;
// The holes in a shadow (light through MASK texels below the cutoff, BLEND, opacity < 1) count
// where the best candidate shows at least this much of their outline, in thumbnail pixel pairs:
// one hole two pixels across.
constexpr double kMinHoleEdges = 8.0;
// The best ViewSearchOptions::refine pairs are scored again at kRefineScale times the thumbnail
// width (192 × 108): a MASK board's holes or a strap's shadow, a pixel or two at 64, decide there.
constexpr int kRefineScale = 3;

std::string fmt(double v, const char* f = "%.3g") {
    char buf[64];
    std::snprintf(buf, sizeof buf, f, v);
    return buf;
}

// One thumbnail's primary hits: what the shadow tests of every candidate sun start from.
struct Thumbnail {
    int width = 0, height = 0;
    std::vector<SurfacePoint<float>> points;  // object -1: background
    std::vector<float> distance;              // to the eye, for the near-wall test
    std::vector<float> cosView;               // |cos| between the view ray and the surface's normal
    double pixelAngle = 0;                    // radians between neighbouring pixels' rays (at the center)

    // A shadow on a surface seen at angle θ from head-on appears squeezed to cos θ of its width.
    // Within 60° (squeezed at most in half) its shape still reads and the pixel counts whole;
    // nearer edge-on it counts |cos| / 0.5 of one in the shadow share, the edges and the holes.
    double legibility(std::size_t i) const { return std::min(1.0, double(cosView[i]) / kFullLegibility); }

    // Neighbouring pixels i and j see one surface, not a silhouette against what lies behind it:
    // the same object, at depths no further apart than a plane seen at their angle would put
    // them (d·α·tanθ ≤ d·α / |cos|, twice that for curvature).
    bool sameSurface(std::size_t i, std::size_t j) const {
        if (points[i].object != points[j].object) return false;
        const double c = std::max(0.05f, std::min(cosView[i], cosView[j]));
        return std::abs(distance[i] - distance[j]) <= 2.0 * pixelAngle * std::max(distance[i], distance[j]) / c;
    }
};

Thumbnail primaryHits(const Tracer<float>& tracer, const scene::Camera& camera, int width, int height) {
    scene::Camera c = camera;
    c.width = width;
    c.height = height;
    const scene::CameraBasis basis = scene::cameraBasis(c);
    Thumbnail t;
    t.width = width;
    t.height = height;
    t.points.resize(std::size_t(width) * height);
    t.distance.assign(t.points.size(), 0.0f);
    t.cosView.assign(t.points.size(), 0.0f);
    t.pixelAngle = 2.0 * std::tan(0.5 * c.fovYDegrees * kDegrees) / height;
    tbb::parallel_for(0, height, [&](int y) {
        for (int x = 0; x < width; ++x) {
            const Vec3 d = glm::normalize(scene::pixelDirection(basis, x, y));
            const Ray<float> ray(V(camera.position), V(d));
            Hit<float> hit;
            SurfacePoint<float>& sp = t.points[std::size_t(y) * width + x];
            sp.object = -1;
            if (!tracer.closestHit(ray, std::numeric_limits<float>::infinity(), false, hit)) continue;
            sp = tracer.surfacePoint(ray, hit, false);
            sp.object = hit.object;
            t.distance[std::size_t(y) * width + x] = hit.t;
            const double cosView = std::abs(glm::dot(Vec3(sp.ng), d));
            t.cosView[std::size_t(y) * width + x] = float(cosView);
        }
    });
    return t;
}

// Per pixel: -1 background, 0 faces away from the light, 1 lit, 2 in cast shadow, 3 lit through
// a cut-out (its light crosses an object that lets light through: a hole in that object's
// shadow); for the shadowed ones the object that casts the shadow.
struct Shading {
    std::vector<std::int8_t> cls;
    std::vector<int> blocker;
};

// Objects whose shadow can have holes: MASK whose alpha can fall below its cutoff, BLEND,
// opacity < 1.
std::vector<int> seeThroughObjects(const scene::Scene& scene) {
    std::vector<int> out;
    for (std::size_t i = 0; i < scene.objects.size(); ++i) {
        const scene::Material& m = scene.materialOf(scene.objects[i]);
        const bool mask = m.alphaMode == scene::AlphaMode::Mask && m.alphaCanFallBelow(m.alphaCutoff);
        if (!m.opaque() || mask) out.push_back(int(i));
    }
    return out;
}

// A lit point's light crosses one of `seeThrough` (its surface, alpha ignored): one ray toward the
// light's center, as for a point or directional light.
bool litThrough(const Tracer<float>& tracer, const scene::Light& light, const SurfacePoint<float>& sp,
                const scene::RaytraceSettings& settings, const std::vector<int>& seeThrough) {
    const bool directional = light.type == scene::LightType::Directional;
    const V w = directional ? V(-light.direction) : V(light.position) - sp.p;
    const V o = shadowOrigin(sp, w, settings);
    const Ray<float> ray(o, directional ? w : V(light.position) - o);
    const float tMax = directional ? std::numeric_limits<float>::infinity() : 1.0f;
    for (const int k : seeThrough) {
        Hit<float> h;
        if (tracer.intersectObject(k, ray, tMax, false, true, h, scene::AlphaTest::Off)) return true;
    }
    return false;
}

Shading shadowClasses(const Tracer<float>& tracer, const Thumbnail& t, const scene::Light& light, double rayBias,
                      bool anyHit, const std::vector<int>& seeThrough) {
    Shading out{std::vector<std::int8_t>(t.points.size(), -1), std::vector<int>(t.points.size(), -1)};
    scene::RaytraceSettings settings;
    settings.rayBias = rayBias;
    settings.samples = 4;
    const double cosCone = std::cos(light.coneAngleDegrees * kDegrees);
    tbb::parallel_for(0, t.height, [&](int y) {
        Rng rng(0x5eedull + std::uint64_t(y));
        for (int x = 0; x < t.width; ++x) {
            const std::size_t i = std::size_t(y) * t.width + x;
            const SurfacePoint<float>& sp = t.points[i];
            if (sp.object < 0) continue;
            const Vec3 p(sp.p), n(sp.ns);
            Vec3 toLight = -light.direction;
            if (light.type != scene::LightType::Directional) toLight = glm::normalize(light.position - p);
            bool reached = glm::dot(n, toLight) > 0;
            if (light.type == scene::LightType::Spot)
                reached = reached && glm::dot(-toLight, light.direction) >= cosCone;
            if (!reached) {
                out.cls[i] = 0;
                continue;
            }
            const ShadowResult r = lightVisibility(tracer, light, sp, settings, anyHit, rng);
            out.cls[i] = r.transmittance < 0.5 ? 2 : 1;
            if (out.cls[i] == 2)
                out.blocker[i] = r.blocker;
            else if (!seeThrough.empty() && litThrough(tracer, light, sp, settings, seeThrough))
                out.cls[i] = 3;
        }
    });
    return out;
}

// `ground`: the added ground's object index (-1 when none), left out of the model's own facing
// share; `casters`: the objects that can cast (all but the ground). Shadow shares, edges and the
// holes count each pixel by its legibility (Thumbnail::legibility).
ViewScore score(const Thumbnail& t, const Shading& shading, const Vec3& forward, const scene::Light& light,
                double nearWall, int ground, int casters) {
    const std::vector<std::int8_t>& cls = shading.cls;
    ViewScore s;
    std::size_t hit = 0, facing = 0, near = 0, model = 0, modelFacing = 0;
    double facingWeight = 0, shadowed = 0, edges = 0, holeEdges = 0;
    // Per caster, the lit–shadowed pairs on the shadowed side of which it is the blocker: the
    // outline of its shadow as the view shows it. A caster whose shadow lies inside another's
    // shadow has none, however many pixels it would darken alone.
    std::vector<double> outline(std::size_t(std::max(casters, 0)), 0.0);
    for (int y = 0; y < t.height; ++y)
        for (int x = 0; x < t.width; ++x) {
            const std::size_t i = std::size_t(y) * t.width + x;
            if (cls[i] < 0) continue;
            ++hit;
            if (t.distance[i] < nearWall) ++near;
            const bool onModel = t.points[i].object != ground;
            model += onModel;
            modelFacing += onModel && cls[i] > 0;
            if (cls[i] == 0) continue;
            ++facing;
            const double w = t.legibility(i);
            facingWeight += w;
            shadowed += cls[i] == 2 ? w : 0.0;
            for (const std::size_t j : {x + 1 < t.width ? i + 1 : i, y + 1 < t.height ? i + t.width : i}) {
                // A shadow's outline: lit against shadowed on one surface (a lit caster seen against
                // the shadow behind it is a silhouette, not an outline).
                if (j == i || cls[j] <= 0 || (cls[i] == 2) == (cls[j] == 2) || !t.sameSurface(i, j)) continue;
                const double e = std::min(w, t.legibility(j));
                edges += e;
                holeEdges += cls[i] == 3 || cls[j] == 3 ? e : 0.0;  // a hole's outline: lit through a cut-out
                const int b = shading.blocker[cls[i] == 2 ? i : j];
                if (b >= 0 && std::size_t(b) < outline.size()) outline[std::size_t(b)] += e;
            }
        }
    const double pixels = double(t.points.size());
    s.coverage = hit / pixels;
    s.facing = hit ? double(facing) / double(hit) : 0.0;
    s.shadowedShare = facingWeight > 0 ? shadowed / facingWeight : 0.0;
    s.edgeLength = edges / double(t.width + t.height);
    s.holeEdgeLength = holeEdges / double(t.width + t.height);
    s.sunSide = light.type == scene::LightType::Directional ? glm::dot(forward, light.direction) : 0.0;
    // The effective number of casters (inverse Simpson index of their outline lengths): n casters
    // with equal outlines give n, one long outline beside short ones gives little more than 1.
    double sum = 0, sumSquares = 0;
    for (const double o : outline) {
        sum += o;
        sumSquares += o * o;
    }
    s.casters = sumSquares > 0 ? sum * sum / sumSquares : 0.0;
    // Shadows a quarter to a third of the lit-facing surface read best; more is a dark picture.
    const double fShare =
        s.shadowedShare <= 0.35 ? s.shadowedShare / 0.35 : std::max(0.2, 1.0 - (s.shadowedShare - 0.35) / 0.4);
    const double fEdge = std::min(1.0, 0.5 * s.edgeLength);  // two image sides of edge: a pattern, not one line
    const double fCover = std::min(1.0, s.coverage / 0.5);
    // Most of what is seen should face the light, the model itself included: a model seen from
    // its dark side shows its shadow but not itself.
    s.modelFacing = model ? double(modelFacing) / double(model) : 0.0;
    const double fFacing = std::min(1.0, s.facing / 0.6) * std::min(1.0, 0.2 + s.modelFacing / 0.6);
    // From the sun's side every shadow hides behind its caster.
    const double fSide = 1.0 - 0.6 * std::max(0.0, s.sunSide);
    const double fNear = hit && near > hit / 2 ? 0.3 : 1.0;  // half the view is a wall in the face (4% of the size)
    // Of several casters, a view that shows the outlines of more of them evenly (a row of cut-out
    // cards, not the one wall whose shadow swallows theirs) tells more; a single caster's scene
    // is not affected.
    const int wanted = std::clamp(casters, 1, kVarietyCasters);
    const double fVariety = 0.5 + 0.5 * std::min(1.0, s.casters / double(wanted));
    s.score = fCover * fFacing * (0.5 * fShare + 0.5 * fEdge) * fSide * fNear * fVariety;
    return s;
}

scene::Light sunLight(const scene::Scene& scene, double az, double el) {
    scene::Light l = scene.lights.empty() ? scene::Light{} : scene.lights.front();
    l.type = scene::LightType::Directional;
    l.direction = scene::sunDirection(az, el);
    l.radius = 0;
    return l;
}

// Probe points on a 5 × 5 grid over the inner part of the footprint at 20% and 40% of the
// height: inside a solid when a third of the hits are back faces, enclosed when nearly every
// direction meets a front face.
void probeInterior(const Tracer<float>& tracer, const scene::Bounds& b, ViewSearchResult& r,
                   std::vector<Vec3>& enclosed) {
    const Vec3 e = b.extent();
    std::vector<Vec3> probes;
    for (double h : {0.2, 0.4})
        for (int iz = 0; iz < 5; ++iz)
            for (int ix = 0; ix < 5; ++ix)
                probes.push_back(
                    {b.min.x + e.x * (0.1 + 0.2 * ix), b.min.y + e.y * h, b.min.z + e.z * (0.1 + 0.2 * iz)});
    std::vector<int> state(probes.size(), 0);  // 0 open, 1 enclosed, 2 inside a solid
    std::vector<int> sky(probes.size(), 0);    // upward rays (45° and 70°) that meet nothing
    tbb::parallel_for(std::size_t(0), probes.size(), [&](std::size_t k) {
        for (double el : {45.0, 70.0})
            for (int a = 0; a < 12; ++a) {
                const double az = (a + 0.5) * 30.0 * kDegrees;
                const Vec3 d(std::cos(el * kDegrees) * std::sin(az), std::sin(el * kDegrees),
                             std::cos(el * kDegrees) * std::cos(az));
                Hit<float> hit;
                if (!tracer.closestHit(Ray<float>(V(probes[k]), V(d)), std::numeric_limits<float>::infinity(), false,
                                       hit))
                    ++sky[k];
            }
        int front = 0, back = 0, total = 0;
        for (double el : {-20.0, 0.0, 20.0})
            for (int a = 0; a < 12; ++a) {
                const double az = (a + 0.5) * 30.0 * kDegrees;
                const Vec3 d(std::cos(el * kDegrees) * std::sin(az), std::sin(el * kDegrees),
                             std::cos(el * kDegrees) * std::cos(az));
                const Ray<float> ray(V(probes[k]), V(d));
                Hit<float> hit;
                ++total;
                if (!tracer.closestHit(ray, std::numeric_limits<float>::infinity(), false, hit)) continue;
                const SurfacePoint<float> sp = tracer.surfacePoint(ray, hit, false);
                // Quads are two-sided walls: a back hit on one says nothing about solids.
                if (sp.backFacing && tracer.kind(hit.object) != ShapeKind::Quad)
                    ++back;
                else
                    ++front;
            }
        state[k] = back * 3 >= front + back && back > 0 ? 2 : front >= kEnclosedShare * total ? 1 : 0;
    });
    std::vector<std::size_t> order;
    for (std::size_t k = 0; k < probes.size(); ++k) {
        if (state[k] == 2) continue;
        ++r.probePoints;
        if (state[k] == 1) {
            ++r.enclosedPoints;
            order.push_back(k);
        }
    }
    // The eyes a view from inside starts from: where most sky shows, since that is where a sun
    // can shine in and cast shadows in sight (a stable sort keeps the grid order among equals).
    std::stable_sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) { return sky[i] > sky[j]; });
    for (std::size_t k : order) enclosed.push_back(probes[k]);
    r.interior = r.enclosedPoints >= 3 && r.enclosedPoints >= kInteriorShare * r.probePoints;
}

struct Candidate {
    scene::Camera camera;
    std::string text;
    bool framed = false;  // a view from outside framing the model (framedCamera), not a file's camera
};

// With --camera auto the file's own cameras compete too (a city model's first camera may face a
// wall in shadow while another looks down a sunlit street).
void addFileCameras(const scene::Scene& scene, std::vector<Candidate>& out) {
    for (std::size_t i = 0; i < scene.origin.cameras.size(); ++i) {
        const scene::FileCamera& c = scene.origin.cameras[i];
        out.push_back({c.camera, "file camera " + std::to_string(i) + (c.name.empty() ? "" : " '" + c.name + "'")});
    }
}

std::vector<Candidate> viewCandidates(const scene::Scene& scene, const scene::Bounds& b, bool interior,
                                      const std::vector<Vec3>& enclosed) {
    std::vector<Candidate> out;
    if (!interior) {
        for (double el : kOutsideElevations)
            for (int a = 0; a < kOutsideAzimuths; ++a) {
                const double az = a * 360.0 / kOutsideAzimuths;
                const Vec3 from(std::cos(el * kDegrees) * std::sin(az * kDegrees), std::sin(el * kDegrees),
                                std::cos(el * kDegrees) * std::cos(az * kDegrees));
                out.push_back({scene::framedCamera(b, from, 40.0, scene.camera),
                               "from outside, azimuth " + fmt(az) + ", elevation " + fmt(el) + " degrees", true});
            }
        addFileCameras(scene, out);
        return out;
    }
    // Inside: the enclosed probe points that see the most sky (probeInterior's order).
    const std::vector<Vec3> eyes(enclosed.begin(),
                                 enclosed.begin() + std::min<std::size_t>(enclosed.size(), kInsideEyes));
    const double diag = b.diagonal();
    for (const Vec3& eye : eyes)
        for (int h = 0; h < kInsideHeadings; ++h) {
            const double az = h * 360.0 / kInsideHeadings;
            const double pitch = -10.0;
            const Vec3 d(std::cos(pitch * kDegrees) * std::sin(az * kDegrees), std::sin(pitch * kDegrees),
                         std::cos(pitch * kDegrees) * std::cos(az * kDegrees));
            scene::Camera c = scene.camera;
            c.position = eye;
            c.lookAt = eye + d;
            c.up = {0, 1, 0};
            c.fovYDegrees = 60.0;
            c.near = 1e-3 * diag;
            c.far = 2.0 * diag;
            out.push_back({c, "from inside at (" + fmt(eye.x) + ", " + fmt(eye.y) + ", " + fmt(eye.z) + "), heading " +
                                  fmt(az) + " degrees, 10 degrees down"});
        }
    addFileCameras(scene, out);
    return out;
}

// The ground scene/model_view.h adds is the last object, named "ground", on its own material.
int groundIndex(const scene::Scene& scene) {
    if (scene.objects.empty() || scene.objects.back().name != "ground" ||
        !std::holds_alternative<scene::Quad>(scene.objects.back().shape))
        return -1;
    return int(scene.objects.size()) - 1;
}

// Objects that can cast a shadow the score counts: all but the added ground.
int casterCount(const scene::Scene& scene) { return int(scene.objects.size()) - (groundIndex(scene) >= 0 ? 1 : 0); }

int thumbnailHeight(const scene::Camera& c, int width) {
    return std::clamp(int(std::lround(double(width) * c.height / std::max(1, c.width))), 16, 4 * width);
}

}  // namespace

ViewScore scoreScene(const scene::Scene& scene, int width, int threads) {
    tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
    ViewScore s;
    arena.execute([&] {
        const Tracer<float> tracer(scene);
        const Thumbnail t = primaryHits(tracer, scene.camera, width, thumbnailHeight(scene.camera, width));
        const scene::CameraBasis basis = scene::cameraBasis(scene.camera);
        s = score(t,
                  shadowClasses(tracer, t, scene.lights.front(), scene::defaultRayBias(scene), scene.allOpaque(),
                                seeThroughObjects(scene)),
                  basis.forward, scene.lights.front(), 0.0, groundIndex(scene), casterCount(scene));
    });
    return s;
}

ViewSearchResult searchViewAndSun(const scene::Scene& scene, const ViewSearchOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    ViewSearchResult r;
    r.camera = scene.camera;
    if (!scene.lights.empty()) r.sunDirection = scene.lights.front().direction;
    tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
    arena.execute([&] {
        const Tracer<float> tracer(scene);
        const scene::Bounds b = scene.origin.modelBounds.empty() ? scene.bounds() : scene.origin.modelBounds;
        std::vector<Vec3> enclosed;
        probeInterior(tracer, b, r, enclosed);
        std::vector<Candidate> views;
        if (options.chooseView)
            views = viewCandidates(scene, b, r.interior, enclosed);
        else
            views.push_back({scene.camera, "the scene's camera"});
        std::vector<std::pair<scene::Light, std::string>> suns;
        if (options.chooseSun) {
            for (double el : kSunElevations)
                for (int a = 0; a < kSunAzimuths; ++a) {
                    const double az = a * 360.0 / kSunAzimuths;
                    suns.emplace_back(sunLight(scene, az, el),
                                      "azimuth " + fmt(az) + ", elevation " + fmt(el) + " degrees");
                }
        } else {
            suns.emplace_back(scene.lights.front(), "the scene's light");
        }
        r.width = options.width;
        r.height = thumbnailHeight(scene.camera, options.width);
        r.views = int(views.size());
        r.suns = int(suns.size());
        const double rayBias = scene::defaultRayBias(scene);
        const double nearWall = r.interior ? 0.04 * b.diagonal() : 0.0;
        const int ground = groundIndex(scene);
        const int casters = casterCount(scene);
        const std::vector<int> seeThrough = seeThroughObjects(scene);
        struct Scored {
            ViewScore score;
            std::size_t view, sun;
        };
        // The holes in a shadow are what a model's cut-outs are for: where some candidate shows
        // them, each candidate's score is multiplied by its hole outline relative to the most shown.
        auto weighByHoles = [](std::vector<Scored>& list, bool holes) {
            double most = 0;
            for (const Scored& c : list) most = std::max(most, c.score.holeEdgeLength);
            if (!holes || !(most > 0)) return;
            for (Scored& c : list) c.score.score *= c.score.holeEdgeLength / most;
        };
        std::vector<Scored> scored;
        for (std::size_t v = 0; v < views.size(); ++v) {
            const Thumbnail t = primaryHits(tracer, views[v].camera, r.width, r.height);
            const Vec3 forward = scene::cameraBasis(views[v].camera).forward;
            for (std::size_t s = 0; s < suns.size(); ++s) {
                const ViewScore sc =
                    score(t, shadowClasses(tracer, t, suns[s].first, rayBias, scene.allOpaque(), seeThrough), forward,
                          suns[s].first, nearWall, ground, casters);
                scored.push_back({sc, v, s});
            }
        }
        double mostHoles = 0;
        for (const Scored& c : scored) mostHoles = std::max(mostHoles, c.score.holeEdgeLength);
        r.holes = mostHoles * double(r.width + r.height) >= kMinHoleEdges;
        weighByHoles(scored, r.holes);
        // The best few again at a finer size, where the holes of cut-outs and thin casters lost
        // at thumbnail size decide between them; a stable order keeps the first among equals.
        std::stable_sort(scored.begin(), scored.end(),
                         [](const Scored& x, const Scored& y) { return x.score.score > y.score.score; });
        const std::size_t refined = std::min<std::size_t>(scored.size(), std::size_t(std::max(options.refine, 0)));
        scored.resize(std::max<std::size_t>(refined, 1));
        std::sort(scored.begin(), scored.end(),
                  [](const Scored& x, const Scored& y) { return x.view != y.view ? x.view < y.view : x.sun < y.sun; });
        r.fineWidth = kRefineScale * r.width;
        r.fineHeight = thumbnailHeight(scene.camera, r.fineWidth);
        r.refined = int(refined);
        if (refined > 0) {
            std::size_t thumbnailView = views.size();
            Thumbnail fine;
            for (Scored& c : scored) {
                if (c.view != thumbnailView) {
                    fine = primaryHits(tracer, views[c.view].camera, r.fineWidth, r.fineHeight);
                    thumbnailView = c.view;
                }
                const Vec3 forward = scene::cameraBasis(views[c.view].camera).forward;
                c.score =
                    score(fine, shadowClasses(tracer, fine, suns[c.sun].first, rayBias, scene.allOpaque(), seeThrough),
                          forward, suns[c.sun].first, nearWall, ground, casters);
            }
            weighByHoles(scored, r.holes);
        }
        std::size_t bestView = 0, bestSun = 0;
        ViewScore best;
        best.score = -1;
        for (const Scored& c : scored)
            if (c.score.score > best.score) {
                best = c.score;
                bestView = c.view;
                bestSun = c.sun;
            }
        r.best = best;
        r.camera = views[bestView].camera;
        r.sunDirection = suns[bestSun].first.direction;
        // A view framing the model alone cuts off the shadow it casts under a low sun (the box's,
        // 1.4 heights long at 35°): the chosen view moves back until that shadow fits too.
        bool widened = false;
        if (views[bestView].framed && suns[bestSun].first.type == scene::LightType::Directional) {
            const scene::Camera c = scene::framedWithShadow(r.camera, b, r.sunDirection, scene.bounds());
            widened = c.position != r.camera.position || c.lookAt != r.camera.lookAt;
            r.camera = c;
        }
        const std::string refinedText = refined > 0
                                            ? ", the best " + std::to_string(refined) + " again at " +
                                                  std::to_string(r.fineWidth) + "x" + std::to_string(r.fineHeight)
                                            : "";
        const std::string why =
            " (the best of " + std::to_string(r.views * r.suns) + " view x sun pairs at " + std::to_string(r.width) +
            "x" + std::to_string(r.height) + refinedText + ", score " + fmt(best.score, "%.2f") + ": " +
            fmt(100 * best.shadowedShare, "%.0f") + "% of the lit-facing surface in shadow, " +
            fmt(best.edgeLength, "%.2f") + " shadow edge per image side, the outlines of " + fmt(best.casters, "%.1f") +
            " caster(s), " +
            (r.holes ? fmt(best.holeEdgeLength, "%.2f") + " of it around holes (light through cut-outs), " : "") +
            fmt(100 * best.coverage, "%.0f") + "% of the image on the model)";
        r.viewText = (options.chooseView ? "searched, " + views[bestView].text : views[bestView].text) +
                     (r.interior ? "; the model encloses its space (" + std::to_string(r.enclosedPoints) + " of " +
                                       std::to_string(r.probePoints) + " probe points walled in)"
                                 : "") +
                     why + (widened ? ", then moved back to hold the model's whole shadow under that sun" : "");
        r.sunText = options.chooseSun ? "searched, " + suns[bestSun].second : suns[bestSun].second;
    });
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return r;
}

void chooseViewAndSun(scene::Scene& scene, int threads) {
    if (!scene.origin.chooseView && !scene.origin.chooseSun) return;
    ViewSearchOptions o;
    o.chooseView = scene.origin.chooseView;
    o.chooseSun = scene.origin.chooseSun;
    o.threads = threads;
    const ViewSearchResult r = searchViewAndSun(scene, o);
    const int width = scene.camera.width, height = scene.camera.height;
    if (o.chooseView) {
        scene.camera = r.camera;
        scene.camera.width = width;
        scene.camera.height = height;
        scene::recordChoice(scene, "view", r.viewText + ", in " + fmt(r.seconds, "%.2f") + " s");
    }
    if (o.chooseSun) {
        scene.lights.front().direction = r.sunDirection;
        scene::recordChoice(scene, "sun", r.sunText + " (with the view above)");
    }
    // Most of an interior is in shadow, lit by the ambient term alone: at the default 0.05 its
    // shape is lost in the dark. The shipped JSON interiors use 0.15 too.
    if (r.interior && o.chooseView && scene.origin.modelScene && scene.ambient < kInteriorAmbient) {
        scene.ambient = kInteriorAmbient;
        scene::recordChoice(scene, "ambient", fmt(kInteriorAmbient) + " (an interior seen from inside)");
    }
    scene.origin.chooseView = scene.origin.chooseSun = false;
}

}  // namespace shadowlab::raytrace

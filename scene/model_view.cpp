// scene/model_view.cpp: picking a file's camera, the ground under a model, the sun's direction.
#include "scene/model_view.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "scene/camera.h"
#include "scene/error.h"
#include "scene/loader.h"

namespace shadowlab::scene {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegrees = kPi / 180.0;
// framedWithShadow: the points it must show stay this factor inside the image's half-extents.
constexpr double kShadowFrameMargin = 1.1;
// The added ground's side (extent + 3 heights) holds the shadow of a sun this high or higher
// (a shadow 1/tan 35° = 1.43 heights long).
constexpr double kGroundSunElevation = 35.0;
// A lower sun given by the user grows the ground to hold its shadow, down to this elevation
// (5.7 heights); lower still, holding it all would leave the model a speck in the framed view.
constexpr double kGroundSunFloor = 10.0;

std::string describeCamera(const std::vector<FileCamera>& cameras, std::size_t i) {
    const FileCamera& c = cameras[i];
    return std::to_string(i) + (c.name.empty() ? " (unnamed)" : " '" + c.name + "'") + " in " + c.source;
}

std::string listCameras(const std::vector<FileCamera>& cameras) {
    if (cameras.empty()) return "the scene's files hold no camera";
    std::string list;
    for (std::size_t i = 0; i < cameras.size(); ++i) list += (i ? ", " : "") + describeCamera(cameras, i);
    return "cameras: " + list;
}

std::string fmt(double v, const char* f = "%.3g") {
    char buf[64];
    std::snprintf(buf, sizeof buf, f, v);
    return buf;
}

// Sine and cosine of an angle in degrees, exact at multiples of 90°: the angle is reduced to
// within 45° of a quarter turn first, so sin 180° is 0, not sin(π) = 1.2e-16. A sun at azimuth
// 180 must travel in the YZ plane: a residue there gives every face that is edge-on to the light
// (an axis-aligned model's sides) an N·L of ±1e-16, and so a sign, a shadow test and a class.
std::pair<double, double> sinCosDegrees(double degrees) {
    double r = std::fmod(degrees, 360.0);
    if (r < 0) r += 360.0;
    const double quarter = std::round(r / 90.0);
    const double x = (r - 90.0 * quarter) * kDegrees;  // |x| ≤ π/4
    const double s = std::sin(x), c = std::cos(x);
    switch (int(quarter) % 4) {
        case 0: return {s, c};
        case 1: return {c, -s};
        case 2: return {-s, -c};
        default: return {-c, s};
    }
}

}  // namespace

int findFileCamera(const std::vector<FileCamera>& cameras, const std::string& spec, std::string& why) {
    char* end = nullptr;
    const long index = std::strtol(spec.c_str(), &end, 10);
    if (!spec.empty() && end && *end == '\0') {
        if (index >= 0 && std::size_t(index) < cameras.size()) return int(index);
        why = "no camera " + spec + " (" + listCameras(cameras) + ")";
        return -1;
    }
    for (std::size_t i = 0; i < cameras.size(); ++i)
        if (cameras[i].name == spec) return int(i);
    why = "no camera named '" + spec + "' (" + listCameras(cameras) + ")";
    return -1;
}

Camera cameraFromGltf(const Vec3& position, const Vec3& forward, const Vec3& up, double yfovRadians, double znear,
                      double zfar, double aspect, const Bounds& bounds, const Camera& base) {
    const double radius = std::max(0.5 * bounds.diagonal(), 1e-9);
    Camera cam = base;
    cam.position = position;
    cam.lookAt = position + forward;
    cam.up = up;
    cam.fovYDegrees = std::clamp(yfovRadians / kDegrees, 1.0, 170.0);
    cam.near = znear > 0 ? znear : radius * 1e-3;
    cam.far = zfar > cam.near ? zfar : glm::length(position - bounds.center()) + 4.0 * radius;
    // Clamped before the conversion: a tiny aspect would overflow int.
    if (aspect > 0) cam.height = int(std::lround(std::clamp(cam.width / aspect, 1.0, double(kMaxResolution))));
    return cam;
}

Camera framedCamera(const Bounds& bounds, const Vec3& fromDirection, double fovYDegrees, const Camera& base) {
    const double radius = std::max(0.5 * bounds.diagonal(), 1e-9);
    Camera cam = base;
    cam.fovYDegrees = fovYDegrees;
    const double distance = 1.15 * radius / std::sin(0.5 * fovYDegrees * kDegrees);
    cam.lookAt = bounds.center();
    cam.position = bounds.center() + distance * glm::normalize(fromDirection);
    cam.up = {0, 1, 0};
    cam.near = std::max(distance - 2.0 * radius, distance * 1e-3);
    cam.far = distance + 2.0 * radius;
    return cam;
}

Camera framedWithShadow(const Camera& framed, const Bounds& bounds, const Vec3& lightDirection,
                        const Bounds& receivers) {
    // The shadow of the bounds' box on the plane of its base contains the model's shadow there.
    const Vec3 l = glm::normalize(lightDirection);
    if (bounds.empty() || !(l.y < -1e-9)) return framed;
    std::vector<Vec3> points, shadow;
    for (int k = 0; k < 8; ++k) {
        const Vec3 c((k & 1) ? bounds.max.x : bounds.min.x, (k & 2) ? bounds.max.y : bounds.min.y,
                     (k & 4) ? bounds.max.z : bounds.min.z);
        points.push_back(c);
        shadow.push_back(c + ((bounds.min.y - c.y) / l.y) * l);
    }
    const auto over = [&](const Vec3& p) {
        return p.x >= receivers.min.x && p.x <= receivers.max.x && p.z >= receivers.min.z && p.z <= receivers.max.z;
    };
    if (receivers.empty() || std::all_of(shadow.begin(), shadow.end(), over)) {
        points.insert(points.end(), shadow.begin(), shadow.end());
    } else {
        // Past the receivers: the shadow's rectangle on the base plane cut to theirs, which holds
        // every part of the shadow that lands on them.
        Bounds r;
        for (const Vec3& p : shadow) r.extend(p);
        r.min = glm::max(r.min, receivers.min);
        r.max = glm::min(r.max, receivers.max);
        if (r.min.x <= r.max.x && r.min.z <= r.max.z)
            for (const double x : {r.min.x, r.max.x})
                for (const double z : {r.min.z, r.max.z}) points.push_back(Vec3(x, bounds.min.y, z));
    }
    const CameraBasis cam = cameraBasis(framed);
    const double tanV = cam.tanHalfFovY / kShadowFrameMargin, tanH = tanV * cam.aspect;
    // The image holds p where its depth z = D − (p − c)·d (d toward the camera, D the camera's
    // distance from the target c) is at least |x|/tanH and |y|/tanV: D ≥ (p − c)·d + max(...).
    auto fits = [&](const Vec3& target, double distance) {
        for (const Vec3& p : points) {
            const Vec3 q = p - target;
            const double z = distance + glm::dot(q, cam.forward);
            if (std::abs(glm::dot(q, cam.right)) > tanH * z * (1 + 1e-9) ||
                std::abs(glm::dot(q, cam.up)) > tanV * z * (1 + 1e-9))
                return false;
        }
        return true;
    };
    const double framedDistance = glm::length(framed.lookAt - framed.position);
    if (fits(framed.lookAt, framedDistance)) return framed;
    Bounds all;
    for (const Vec3& p : points) all.extend(p);
    const Vec3 target = all.center();
    double distance = framedDistance, radius = 0.5 * bounds.diagonal();
    for (const Vec3& p : points) {
        const Vec3 q = p - target;
        distance = std::max(distance, -glm::dot(q, cam.forward) + std::max(std::abs(glm::dot(q, cam.right)) / tanH,
                                                                           std::abs(glm::dot(q, cam.up)) / tanV));
        radius = std::max(radius, glm::length(q));
    }
    Camera c = framed;
    c.lookAt = target;
    c.position = target - distance * cam.forward;
    c.near = std::max(distance - 2.0 * radius, distance * 1e-3);
    c.far = distance + 2.0 * radius;
    return c;
}

void recordChoice(Scene& scene, const std::string& key, const std::string& text) {
    for (auto& [k, v] : scene.origin.choices)
        if (k == key) {
            v = text;
            return;
        }
    scene.origin.choices.emplace_back(key, text);
}

void applyCameraOption(Scene& scene, const std::string& spec) {
    if (spec == "auto") {
        scene.origin.chooseView = true;
        recordChoice(scene, "view", "to be searched (--camera auto)");
        return;
    }
    std::string why;
    const int i = findFileCamera(scene.origin.cameras, spec, why);
    if (i < 0) throw InputError("--camera " + spec + ": " + why);
    const Camera& c = scene.origin.cameras[std::size_t(i)].camera;
    const int width = scene.camera.width, height = scene.camera.height;
    scene.camera = c;
    scene.camera.width = width;  // the image size stays the scene's (or --resolution's)
    scene.camera.height = height;
    scene.origin.chooseView = false;
    recordChoice(scene, "view", "file camera " + describeCamera(scene.origin.cameras, std::size_t(i)) + " (--camera)");
}

bool hasOwnGround(const Scene& scene) {
    const Bounds b = scene.origin.modelBounds.empty() ? scene.bounds() : scene.origin.modelBounds;
    if (b.empty()) return false;
    const Vec3 e = b.extent();
    const double footprint = e.x * e.z;
    if (!(footprint > 0)) return false;
    const double top = b.min.y + 0.05 * e.y;
    double area = 0;  // projected onto the ground plane
    for (const Object& o : scene.objects) {
        if (const Quad* q = std::get_if<Quad>(&o.shape)) {
            if (std::abs(q->normal.y) > 0.7 && q->center.y <= top)
                area += q->size.x * q->size.y * std::abs(q->normal.y);
        } else if (const Mesh* m = std::get_if<Mesh>(&o.shape)) {
            for (const MeshInstance& in : m->instances) {
                if (!in.geometry) continue;
                const TriangleMesh& g = *in.geometry;
                for (std::size_t t = 0; t + 2 < g.indices.size(); t += 3) {
                    const Vec3 p0 = transformPoint(in.transform, g.positions[g.indices[t]]);
                    const Vec3 p1 = transformPoint(in.transform, g.positions[g.indices[t + 1]]);
                    const Vec3 p2 = transformPoint(in.transform, g.positions[g.indices[t + 2]]);
                    if (std::max({p0.y, p1.y, p2.y}) > top) continue;
                    const Vec3 n = glm::cross(p1 - p0, p2 - p0);  // |n| = twice the area
                    const double len = glm::length(n);
                    if (len > 0 && n.y > 0.7 * len) area += 0.5 * n.y;
                }
            }
        }
    }
    return area >= 0.5 * footprint;
}

void addGround(Scene& scene) {
    const Bounds b = scene.origin.modelBounds.empty() ? scene.bounds() : scene.origin.modelBounds;
    const Vec3 e = b.extent();
    const double side = std::max(e.x, e.z) + 3.0 * e.y;
    Quad q;
    q.center = {b.center().x, b.min.y - 1e-4 * b.diagonal(), b.center().z};
    q.normal = {0, 1, 0};
    q.size = {side, side};
    quadAxes(q.normal, q.uAxis, q.vAxis);
    scene.materials.push_back({"ground", {0.75, 0.75, 0.75}, 1.0});
    scene.objects.push_back({"ground", q, int(scene.materials.size()) - 1});
    scene.origin.addedGround = int(scene.objects.size()) - 1;
}

void fitGroundToSun(Scene& scene) {
    if (scene.origin.addedGround < 0 || scene.origin.chooseSun) return;
    const auto sun = std::find_if(scene.lights.begin(), scene.lights.end(),
                                  [](const Light& l) { return l.type == LightType::Directional; });
    if (sun == scene.lights.end()) return;
    const double elevation = sunAngles(sun->direction).y;
    if (!(elevation > 0.0) || elevation >= kGroundSunElevation) return;
    Quad& q = std::get<Quad>(scene.objects[std::size_t(scene.origin.addedGround)].shape);
    const Bounds b = scene.origin.modelBounds;
    const Vec3 e = b.extent();
    const double reach = e.y / std::tan(std::max(elevation, kGroundSunFloor) * kDegrees);
    const double side = std::max(e.x, e.z) + 2.0 * reach;
    if (side > q.size.x) {
        const double before = q.size.x;
        q.size = {side, side};
        fitNearFarToBounds(scene);
        for (auto& [key, text] : scene.origin.choices)
            if (key == "ground")
                text = "a " + fmt(side) + " x " + fmt(side) + text.substr(std::min(text.find(" quad"), text.size())) +
                       ", grown from " + fmt(before) + " to hold the shadow of a sun " + fmt(elevation) + " degrees up";
    }
    if (elevation < kGroundSunFloor)
        scene.origin.notes.push_back(
            "the sun " + fmt(elevation) + " degrees up casts the model's shadow " +
            fmt(e.y / std::tan(elevation * kDegrees)) + " from its base (" +
            fmt(1.0 / std::tan(elevation * kDegrees), "%.3g") +
            " model heights); the added ground holds the shadow of a sun " + fmt(kGroundSunFloor) +
            " degrees or more up (side " + fmt(q.size.x) +
            "), so past it the shadow runs off the ground's edge: give the scene a ground of its own to see all of it");
}

void fitNearFarToBounds(Scene& scene) {
    const Bounds b = scene.bounds();
    if (!scene.origin.farFromBounds || b.empty()) return;
    double farthest = 0.0;
    for (int k = 0; k < 8; ++k) {
        const Vec3 corner((k & 1) ? b.max.x : b.min.x, (k & 2) ? b.max.y : b.min.y, (k & 4) ? b.max.z : b.min.z);
        farthest = std::max(farthest, glm::length(corner - scene.camera.position));
    }
    // A hundredth beyond, so the depth of the farthest point does not round past the plane.
    if (scene.origin.nearFromBounds) scene.camera.near = std::min(kDefaultNear, kNearPerFar * 1.01 * farthest);
    scene.camera.far = std::max(1.01 * farthest, 2.0 * scene.camera.near);
}

void applyGround(Scene& scene, std::optional<bool> option) {
    if (scene.origin.modelBounds.empty()) scene.origin.modelBounds = scene.bounds();
    bool on = false;
    std::string why;
    if (option) {
        on = *option;
        why = on ? "--ground" : "--no-ground";
    } else if (scene.origin.ground) {
        on = *scene.origin.ground;
        why = std::string("the scene's \"ground\": ") + (on ? "true" : "false");
    } else if (scene.origin.modelScene) {
        on = !hasOwnGround(scene);
        why = on ? "default for a model without a floor of its own: a model with nothing under it casts its "
                   "shadow into the void"
                 : "none: the model has a floor of its own (upward faces over half its footprint at its base)";
    } else {
        return;  // a JSON scene without the key: as its author wrote it
    }
    if (on) {
        addGround(scene);
        fitNearFarToBounds(scene);
        const Quad& q = std::get<Quad>(scene.objects.back().shape);
        why =
            "a " + fmt(q.size.x) + " x " + fmt(q.size.y) + " quad at y = " + fmt(q.center.y, "%.4g") + " (" + why + ")";
    } else if (option || scene.origin.ground) {
        why = "none (" + why + ")";
    }
    recordChoice(scene, "ground", why);
}

Vec3 sunDirection(double azimuthDegrees, double elevationDegrees) {
    const auto [sinA, cosA] = sinCosDegrees(azimuthDegrees);
    const auto [sinE, cosE] = sinCosDegrees(elevationDegrees);
    return -Vec3(cosE * sinA, sinE, cosE * cosA);
}

glm::dvec2 sunAngles(const Vec3& direction) {
    const Vec3 toSun = -glm::normalize(direction);
    double az = std::atan2(toSun.x, toSun.z) / kDegrees;
    if (az < 0) az += 360.0;
    const double el = std::asin(std::clamp(toSun.y, -1.0, 1.0)) / kDegrees;
    return {az, el};
}

void applySunOption(Scene& scene, const std::string& text) {
    double az = 0, el = 0;
    char comma = 0, extra = 0;
    if (std::sscanf(text.c_str(), "%lf%c%lf%c", &az, &comma, &el, &extra) != 3 || comma != ',' || !std::isfinite(az) ||
        !std::isfinite(el))
        throw InputError("--sun: expected AZIMUTH,ELEVATION in degrees (e.g. 135,40), got '" + text + "'");
    if (el < -90.0 || el > 90.0)
        throw InputError("--sun " + text + ": the elevation must be in -90..90 degrees, got " + fmt(el));
    for (Light& l : scene.lights) {
        if (l.type != LightType::Directional) continue;
        l.direction = sunDirection(az, el);
        scene.origin.chooseSun = false;
        recordChoice(scene, "sun", "azimuth " + fmt(az) + ", elevation " + fmt(el) + " degrees (--sun)");
        // Allowed (light from below is a case to study), but rarely meant: say what it gives.
        if (el < 0.0)
            scene.origin.notes.push_back("--sun " + text + ": the elevation " + fmt(el) +
                                         " puts the sun below the horizon, so faces turned up get no light and "
                                         "a ground shows no shadow; a sun above would be elevation " +
                                         fmt(-el));
        return;
    }
    throw InputError("--sun " + text + ": the scene has no directional light to point");
}

std::string explainOrigin(const Scene& scene) {
    std::string out;
    if (!scene.origin.cameras.empty()) {
        out += "file cameras (--camera N|NAME):";
        for (std::size_t i = 0; i < scene.origin.cameras.size(); ++i)
            out += "\n  " + describeCamera(scene.origin.cameras, i);
        out += "\n";
    } else if (scene.origin.modelScene) {
        out += "file cameras: none\n";
    }
    for (const auto& [key, text] : scene.origin.choices) out += key + ": " + text + "\n";
    return out;
}

}  // namespace shadowlab::scene

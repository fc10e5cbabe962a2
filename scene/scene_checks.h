// scene/scene_checks.h: value checks every scene source shares (JSON scenes, glTF files), so a
// light or a coordinate read from glTF gets exactly the checks a JSON one gets.
#pragma once

#include <string>

#include "scene/error.h"
#include "scene/scene.h"

namespace shadowlab::scene {

// The largest coordinate a scene may reach. The backends work in float: squared distances of
// coordinates up to 1e15 (1e30, plus sums) stay far below float's 3.4e38, where larger ones
// overflow to infinity (a sphere at 1e300 turned every default bias infinite).
inline constexpr double kMaxSceneCoordinate = 1e15;

// The brightest light, intensity times its brightest colour component. Sunlight in lux, the
// largest figure glTF files use, is about 1e5; a product above 1e12 overflows nothing in double
// but leaves float shading, which divides by squared distances, too little headroom.
inline constexpr double kMaxLightPower = 1e12;

// What is wrong with a value and the key (relative to the light's JSON path) at fault.
struct ValueProblem {
    std::string key;
    std::string what;
    explicit operator bool() const { return !what.empty(); }
};

// Every field of a light: finite, colour >= 0, intensity >= 0, their product at most
// kMaxLightPower, unit direction, position within kMaxSceneCoordinate, radius >= 0, cone in
// (0, 90) degrees. Empty when the light is good.
ValueProblem lightProblem(const Light& light);

// Throws SceneError when an object, the camera or a light reaches beyond kMaxSceneCoordinate:
// at `objects[i]`, `camera.position`... when `jsonPaths`, else at the file (a glTF scene).
void checkSceneExtent(const Scene& scene, bool jsonPaths);

}  // namespace shadowlab::scene

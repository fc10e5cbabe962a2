// scene/camera_animation.h: samples a glTF camera animation (translation and rotation channels,
// LINEAR, STEP or CUBICSPLINE, glTF 2.0 3.11) at a time, as the camera the scene would have there.
#pragma once

#include <string>

#include "scene/scene.h"

namespace shadowlab::scene {

// The curve's value at `time` (seconds), clamped to its first and last key. A rotation is
// slerped (LINEAR) and normalized (CUBICSPLINE), as glTF requires.
glm::dvec4 sampleCurve(const AnimationCurve& curve, double time, bool rotation);

// The animated node's world transform at `time`: parent · T · R · S, each from its curve or the
// node's own value.
glm::dmat4 animatedNodeMatrix(const CameraAnimation& animation, double time);

// `scene`'s camera moved to where `animation` puts its camera at `time`: position, look-at one
// unit down the node's −Z, up its +Y (glTF cameras look down local −Z); the field of view, image
// size and near/far of the file camera it animates (SceneOrigin::cameras).
Camera animatedCamera(const Scene& scene, const CameraAnimation& animation, double time);

// The animation named `which` (its name, or its index among the file's animations as digits);
// empty: the first. Throws InputError naming what the scene has.
const CameraAnimation& findCameraAnimation(const Scene& scene, const std::string& which);

}  // namespace shadowlab::scene

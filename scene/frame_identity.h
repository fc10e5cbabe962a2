// scene/frame_identity.h: what a Frame shows, recorded in it so that compare can refuse two
// frames of different scenes, cameras or sizes: a hash of the scene as loaded, the camera as
// OpenEXR's standard worldToCamera and worldToNDC matrices, and each light's parameters.
#pragma once

#include <string>

#include <glm/mat4x4.hpp>

#include "scene/frame.h"
#include "scene/scene.h"

namespace shadowlab::scene {

// FNV-1a (64 bits) over every number of the loaded scene that decides what is rendered:
// background, ambient, materials, lights, every object's shape, placement and material, and
// every vertex, normal and index of every mesh its files hold after resolving (so a glTF's
// external buffers count). Not the camera (recorded on its own), names, the description, the
// "shadow" and "budgets" blocks or the file's formatting. 16 lowercase hex digits.
std::string sceneHash(const Scene& scene);

// OpenEXR's camera space (ImfStandardAttributes.h, as RenderMan's): left-handed, origin at the
// eye, +x right and +y up in the image, +z the viewing direction (points in front have z > 0).
// Column-vector form (p_camera = M·p_world); see AttributeValue for how it is written.
glm::dmat4 worldToCamera(const Camera& camera);
// OpenEXR's NDC: (0, 0) the top-left and (1, 1) the bottom-right corner of the display window,
// y down; x and y after the divide by w, z discarded (ours: 0 at near, 1 at far). Pixel (x, y)
// has its centre at ((x + 0.5) / W, (y + 0.5) / H), where both backends sample.
glm::dmat4 worldToNDC(const Camera& camera);

// Sets attributes "scene_hash" and "light.<i>.type", and typedAttributes "worldToCamera",
// "worldToNDC", "light_count" and per light "light.<i>.direction", ".position", ".color",
// ".intensity", ".radius", ".cone_angle" (degrees).
void recordIdentity(Frame& frame, const Scene& scene);

// Empty when the two frames show the same scene, camera and image size as far as both record
// them (a frame without the attributes, e.g. another engine's mask, is not held to them); else
// one sentence saying what differs, e.g. "different cameras (worldToNDC differs ...)".
std::string describeIdentityDifference(const Frame& method, const Frame& reference);

}  // namespace shadowlab::scene

// scene/model_view.h: the choices a scene file leaves open: which of its glTF files' cameras is
// the view (--camera, a mesh object's "camera" key), a ground under a model that has none of its
// own (--ground, the "ground" key) and the sun's direction (--sun AZIMUTH,ELEVATION). The search
// for a view and a sun that show shadows needs the ray tracer: raytrace/view_search.h.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace shadowlab::scene {

// The camera `spec` names in `cameras`: a 0-based index, else a glTF camera name, else a node
// name (exact). -1 when none matches, with `why` saying what there is.
int findFileCamera(const std::vector<FileCamera>& cameras, const std::string& spec, std::string& why);

// A glTF camera as a scene camera: placed by `transform` (object to world), its field of view
// and near/far (or near/far from `bounds` where the file has none), the image size of `base`
// with the height from the file's aspect ratio when it has one.
Camera cameraFromGltf(const Vec3& position, const Vec3& forward, const Vec3& up, double yfovRadians, double znear,
                      double zfar, double aspect, const Bounds& bounds, const Camera& base);

// `bounds`' bounding sphere filling the vertical field of view, seen from `fromDirection` (any
// length) toward its center; near and far just around the sphere.
Camera framedCamera(const Bounds& bounds, const Vec3& fromDirection, double fovYDegrees, const Camera& base);

// `framed` (a framedCamera of `bounds`) moved back along its own view direction, and its target
// moved to the middle of what it must show, so that the shadow `bounds` casts under a directional
// light travelling along `lightDirection` (its corners projected along the light onto the plane
// of its base, where the added ground lies) fits the image too, each point at least 1/1.1 of the
// half-width and half-height from the center's edge. Unchanged when that shadow already fits, or
// the light does not travel downward; never closer than `framed`. With `receivers` (the scene's
// bounds, ground included), only the part of the shadow over them counts: under a low sun the
// shadow runs far past the ground, where nothing receives it, and framing it all would leave the
// model a speck.
Camera framedWithShadow(const Camera& framed, const Bounds& bounds, const Vec3& lightDirection,
                        const Bounds& receivers = {});

// --camera N|NAME|auto: N or NAME puts that file camera in place of the view; auto asks for a
// view search even where the file has cameras. Throws InputError listing the cameras there are.
void applyCameraOption(Scene& scene, const std::string& spec);

// True when the objects' lowest 5% of height holds upward-facing mesh or quad area covering at
// least half the footprint (bounds x × z): a floor of its own, which a ground would only hide.
bool hasOwnGround(const Scene& scene);

// A square quad just under origin.modelBounds (1e-4 of the diagonal below, so it never cuts the
// model's bottom faces), its side the larger horizontal extent plus 3 × the height (a shadow
// cast under a sun 35° or more above the horizon stays on it), material "ground".
void addGround(Scene& scene);

// A JSON camera without "far" (SceneOrigin::farFromBounds) sees to the farthest corner of the
// scene's bounds, so a large ground is never cut off by a guessed constant; without "near" either
// (nearFromBounds), its near plane is kNearPerFar of that far one when nearer than the default
// 0.1, so a scene a few centimetres across is not clipped away. No-op otherwise.
void fitNearFarToBounds(Scene& scene);

// A ground addGround added, grown to hold the model's shadow under the scene's sun where it is
// lower than the 35 degrees the ground's default side holds (down to 10 degrees: 5.7 model
// heights of shadow; below that a note says the shadow runs off the ground's edge). No-op without
// an added ground, without a directional light, or while the sun is still to be searched.
void fitGroundToSun(Scene& scene);

// Whether a ground is added and why: `option` (--ground / --no-ground), else the file's "ground"
// key, else on for a glTF given as the scene that has no ground of its own (hasOwnGround), off
// for a JSON scene (its author composed it). Records the choice in scene.origin.choices.
void applyGround(Scene& scene, std::optional<bool> option);

// The way a sun's light travels for a sun at `azimuthDegrees` (in the ground plane from +Z toward
// +X) and `elevationDegrees` above the horizon: −(cos e · sin a, sin e, cos e · cos a), exact at
// multiples of 90° (a sun at azimuth 180 travels in the YZ plane, edge-on to faces along X).
Vec3 sunDirection(double azimuthDegrees, double elevationDegrees);
// The inverse: a sun's azimuth (0..360) and elevation of a direction light travels.
glm::dvec2 sunAngles(const Vec3& direction);

// --sun AZIMUTH,ELEVATION (degrees): sets the first directional light's direction; elevation in
// -90..90. Throws InputError for bad text or a scene without a directional light.
void applySunOption(Scene& scene, const std::string& text);

// Sets (or replaces) origin.choices[key].
void recordChoice(Scene& scene, const std::string& key, const std::string& text);

// "file cameras: 0 'Main' (Box.gltf), 1 ..." and every choice, one per line, for --explain.
std::string explainOrigin(const Scene& scene);

}  // namespace shadowlab::scene

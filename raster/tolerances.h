// raster/tolerances.h: the raster backend's few non-derived constants, each with its reason.
#pragma once

#include <cstddef>
#include <cstdint>

namespace shadowlab::raster {

// Sphere tessellation: the chord of each UV-sphere segment may deviate from the true sphere by
// at most this fraction of a pixel at the sphere's nearest distance to the camera, so that the
// silhouette (and the shadow the sphere casts) differs from the analytic sphere by well under
// a pixel, which is what "agrees except on silhouettes" allows.
inline constexpr double kSphereChordErrorPixels = 0.25;
// Bounds on the number of segments around a sphere (rings = segments / 2). 16 keeps even a
// far-away sphere round in the shadow map; 256 caps the cost of a sphere filling the view
// (256 x 128 segments is 65k triangles per sphere).
inline constexpr int kMinSphereSegments = 16;
inline constexpr int kMaxSphereSegments = 256;

// The light frustum encloses the scene's bounding sphere enlarged by this factor, so that the
// vertices touching the sphere (a tessellated sphere's poles, a quad's corners) stay strictly
// inside the near and far planes and the map's outer texels after float rounding.
inline constexpr double kLightFrustumMargin = 1.01;

// A spot light's map covers its cone plus 2% of the half-angle, so the cone's rim is not on
// the map's outermost texels (where filter taps would fall outside). Half-angles are capped at
// 85°: a perspective map wider than that spends almost all texels near its edges.
inline constexpr double kSpotFovMargin = 1.02;
inline constexpr double kMaxSpotHalfAngleDegrees = 85.0;
// A spot map's near plane is never closer than far/1000: with standard D32 depth the depth
// resolution at distance d is about 6e-8·d²/near, so this keeps it near 6e-5·far at the far
// plane, well below a texel at any sensible map size.
inline constexpr double kSpotMinNearOverFar = 1e-3;

// A point light's cube map is six perspective maps, one per axis direction. Each face's field of
// view is widened past 90° so that it reaches this many texels beyond its face's edge: a filter
// tap or normal offset near an edge then still reads real depths of the same face instead of
// clamped edge texels, which is what makes seams free of false shadows. 12 = the widest kernel's
// half-width (kMaxPcfSize / 2 = 7.5 texels) plus 4 texels of normal offset.
inline constexpr double kPointFaceMarginTexels = 12.0;

// The transmittance map's second pass counts a semi-transparent fragment as behind the nearest
// layer when its depth exceeds that layer's depth D1 by more than this (map depth units, 0..1).
// The nearest layer's own fragment is drawn by the same vertex shader, matrix and triangles in
// both passes, so it has D1 exactly on lavapipe; this only absorbs rounding that an implementation
// may add between two pipelines (without `invariant`, which glslang puts on a gl_PerVertex member
// and the validation layer then flags): 4 ulps of a float depth in [0.5, 1) (ulp 6e-8),
// more below 0.5. In world units it is 4 ulps of the depth resolution: 2.5e-7 of the depth range
// for an orthographic map (5e-6 units for a 20-unit scene), and for a perspective map
// 2.5e-7·d²/near at distance d, at most 2.5e-4·far with kSpotMinNearOverFar. Layers closer than
// that are one layer, which changes only the factor a receiver between them gets.
inline constexpr float kTransmittanceLayerSeparation = 2.5e-7f;
// The transmittance maps are drawn (and cleared) only within a window of each layer around the
// semi-transparent casters (the projection of their bounding boxes), and lit.frag takes a texel
// outside the window as "nothing semi-transparent". The window keeps this many texels of margin
// around the casters' projected extent, so that a texel on its edge holds "nothing" either way:
// one for the rasterizer's pixel centers and the float rounding of the corners' projection (a few
// 1e-7 of the map), one for lit.frag's texel index (floor(uv · size)) against the sampler's.
inline constexpr std::uint32_t kTransmittanceWindowMarginTexels = 2;
// The window comes from the casters' triangles projected into each layer (a sphere's box projects to
// up to about three times the sphere's area in a spot's map), for casters of up to this many
// triangles: projecting them costs well under a millisecond a frame. Larger casters use their box.
inline constexpr std::size_t kTransmittanceWindowTriangles = 1 << 16;

// The slope bias grows with tan(theta), which is infinite at grazing light; clamping it at
// 10 (theta ~ 84°) keeps the bias finite where a receiver is nearly edge-on to the light and
// its N·L shading is close to zero anyway (a common clamp: Microsoft's "Common Techniques to
// Improve Shadow Depth Maps" and most engines use a similar bound). Past it lit.frag applies the
// rest of the slope bias as a lift along the normal, which gives the receiver's own plane the same
// margin without carrying the compare point along the light (docs/raster.md "Grazing light").
inline constexpr double kMaxSlopeTan = 10.0;
// The lit pass draws a triangle with the pipeline without that lift when every vertex normal has
// |N·L| ≥ cos θ at the cap plus this margin (raster/lift_free.h): the interpolated, normalized normal
// then has N·L past the cap by the margin, far more than the float error of lavapipe's
// interpolation and normalization (a few ulp of the interpolation plane's values), so no fragment of
// it takes the lift in the pipeline with it either. 0.05: light up to about 81° from the normal.
inline constexpr double kLiftFreeMargin = 0.05;
// A run of lift-free triangles covering fewer pixels than this (their areas on the image, unclipped)
// stays with the lift: each run is a draw and a pipeline switch of its own.
inline constexpr double kLiftFreeMinPixels = 1024.0;

// The lit pass leaves out runs of this many consecutive triangles of an object (raster/view_cull.h)
// whose box lies outside the camera's clip volume. Smaller runs fit the visible part more tightly
// but each gap between visible runs is a draw more (about 6 µs of llvmpipe's CPU each).
inline constexpr std::uint32_t kViewCullClusterTriangles = 256;
// A box is outside a plane of the clip volume only by this fraction of the magnitudes summed in the
// plane's product (|m_j|·|p_j|): the vertex shader's float product errs by a few 1e-7 of that sum.
inline constexpr double kViewCullMargin = 1e-5;

// Largest pcf kernel (taps per side; the Poisson diameter in texels): 15x15 = 225 taps per
// pixel and light is already slow on lavapipe, and wider penumbrae want a different filter.
inline constexpr int kMaxPcfSize = 15;

// The light-frustum view draws an edge point as hidden when it lies farther from the camera than
// the pixel's visible surface by more than this fraction of the surface's view depth: the Frame's
// depth is sampled at the pixel's center while the line point is anywhere in the pixel, so an edge
// lying on a surface must not flicker between solid and dashed. Half a pixel's footprint at 720
// rows and a 40° field of view is 5e-4·z; on a surface turned θ away from facing the camera the
// depth changes by that times tan θ, which stays below 2e-3·z up to θ ≈ 75°.
inline constexpr double kFrustumEdgeDepthTolerance = 2e-3;

}  // namespace shadowlab::raster

// bench/terrain_scene.cpp: the benches' generated terrain (terrain_scene.h).
#include "terrain_scene.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>

#include "scene/mesh_loader.h"

namespace shadowlab::bench {

scene::Scene terrainScene(int cells) {
    auto mesh = std::make_shared<scene::TriangleMesh>();
    const int n = cells + 1;
    auto height = [](double x, double z) {
        return 3.0 * std::sin(0.11 * x) * std::cos(0.13 * z) + 1.5 * std::sin(0.37 * x + 0.5 * z) +
               4.0 * std::abs(std::sin(0.05 * (x - 2 * z)));
    };
    mesh->positions.reserve(std::size_t(n) * n);
    mesh->indices.reserve(std::size_t(6) * cells * cells);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const double x = -50 + 100.0 * i / cells, z = -50 + 100.0 * j / cells;
            mesh->positions.emplace_back(x, height(x, z), z);
        }
    for (int j = 0; j < cells; ++j)
        for (int i = 0; i < cells; ++i) {
            const std::uint32_t a = std::uint32_t(j * n + i), b = a + 1, c = a + std::uint32_t(n), d = c + 1;
            for (std::uint32_t v : {a, c, b, b, c, d}) mesh->indices.push_back(v);
        }
    // Area-weighted vertex normals, as an OBJ without normals gets on load (without them both
    // backends would shade each triangle flat).
    scene::finalizeMesh(*mesh);
    scene::Scene s;
    s.file = "generated-terrain";
    s.camera.position = {-45, 14, -45};
    s.camera.lookAt = {10, 0, 10};
    s.camera.fovYDegrees = 60;
    scene::Light sun;
    sun.direction = glm::normalize(scene::Vec3(0.6, -0.25, 0.3));  // about 14° above the horizon
    s.lights.push_back(sun);
    s.materials.push_back(scene::Material{"matte"});
    scene::Object o;
    o.name = "terrain";
    o.shape = scene::Mesh::single("generated-terrain", mesh);
    s.objects.push_back(o);
    return s;
}

int terrainCellsFor(long long triangles) { return std::max(1, int(std::lround(std::sqrt(double(triangles) / 2.0)))); }

}  // namespace shadowlab::bench

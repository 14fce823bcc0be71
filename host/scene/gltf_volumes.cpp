// KHR_materials_volume: "the mesh is closed" (its specification's requirement for thickness),
// checked on the scene's triangles, edge by edge.
#include "scene/gltf_volumes.h"

#include <array>
#include <map>
#include <string>

namespace mcrt::gltf {

void warn_open_volumes(const Scene& scene, Diagnostics& diag) {
    using Point = std::array<float, 3>;
    for (size_t m = 0; m < scene.materials.size(); ++m) {
        const Material& material = scene.materials[m];
        if (!material.volume || material.transmission == 0.0f) continue;
        // Each undirected edge, its end points ordered, with how many triangles have it.
        std::map<std::pair<Point, Point>, uint32_t> edges;
        size_t triangles = 0;
        for (size_t t = 0; t < scene.triangle_count(); ++t) {
            if (scene.triangle_material[t] != m) continue;
            ++triangles;
            for (int k = 0; k < 3; ++k) {
                const glm::vec3 a = scene.positions[3 * t + size_t(k)];
                const glm::vec3 b = scene.positions[3 * t + size_t((k + 1) % 3)];
                Point pa{a.x, a.y, a.z}, pb{b.x, b.y, b.z};
                if (pb < pa) std::swap(pa, pb);
                ++edges[{pa, pb}];
            }
        }
        size_t open = 0;
        for (const auto& [edge, count] : edges) open += count % 2;
        if (open > 0) {
            diag.warn_once("open-volume-" + std::to_string(m),
                           "material \"" + material.name +
                               "\": KHR_materials_volume on a surface "
                               "that is not closed (" +
                               std::to_string(open) + " of its " + std::to_string(edges.size()) +
                               " edges bound an odd number of its " + std::to_string(triangles) +
                               " triangles): a ray may enter and not leave it; light through it "
                               "is attenuated over the rest of its way");
        }
    }
}

}  // namespace mcrt::gltf

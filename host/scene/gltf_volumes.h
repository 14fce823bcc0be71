// KHR_materials_volume's precondition: a volume's surface is closed, so that a ray that enters
// it leaves it again. Checked once the scene is built; an open one is warned about.
#pragma once

#include "scene/gltf_diagnostics.h"
#include "scene/scene.h"

namespace mcrt::gltf {

// One warning per material that bounds a volume (Material::volume) on triangles that do not
// close: an edge (by its two end points' positions) that an odd number of its triangles share.
// Rendering goes on: a ray that enters such a surface and escapes through its hole is attenuated
// over the rest of its way (all of it, to black, where the volume absorbs), never NaN.
void warn_open_volumes(const Scene& scene, Diagnostics& diag);

}  // namespace mcrt::gltf

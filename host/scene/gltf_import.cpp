// glTF 2.0 import: the default scene's triangles, metallic-roughness materials with their
// textures and perspective cameras, each part read by its own file (gltf_parse, gltf_nodes,
// gltf_geometry, gltf_materials, gltf_textures, gltf_images, gltf_cameras); this one walks the
// scene and hands each node's content to them.
//
// tinygltf parses the file; it accepts out-of-range indices, node cycles and accessors that
// overrun their data, so every part validates what it reads before it uses it. Quoted section
// names refer to the glTF 2.0 specification (Khronos, 2021).
#include "scene/gltf_import.h"

#include "scene/gltf_cameras.h"
#include "scene/gltf_diagnostics.h"
#include "scene/gltf_geometry.h"
#include "scene/gltf_images.h"
#include "scene/gltf_lights.h"
#include "scene/gltf_materials.h"
#include "scene/gltf_nodes.h"
#include "scene/gltf_parse.h"
#include "scene/gltf_volumes.h"

namespace mcrt {

namespace {

// Skins are ignored wherever a file holds them (the model or a node): one warning.
void warn_skins(gltf::Diagnostics& diag) {
    diag.warn_once("skins", "skins are not supported; meshes keep their bind pose");
}

void warn_unsupported_model_parts(const tinygltf::Model& model, gltf::Diagnostics& diag) {
    if (!model.animations.empty()) {
        diag.warn_once("animations", "animations are not supported; the rest pose is used");
    }
    if (!model.skins.empty()) warn_skins(diag);
}

// The default scene of `model`, which was read from `path` (named in every message).
Scene import_default_scene(const tinygltf::Model& model, const std::string& path,
                           const WarningSink& warn) {
    gltf::Diagnostics diag(path, warn);
    Scene scene;
    scene.path = path;
    gltf::check_asset(model, diag);
    warn_unsupported_model_parts(model, diag);
    const gltf::RootNodes roots = gltf::root_nodes(model, diag);
    gltf::check_expansion(model, roots, diag);

    gltf::TextureTable textures(model, diag);
    gltf::MaterialTable materials(model, diag, textures, scene.materials);
    gltf::GeometryImporter geometry(model, diag, materials, scene);
    gltf::traverse(model, roots, diag, [&](int node_index, const glm::dmat4& world) {
        const tinygltf::Node& node = model.nodes[static_cast<size_t>(node_index)];
        const std::string element = gltf::element_name("node", static_cast<size_t>(node_index));
        if (node.skin != -1) warn_skins(diag);
        if (!node.weights.empty()) gltf::warn_morph_targets(diag);
        const auto light = node.extensions.find("KHR_lights_punctual");
        if (light != node.extensions.end()) {
            scene.punctual_lights.push_back(
                gltf::read_punctual_light(model, light->second, world, node_index, diag));
        }
        if (node.mesh != -1) {
            const tinygltf::Mesh& mesh =
                gltf::checked_at(model.meshes, node.mesh, "mesh", element, diag);
            for (size_t p = 0; p < mesh.primitives.size(); ++p) {
                const std::string primitive_element =
                    gltf::element_name("mesh", static_cast<size_t>(node.mesh)) + " primitive " +
                    std::to_string(p);
                geometry.add_primitive(mesh.primitives[p], primitive_element, world, element);
            }
        }
        if (node.camera != -1) {
            if (auto camera = gltf::read_camera(model, node.camera, world, node_index, diag)) {
                camera->gltf_index = node.camera;
                scene.cameras.push_back(*camera);
            }
        }
    });
    geometry.finish();
    gltf::warn_open_volumes(scene, diag);
    for (const tinygltf::Camera& camera : model.cameras)
        scene.gltf_camera_types.push_back(camera.type);
    // The images the used materials' texture slots name, once the walk has found them all.
    scene.images = gltf::decode_images(model, textures.image_sources(), diag);
    return scene;
}

}  // namespace

Scene load_gltf(const std::string& path, const WarningSink& warn,
                std::vector<std::string>* files_read, FileBundle* record) {
    return import_default_scene(gltf::read_gltf_file(path, files_read, record), path, warn);
}

Scene load_gltf_from_bundle(const std::string& path, const FileBundle& files,
                            const WarningSink& warn) {
    return import_default_scene(gltf::read_gltf_bundle(path, files), path, warn);
}

Scene load_gltf_from_memory(const std::string& name, const std::vector<unsigned char>& bytes,
                            const WarningSink& warn) {
    return import_default_scene(gltf::read_gltf_memory(name, bytes), name, warn);
}

}  // namespace mcrt

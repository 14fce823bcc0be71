// The node hierarchy ("Nodes and Hierarchy", "Transformations"): the default scene's roots, the
// bounded expansion of shared subtrees, cycles, and each node instance's world transform.
#include "scene/gltf_nodes.h"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "scene/gltf_limits.h"

namespace mcrt::gltf {

namespace {

// "Transformations": a column-major `matrix`, or T·R·S with the rotation a unit quaternion
// [x, y, z, w].
glm::dmat4 local_transform(const tinygltf::Model& model, int node_index, Diagnostics& diag) {
    const tinygltf::Node& node = model.nodes[static_cast<size_t>(node_index)];
    const std::string element = element_name("node", static_cast<size_t>(node_index));
    auto check = [&](const std::vector<double>& values, size_t size, const char* name) {
        if (!values.empty() && values.size() != size) {
            diag.fail(element,
                      std::string(name) + " must have " + std::to_string(size) + " numbers");
        }
        if (!all_finite(values)) diag.fail(element, std::string(name) + " is not finite");
    };
    check(node.matrix, 16, "matrix");
    check(node.translation, 3, "translation");
    check(node.rotation, 4, "rotation");
    check(node.scale, 3, "scale");

    glm::dmat4 transform(1.0);
    if (!node.matrix.empty()) {
        transform = glm::make_mat4(node.matrix.data());
        // "Transformations": a matrix must decompose into T·R·S, so its last row is 0 0 0 1.
        if (transform[0][3] != 0.0 || transform[1][3] != 0.0 || transform[2][3] != 0.0 ||
            transform[3][3] != 1.0) {
            diag.fail(element, "matrix is projective (its last row is not 0 0 0 1)");
        }
    } else {
        if (!node.translation.empty())
            transform = glm::translate(transform, glm::make_vec3(node.translation.data()));
        if (!node.rotation.empty()) {
            const auto& r = node.rotation;
            const glm::dquat q(r[3], r[0], r[1], r[2]);  // glm takes w first
            const double length = glm::length(q);
            if (!(length > 0.0)) diag.fail(element, "rotation is a zero quaternion");
            transform *= glm::mat4_cast(q / length);
        }
        if (!node.scale.empty())
            transform = glm::scale(transform, glm::make_vec3(node.scale.data()));
    }
    if (glm::determinant(glm::dmat3(transform)) == 0.0) {
        diag.warn_once("singular", element +
                                       ": transform is singular (zero scale): its "
                                       "geometry collapses and is degenerate");
    }
    return transform;
}

}  // namespace

RootNodes root_nodes(const tinygltf::Model& model, const Diagnostics& diag) {
    if (model.defaultScene != -1 || !model.scenes.empty()) {
        const int index = model.defaultScene == -1 ? 0 : model.defaultScene;
        const tinygltf::Scene& scene =
            checked_at(model.scenes, index, "scene", "scene property", diag);
        return RootNodes{scene.nodes, element_name("scene", static_cast<size_t>(index))};
    }
    if (model.nodes.empty()) diag.fail("no scenes and no nodes: nothing to render");
    std::vector<char> is_child(model.nodes.size(), 0);
    for (size_t n = 0; n < model.nodes.size(); ++n) {
        for (int child : model.nodes[n].children) {
            checked_at(model.nodes, child, "child", element_name("node", n), diag);
            is_child[static_cast<size_t>(child)] = 1;
        }
    }
    std::vector<int> roots;
    for (size_t n = 0; n < model.nodes.size(); ++n) {
        if (!is_child[n]) roots.push_back(static_cast<int>(n));
    }
    // Following parents from any node then never ends: the hierarchy holds a cycle.
    if (roots.empty()) diag.fail("node cycle: every node is the child of another");
    return RootNodes{roots, "root nodes"};
}

void check_expansion(const tinygltf::Model& model, const RootNodes& roots,
                     const Diagnostics& diag) {
    const size_t n = model.nodes.size();
    constexpr double kUnknown = -1.0;
    std::vector<double> instances(n, kUnknown), triangles(n, kUnknown);
    std::vector<char> on_stack(n, 0);
    auto mesh_triangles = [&](int mesh_index) {
        double count = 0.0;
        if (mesh_index < 0 || static_cast<size_t>(mesh_index) >= model.meshes.size()) return count;
        for (const tinygltf::Primitive& p :
             model.meshes[static_cast<size_t>(mesh_index)].primitives) {
            int accessor = p.indices;
            if (accessor == -1) {
                const auto position = p.attributes.find("POSITION");
                accessor = position == p.attributes.end() ? -1 : position->second;
            }
            if (accessor >= 0 && static_cast<size_t>(accessor) < model.accessors.size())
                count += static_cast<double>(model.accessors[static_cast<size_t>(accessor)].count);
        }
        return count;  // ≥ the triangles of any mode
    };
    struct Frame {
        int node;
        size_t next_child;
    };
    std::vector<Frame> stack;
    auto valid = [&](int node) { return node >= 0 && static_cast<size_t>(node) < n; };
    double total_instances = 0.0, total_triangles = 0.0;
    for (int root : roots.nodes) {
        if (!valid(root)) continue;  // traverse() names it
        if (instances[static_cast<size_t>(root)] == kUnknown) {
            stack.push_back(Frame{root, 0});
            on_stack[static_cast<size_t>(root)] = 1;
            while (!stack.empty()) {
                Frame& top = stack.back();
                const auto& children = model.nodes[static_cast<size_t>(top.node)].children;
                if (top.next_child < children.size()) {
                    const int child = children[top.next_child++];
                    if (!valid(child) || on_stack[static_cast<size_t>(child)] ||
                        instances[static_cast<size_t>(child)] != kUnknown)
                        continue;  // invalid or cyclic: traverse() names it
                    on_stack[static_cast<size_t>(child)] = 1;
                    stack.push_back(Frame{child, 0});
                    continue;
                }
                const size_t node = static_cast<size_t>(top.node);
                double i = 1.0, t = mesh_triangles(model.nodes[node].mesh);
                for (int child : children) {
                    if (!valid(child) || instances[static_cast<size_t>(child)] == kUnknown)
                        continue;
                    i += instances[static_cast<size_t>(child)];
                    t += triangles[static_cast<size_t>(child)];
                }
                instances[node] = i;
                triangles[node] = t;
                on_stack[node] = 0;
                stack.pop_back();
            }
        }
        total_instances += instances[static_cast<size_t>(root)];
        total_triangles += triangles[static_cast<size_t>(root)];
    }
    if (total_instances > static_cast<double>(kMaxNodeInstances)) {
        diag.fail("the node hierarchy expands to " + format_number(total_instances) +
                  " node instances, more than " + std::to_string(kMaxNodeInstances));
    }
    if (total_triangles > 3.0 * static_cast<double>(kMaxTriangles)) {
        diag.fail("the node hierarchy expands to up to " + format_number(total_triangles / 3.0) +
                  " triangles, more than " + std::to_string(kMaxTriangles));
    }
}

void traverse(const tinygltf::Model& model, const RootNodes& roots, Diagnostics& diag,
              const NodeVisitor& visit) {
    struct Frame {
        int node;
        glm::dmat4 world;
        size_t next_child;
    };
    std::vector<char> on_path(model.nodes.size(), 0);
    std::vector<Frame> stack;
    size_t instances = 0;

    auto enter = [&](int node, const glm::dmat4& parent_world) {
        if (on_path[static_cast<size_t>(node)]) {
            diag.fail("node cycle through node " + std::to_string(node));
        }
        if (++instances > kMaxNodeInstances) {
            diag.fail("the node hierarchy expands to more than " +
                      std::to_string(kMaxNodeInstances) + " node instances");
        }
        const glm::dmat4 world = parent_world * local_transform(model, node, diag);
        on_path[static_cast<size_t>(node)] = 1;
        visit(node, world);
        stack.push_back(Frame{node, world, 0});
    };

    for (int root : roots.nodes) {
        checked_at(model.nodes, root, "node", roots.element, diag);
        enter(root, glm::dmat4(1.0));
        while (!stack.empty()) {
            Frame& top = stack.back();
            const tinygltf::Node& node = model.nodes[static_cast<size_t>(top.node)];
            if (top.next_child == node.children.size()) {
                on_path[static_cast<size_t>(top.node)] = 0;
                stack.pop_back();
                continue;
            }
            const int child = node.children[top.next_child++];
            checked_at(model.nodes, child, "child",
                       element_name("node", static_cast<size_t>(top.node)), diag);
            const glm::dmat4 parent_world = top.world;  // `top` dies when `enter` grows the stack
            enter(child, parent_world);
        }
    }
}

}  // namespace mcrt::gltf

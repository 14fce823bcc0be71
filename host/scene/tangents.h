// Tangent frames for normal maps by MikkTSpace's method (Mikkelsen 2008, "Simulation of wrinkled
// surfaces revisited"), which glTF 2.0 asks for where a primitive has no TANGENT ("Meshes").
#pragma once

#include <glm/glm.hpp>
#include <vector>

namespace mcrt {

// Per-corner tangents of a triangle list: triangle t has corners 3t, 3t+1, 3t+2 of `positions`,
// unit `normals` and `texcoords`, counter-clockwise seen from its front face. Texture coordinates
// are as glTF stores them, v running down the image ("Images"); the handedness w = ±1 is glTF's:
// the bitangent w·cross(normal, tangent) points up the image, as the normal map's +Y
// ("Materials › Normal texture"). Each tangent is unit and orthogonal to its corner's normal.
//
// As MikkTSpace: corners with the same position, normal and texture coordinates are one vertex;
// around each vertex, triangles that share an edge and map texture space with the same
// orientation form a group, whose tangent is the angle-weighted mean of its triangles' dP/du,
// each projected onto the vertex's tangent plane, and whose w is the sign of that orientation
// (a mirrored UV island keeps tangents of its own). A triangle whose texture coordinates span no
// area joins a neighbour's group and adds nothing. A corner of a triangle with two corners at one
// position copies a grouped corner of its vertex; a corner left without a group (or whose group's
// mean is zero) gets any tangent orthogonal to its normal, with w = +1.
std::vector<glm::dvec4> generate_tangents(const std::vector<glm::dvec3>& positions,
                                          const std::vector<glm::dvec3>& normals,
                                          const std::vector<glm::dvec2>& texcoords);

// A unit vector orthogonal to the unit vector `n` (Duff et al. 2017, "Building an Orthonormal
// Basis, Revisited", JCGT 6(1)).
glm::dvec3 any_tangent(const glm::dvec3& n);

}  // namespace mcrt

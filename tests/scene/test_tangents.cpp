// MikkTSpace tangents (host/scene/tangents.cpp) on triangle lists built here; the glTF import's
// use of them is tested in test_gltf_attributes.cpp.
#include <catch2/catch.hpp>
#include <cmath>
#include <glm/glm.hpp>
#include <vector>

#include "scene/tangents.h"

namespace {

// Two squares sharing the edge x = 1 in z = 0, seen from +Z, as four triangles of corners.
std::vector<glm::dvec3> two_squares() {
    const glm::dvec3 p[6] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 0}, {2, 1, 0}};
    std::vector<glm::dvec3> corners;
    for (int i : {0, 1, 2, 0, 2, 3, 1, 4, 5, 1, 5, 2}) corners.push_back(p[i]);
    return corners;
}

bool near(const glm::dvec4& a, const glm::dvec4& b) {
    return glm::all(glm::lessThan(glm::abs(a - b), glm::dvec4(1e-12)));
}

}  // namespace

TEST_CASE("generate_tangents: glTF's usual map gives dP/du with w = +1, a mirrored one w = -1",
          "[tangents]") {
    // u = x on the left square; on the right one u = 2 − x (mirrored) or u = x; v = 1 − y.
    const std::vector<glm::dvec3> positions = two_squares();
    const std::vector<glm::dvec3> normals(positions.size(), glm::dvec3(0, 0, 1));
    for (const bool mirrored : {false, true}) {
        INFO((mirrored ? "mirrored right square" : "one map"));
        std::vector<glm::dvec2> uv;
        for (const glm::dvec3& p : positions) {
            uv.emplace_back(p.x <= 1.0 || !mirrored ? p.x : 2.0 - p.x, 1.0 - p.y);
        }
        const std::vector<glm::dvec4> t = mcrt::generate_tangents(positions, normals, uv);
        REQUIRE(t.size() == 12);
        for (size_t c = 0; c < 12; ++c) {
            INFO("corner " << c);
            const bool flipped = mirrored && c >= 6;
            CHECK(near(t[c], flipped ? glm::dvec4(-1, 0, 0, -1) : glm::dvec4(1, 0, 0, 1)));
        }
    }
}

TEST_CASE("generate_tangents: degenerate maps and triangles get a frame of their normal",
          "[tangents]") {
    // Triangle 0 spans no texture area; triangle 1 has two corners at one position; triangle 2
    // is a good one sharing triangle 1's vertex 0.
    const glm::dvec3 n(0, 0, 1);
    const std::vector<glm::dvec3> positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0},
                                               {5, 5, 0}, {5, 5, 0}, {6, 5, 0},
                                               {5, 5, 0}, {6, 5, 0}, {5, 6, 0}};
    const std::vector<glm::dvec3> normals(9, n);
    const std::vector<glm::dvec2> texcoords = {{0.5, 0.5}, {0.5, 0.5}, {0.5, 0.5}, {0, 1}, {0, 1},
                                               {1, 1},     {0, 1},     {1, 1},     {0, 0}};
    const std::vector<glm::dvec4> t = mcrt::generate_tangents(positions, normals, texcoords);
    REQUIRE(t.size() == 9);
    for (size_t c = 0; c < 9; ++c) {
        INFO("corner " << c);
        CHECK(glm::length(glm::dvec3(t[c])) == Approx(1.0));
        CHECK(std::abs(glm::dot(glm::dvec3(t[c]), n)) < 1e-12);
        CHECK(std::abs(t[c].w) == 1.0);
    }
    // The degenerate triangle's corners at (5,5) copy the good triangle's corner there.
    CHECK(t[3] == t[6]);
    CHECK(t[4] == t[6]);
    CHECK(near(t[6], glm::dvec4(1, 0, 0, 1)));
}

TEST_CASE("any_tangent is a unit vector orthogonal to its normal", "[tangents]") {
    for (const glm::dvec3& n :
         {glm::dvec3(0, 0, 1), glm::dvec3(0, 0, -1), glm::dvec3(1, 0, 0),
          glm::normalize(glm::dvec3(1, -2, 3)), glm::normalize(glm::dvec3(-1e-9, 1e-9, -1))}) {
        const glm::dvec3 t = mcrt::any_tangent(n);
        CHECK(glm::length(t) == Approx(1.0));
        CHECK(std::abs(glm::dot(t, n)) < 1e-12);
    }
}

#!/usr/bin/python3
"""Writes the stress scenes of scenes/stress/: small glTF files on which some estimator fails.

Each scene is a Lambertian receiver (baseColorFactor) lit by emissive triangles (emissiveFactor ×
KHR_materials_emissive_strength), seen by a perspective camera, with no occluder between any
visible point and any light. So every pixel has an exact value by Lambert's formula for polygon
lights (Arvo 1995, eq. 1), which tests/render/test_stress.cpp computes from the loaded file. What each
scene stresses, and whose failure case it is: scenes/stress/README.md.

Usage: scripts/scenes/make_stress_scenes.py [OUTPUT_DIR]   (default: scenes/stress of this checkout)
"""

import base64
import json
import math
import random
import struct
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from make_test_gltf import FLOAT, Gltf, primitive, write_files  # noqa: E402  (the same glTF writer)


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def add(a, b):
    return tuple(x + y for x, y in zip(a, b))


def scale(a, s):
    return tuple(x * s for x in a)


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def normalize(a):
    n = math.sqrt(sum(x * x for x in a))
    return tuple(x / n for x in a)


def quad(center, u, v):
    """Two triangles of the parallelogram center ± u/2 ± v/2, front face (CCW) toward u × v."""
    c = sub(sub(center, scale(u, 0.5)), scale(v, 0.5))
    p = [c, add(c, u), add(add(c, u), v), add(c, v)]
    return [p[0], p[1], p[2], p[0], p[2], p[3]]


# Edge vectors of horizontal quads: x × z = −y (facing down), z × x = +y (facing up).
X, Z = (1.0, 0.0, 0.0), (0.0, 0.0, 1.0)


class StressScene(Gltf):
    """A Gltf with helpers for Lambertian and emissive objects and a look-at camera. Every
    surface says Lambertian in glTF terms: metallic 0 and KHR_materials_specular's
    specularFactor 0 (no specular layer), so the default --materials gltf reads it as
    baseColor/pi."""

    def __init__(self, name):
        super().__init__()
        self.doc["asset"]["generator"] = "mcrt scripts/scenes/make_stress_scenes.py"
        self.doc["extensionsUsed"] = ["KHR_materials_emissive_strength",
                                      "KHR_materials_specular"]
        self.name = name
        self.roots = []

    LAMBERTIAN = {"KHR_materials_specular": {"specularFactor": 0.0}}

    def lambertian(self, name, albedo, double_sided=False):
        fields = {"name": name, "pbrMetallicRoughness": {
            "baseColorFactor": [*albedo, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0},
            "extensions": dict(self.LAMBERTIAN)}
        if double_sided:  # seen from behind too (glTF 2.0 "Double Sided"; else culled there)
            fields["doubleSided"] = True
        return self.material(**fields)

    def emitter(self, name, Le, albedo=(0.0, 0.0, 0.0), double_sided=False):
        """Le = emissiveFactor × emissiveStrength, the factor's largest component 1."""
        strength = max(Le)
        fields = {"name": name, "emissiveFactor": [round(c / strength, 6) for c in Le],
                  "pbrMetallicRoughness": {"baseColorFactor": [*albedo, 1.0],
                                           "metallicFactor": 0.0},
                  "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": strength},
                                 **self.LAMBERTIAN}}
        if double_sided:
            fields["doubleSided"] = True
        return self.material(**fields)

    def positions(self, points):
        """POSITION accessor with the min and max the glTF specification requires."""
        index = super().positions(points)
        accessor = self.doc["accessors"][index]
        f32 = [struct.unpack("<3f", struct.pack("<3f", *p)) for p in points]
        accessor["min"] = [min(p[i] for p in f32) for i in range(3)]
        accessor["max"] = [max(p[i] for p in f32) for i in range(3)]
        return index

    def triangles(self, name, points, material, indices=None):
        """A node with one mesh of non-indexed (or indexed) triangles."""
        position = self.positions(points)
        ids = self.indices(indices) if indices is not None else None
        mesh = self._add("meshes", {"name": name,
                                    "primitives": [primitive(position, ids, material)]})
        self.roots.append(self.node(name=name, mesh=mesh))

    def triangle_set(self, name, parts):
        """One node, one mesh, one primitive per (points, material) of parts, all positions in
        one buffer view (each accessor at its byteOffset): compact for many small lights."""
        data = b"".join(struct.pack("<3f", *q) for points, _ in parts for q in points)
        view = self.view(data)
        primitives, offset = [], 0
        for points, material in parts:
            f32 = [struct.unpack("<3f", struct.pack("<3f", *q)) for q in points]
            position = self.accessor(view, FLOAT, len(points), "VEC3", byteOffset=offset,
                                     min=[min(q[i] for q in f32) for i in range(3)],
                                     max=[max(q[i] for q in f32) for i in range(3)])
            primitives.append(primitive(position, None, material))
            offset += 12 * len(points)
        mesh = self._add("meshes", {"name": name, "primitives": primitives})
        self.roots.append(self.node(name=name, mesh=mesh))

    def camera(self, eye, target, up, yfov_degrees):
        """A perspective camera at eye looking at target; node matrix column-major (glTF)."""
        back = normalize(sub(eye, target))
        right = normalize(cross(up, back))
        true_up = cross(back, right)
        self.doc["cameras"] = [{"type": "perspective", "name": "camera", "perspective": {
            "yfov": math.radians(yfov_degrees), "aspectRatio": 1.0, "znear": 1e-4}}]
        matrix = [*right, 0.0, *true_up, 0.0, *back, 0.0, *eye, 1.0]
        self.roots.insert(0, self.node(name="camera", camera=0, matrix=matrix))

    def write(self, path):
        """Like Gltf.write, one array element per line (compact: many-lights has 100 of each)."""
        if self.blob:
            uri = "data:application/octet-stream;base64," + base64.b64encode(self.blob).decode()
            self.doc["buffers"] = [{"byteLength": len(self.blob), "uri": uri}]
        lines = []
        for key, value in self.doc.items():
            if isinstance(value, list):
                items = ",\n  ".join(json.dumps(v, separators=(",", ":")) for v in value)
                lines.append('"%s": [\n  %s\n ]' % (key, items))
            else:
                lines.append('"%s": %s' % (key, json.dumps(value, separators=(",", ":"))))
        path.write_text("{\n " + ",\n ".join(lines) + "\n}\n")

    def finish(self):
        self.scene(self.roots)
        return self


def floor(g, half, albedo, y=0.0):
    g.triangles("floor", quad((0.0, y, 0.0), scale(Z, 2 * half), scale(X, 2 * half)),
                g.lambertian("floor", albedo))


def looking_down(g, eye, yfov_degrees):
    """Straight down −Y, image up = −Z (as tests/support/analytic_scenes.h looking_down)."""
    g.camera(eye, (eye[0], eye[1] - 1.0, eye[2]), (0.0, 0.0, -1.0), yfov_degrees)


# ----- the scenes ------------------------------------------------------------------------------

def tiny_bright_light():
    """A 0.01 × 0.01 light of radiance 10^4 at height 1: E = 1 below it. The camera is under
    the light (height 0.9), so it sees the floor and not the light."""
    g = StressScene("tiny-bright-light")
    floor(g, 2.0, (0.7, 0.7, 0.7))
    g.triangles("tiny light", quad((0.1, 1.0, 0.05), scale(X, 0.01), scale(Z, 0.01)),
                g.emitter("tiny light", (1e4, 0.9e4, 0.8e4)))
    looking_down(g, (0.0, 0.9, 0.0), 90.0)
    return g.finish()


def near_light():
    """A 1 × 1 light 0.01 above the floor (1/100 of its size); the camera, between them at
    height 0.006, sees the floor just under the light's centre."""
    g = StressScene("near-light")
    floor(g, 2.0, (0.6, 0.6, 0.6))
    g.triangles("near light", quad((0.0, 0.01, 0.0), X, Z), g.emitter("near light", (1.0, 0.9, 0.8)))
    looking_down(g, (0.0, 0.006, 0.0), 90.0)
    return g.finish()


def grazing_light():
    """A 1 × 1 light facing down 0.02 above the floor and 1.5 to 2.5 away from what the camera
    sees: from the receiver it lies within 1° of the horizon, seen nearly edge-on."""
    g = StressScene("grazing-light")
    floor(g, 3.0, (0.5, 0.6, 0.7))
    g.triangles("grazing light", quad((2.0, 0.02, 0.0), X, Z),
                g.emitter("grazing light", (2000.0, 2000.0, 2000.0)))
    looking_down(g, (0.0, 3.0, 0.0), 30.0)
    return g.finish()


def light_facing_away():
    """A bright one-sided light facing up (away from the floor: it must add exactly nothing)
    and a dim one facing the floor, both outside the camera's view."""
    g = StressScene("light-facing-away")
    floor(g, 3.0, (0.6, 0.5, 0.4))
    g.triangles("light facing away", quad((-1.05, 1.0, 0.0), scale(Z, 0.5), scale(X, 0.5)),
                g.emitter("light facing away", (50.0, 50.0, 50.0)))
    g.triangles("dim light", quad((1.05, 1.0, 0.0), scale(X, 0.5), scale(Z, 0.5)),
                g.emitter("dim light", (2.0, 1.6, 1.2)))
    looking_down(g, (0.0, 3.0, 0.0), 40.0)
    return g.finish()


def many_lights():
    """100 triangle lights (area 0.005 each) on a 10 × 10 grid at height 1, radiances
    10^-3 … 10^3 (10^6 apart, log-spaced, shuffled with a fixed seed), above the camera."""
    g = StressScene("many-lights")
    floor(g, 3.0, (0.5, 0.5, 0.5))
    rng = random.Random(1)
    radiances = [10.0 ** (-3.0 + 6.0 * i / 99.0) for i in range(100)]
    rng.shuffle(radiances)
    parts = []
    for k, L in enumerate(radiances):
        i, j = divmod(k, 10)
        c = (-2.25 + 0.5 * i, 1.0, -2.25 + 0.5 * j)
        tint = (1.0, 0.6 + 0.4 * rng.random(), 0.6 + 0.4 * rng.random())
        # Facing down: (+x edge) × (+z edge) = −y.
        points = [sub(c, (0.05, 0.0, 0.05)), add(c, (0.05, 0.0, -0.05)), add(c, (0.0, 0.0, 0.05))]
        parts.append((points, g.emitter("light %d" % k, scale(tint, L))))
    g.triangle_set("lights", parts)
    looking_down(g, (0.0, 0.9, 0.0), 90.0)
    return g.finish()


def degenerate_emitters():
    """One ordinary light and very bright degenerate emissive triangles: a repeated index, three
    equal vertices, exactly collinear vertices, collinear vertices off the axes (not exactly
    collinear once rounded to float), one whose float cross product vanishes though its double
    area does not, and a needle of area ~1e-7. Some lie in the camera's view."""
    g = StressScene("degenerate-emitters")
    floor(g, 3.0, (0.7, 0.6, 0.5))
    g.triangles("light", quad((1.05, 1.0, 0.0), scale(X, 0.5), scale(Z, 0.5)),
                g.emitter("light", (4.0, 3.5, 3.0)))
    bright = g.emitter("degenerate", (1e3, 1e3, 1e3))
    bright2 = g.emitter("degenerate double-sided", (1e3, 1e3, 1e3), double_sided=True)
    g.triangles("repeated index", [(0.0, 0.5, 0.0), (0.3, 0.5, 0.2)], bright, indices=[0, 0, 1])
    g.triangles("repeated vertex", [(-0.2, 0.5, 0.1), (-0.2, 0.5, 0.1), (0.3, 0.6, -0.2)], bright2)
    g.triangles("point", [(-0.5, 0.95, 0.5)] * 3, bright)
    g.triangles("collinear", [(-1.0, 1.0, -1.0), (-0.5, 1.0, -1.0), (0.0, 1.0, -1.0)], bright)
    # Off the axes: 0.1, 0.2, 0.3 are not floats, so the rounded points are a hair off the line.
    g.triangles("collinear rounded", [(0.1, 0.7, 0.1), (0.2, 0.7, 0.2), (0.3, 0.7, 0.3)], bright)
    g.triangles("collinear 3d", [(-0.3, 0.4, 0.7), (0.1, 0.5, 0.4), (0.5, 0.6, 0.1)], bright2)
    # Not collinear in double precision (area 1.4e-9, so it is a light) but its float cross
    # product is exactly zero: its normal cannot be computed in single precision.
    g.triangles("float-collinear", [(-0.33, 0.82, -0.23), (-0.117, 0.751, -0.107),
                                    (0.167, 0.659, 0.057)], bright)
    # A needle: 2 long, 1.2e-7 wide (4 float ulps at 0.3), area ~9e-8.
    g.triangles("needle", [(-1.0, 0.8, 0.3), (1.0, 0.8, 0.3), (0.0, 0.8, 0.3000001)], bright)
    looking_down(g, (0.0, 0.9, 0.0), 90.0)
    return g.finish()


def reflecting_emitters():
    """An emitting floor and an emitting wall that both reflect (albedo > 0), each lit by the
    other; the wall stops 0.02 above the floor, so area sampling meets a near-1/d² singularity
    along the gap without an infinite variance. The camera sees both."""
    g = StressScene("reflecting-emitters")
    g.triangles("emitting floor", quad((0.0, 0.0, 0.0), scale(Z, 2.0), scale(X, 2.0)),
                g.emitter("emitting floor", (0.2, 0.3, 0.4), albedo=(0.5, 0.5, 0.5)))
    # Facing +x (toward the floor's visible part): +y × +z = +x.
    g.triangles("emitting wall", quad((-1.0, 0.77, 0.0), (0.0, 1.5, 0.0), scale(Z, 2.0)),
                g.emitter("emitting wall", (1.0, 0.6, 0.3), albedo=(0.6, 0.7, 0.8)))
    g.camera((1.6, 1.3, 0.9), (-0.4, 0.3, 0.0), (0.0, 1.0, 0.0), 50.0)
    return g.finish()


SCENES = {
    "tiny-bright-light": tiny_bright_light,
    "near-light": near_light,
    "grazing-light": grazing_light,
    "light-facing-away": light_facing_away,
    "many-lights": many_lights,
    "degenerate-emitters": degenerate_emitters,
    "reflecting-emitters": reflecting_emitters,
}


def main():
    _, paths = write_files(SCENES, Path(__file__).resolve().parents[2] / "scenes" / "stress")
    for path in paths:
        print("%s: %d bytes" % (path, path.stat().st_size))


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""Writes the glass test scenes of scenes/glass/ (KHR_materials_transmission, _ior, _volume):
the cases where light reaches a point only through a delta or a refraction, which next-event
estimation cannot build (shadow rays stop at glass), so that estimators part ways.

  glass-sphere   a smooth glass sphere (ior 1.5, a volume) on a white Lambertian floor under a
                 small light: its caustic on the floor comes only from BSDF-sampled paths
  glass-window   a room lit by a light outside through a thin-walled smooth glass pane in its
                 wall: light strategies see only the pane, the floor's light comes through it
  glass-slab     a smooth glass slab (a closed box, ior 1.5) above a Lambertian floor, for a
                 uniform sky (--sky 1): the slab-and-floor closed form of docs/MATERIALS.md

Render with paths, e.g. `mcrt render scenes/glass/glass-sphere.gltf --max-depth 16 --estimator
mis`; glass-slab with `--sky 1`.

Usage: scripts/scenes/make_glass_scenes.py [OUTPUT_DIR]   (default: scenes/glass of this checkout)
"""
import math
from pathlib import Path

from make_stress_scenes import StressScene, X, Z, floor, quad, scale
from make_test_gltf import write_files

GLASS_EXTENSIONS = ["KHR_materials_ior", "KHR_materials_transmission", "KHR_materials_volume"]


def glass_material(g, name, volume, roughness=0.0, ior=1.5):
    """Clear glass: white base, metallic 0, transmission 1; a volume when `volume`."""
    extensions = {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                  "KHR_materials_ior": {"ior": ior}}
    if volume:
        extensions["KHR_materials_volume"] = {"thicknessFactor": 1.0}
    g.doc["extensionsUsed"] = sorted(set(g.doc["extensionsUsed"] + GLASS_EXTENSIONS))
    return g.material(name=name, pbrMetallicRoughness={
        "baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 0.0,
        "roughnessFactor": roughness}, extensions=extensions)


def sphere(center, radius, slices, stacks):
    """Triangles of a latitude-longitude sphere, counter-clockwise seen from outside."""
    def vertex(i, j):
        if j == 0 or j == stacks:
            return (center[0], center[1] + (radius if j == 0 else -radius), center[2])
        phi = 2.0 * math.pi * (i % slices) / slices
        theta = math.pi * j / stacks
        return (center[0] + radius * math.sin(theta) * math.cos(phi),
                center[1] + radius * math.cos(theta),
                center[2] + radius * math.sin(theta) * math.sin(phi))
    points = []
    for j in range(stacks):
        for i in range(slices):
            a, b, c, d = vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1), vertex(i, j + 1)
            if j > 0:
                points += [a, b, c]
            if j < stacks - 1:
                points += [a, c, d]
    return points


def box(lo, hi):
    """The 12 triangles of an axis-aligned box, counter-clockwise seen from outside."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    c = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
         (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    faces = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (3, 7, 6, 2), (0, 4, 7, 3), (1, 2, 6, 5)]
    points = []
    for a, b, cc, d in faces:
        points += [c[a], c[b], c[cc], c[a], c[cc], c[d]]
    return points


def glass_sphere():
    g = StressScene("glass-sphere")
    floor(g, 3.0, (0.8, 0.8, 0.8))
    g.triangles("sphere", sphere((0.0, 0.5, 0.0), 0.5, 48, 24), glass_material(g, "glass", True))
    g.triangles("light", quad((0.0, 3.0, 0.0), scale(X, 0.3), scale(Z, 0.3)),
                g.emitter("light", (60.0, 60.0, 60.0)))
    g.camera((0.0, 2.2, 3.2), (0.0, 0.35, 0.0), (0.0, 1.0, 0.0), 40.0)
    return g.finish()


def glass_window():
    """The wall x = 0 (facing +x, into the room) with a 1 × 1 window at height 0.5..1.5, a pane
    of thin-walled glass in it, and a light outside at x = −1.5 facing the window."""
    g = StressScene("glass-window")
    floor(g, 3.0, (0.7, 0.7, 0.7))
    # Double-sided: a single-sided wall facing the room would be absent seen from outside, and
    # light would pass through it from the outside in.
    wall = g.lambertian("wall", (0.6, 0.6, 0.6), double_sided=True)
    Y = (0.0, 1.0, 0.0)
    # Four pieces around the window, each a quad in the plane x = 0 facing +x (Y × Z = +x).
    for center, h, w in [((0.0, 0.25, 0.0), 0.5, 6.0), ((0.0, 2.25, 0.0), 1.5, 6.0),
                         ((0.0, 1.0, -1.75), 1.0, 2.5), ((0.0, 1.0, 1.75), 1.0, 2.5)]:
        g.triangles("wall", quad(center, scale(Y, h), scale(Z, w)), wall)
    g.triangles("pane", quad((0.0, 1.0, 0.0), scale(Y, 1.0), scale(Z, 1.0)),
                glass_material(g, "pane", False))
    # The light faces the window: its front is u × v = Y × Z = +x.
    g.triangles("light", quad((-1.5, 1.3, 0.0), scale(Y, 0.6), scale(Z, 0.6)),
                g.emitter("light", (40.0, 40.0, 40.0)))
    g.camera((2.8, 1.6, 0.0), (0.0, 0.4, 0.0), (0.0, 1.0, 0.0), 60.0)
    return g.finish()


def glass_slab():
    g = StressScene("glass-slab")
    floor(g, 3.0, (0.5, 0.5, 0.5))
    g.triangles("slab", box((-1.5, 0.5, -1.5), (1.5, 0.7, 1.5)), glass_material(g, "slab", True))
    g.camera((0.0, 2.5, 2.5), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), 45.0)
    return g.finish()


SCENES = {"glass-sphere": glass_sphere, "glass-window": glass_window, "glass-slab": glass_slab}


def main():
    _, paths = write_files(SCENES, Path(__file__).resolve().parents[2] / "scenes" / "glass")
    for path in paths:
        print("%s: %d bytes" % (path, path.stat().st_size))


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""Writes the punctual-light scenes of scenes/punctual/ (KHR_lights_punctual): delta lights,
which only the light strategies (light-area, light-solid-angle, mis) can sample; directions drawn
on the hemisphere never find one (docs/DESIGN.md "Punctual lights").

  punctual-lights  a Lambertian floor (albedo 0.5) lit by a point light (I = 4) at height 1.5, a
                   spot light (I = 20, cone 20°-30°) at height 2 pointing down, a directional
                   light (E = 1.5) at 60° from the zenith casting a box's shadow, and a small
                   area light: every light selection gives the same image
  point-light      the floor under one point light alone: black to hemisphere-*, bsdf and the
                   ambient estimators, with a warning

Render e.g. `mcrt render scenes/punctual/punctual-lights.gltf --out p.exr --estimator mis`.

Usage: scripts/scenes/make_punctual_scenes.py [OUTPUT_DIR]   (default: scenes/punctual)
"""
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from make_stress_scenes import StressScene, X, Z, floor, looking_down, quad, scale  # noqa: E402
from make_test_gltf import write_files  # noqa: E402


def light(g, node_fields, **fields):
    """A KHR_lights_punctual light and the node that holds it."""
    extension = g.doc.setdefault("extensions", {}).setdefault("KHR_lights_punctual",
                                                              {"lights": []})
    extension["lights"].append(fields)
    if "KHR_lights_punctual" not in g.doc["extensionsUsed"]:
        g.doc["extensionsUsed"].append("KHR_lights_punctual")
    index = len(extension["lights"]) - 1
    g.roots.append(g.node(extensions={"KHR_lights_punctual": {"light": index}}, **node_fields))


def pointing_down():
    """A node rotation taking −Z (where a light points) to −Y: −90° about +X."""
    s = math.sqrt(0.5)
    return [-s, 0.0, 0.0, s]


def box_points(lo, hi):
    """The 12 triangles of an axis-aligned box, counter-clockwise seen from outside."""
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    c = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
         (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    faces = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (3, 7, 6, 2), (0, 4, 7, 3), (1, 2, 6, 5)]
    points = []
    for a, b, d, e in faces:
        points += [c[a], c[b], c[d], c[a], c[d], c[e]]
    return points


def punctual_lights():
    g = StressScene("punctual-lights")
    floor(g, 3.0, (0.5, 0.5, 0.5))
    light(g, {"name": "point", "translation": [-1.0, 1.5, -1.0]}, type="point",
          color=[1.0, 0.8, 0.6], intensity=4.0)
    light(g, {"name": "spot", "translation": [1.0, 2.0, 1.0], "rotation": pointing_down()},
          type="spot", color=[0.6, 0.8, 1.0], intensity=20.0,
          spot={"innerConeAngle": math.radians(20.0), "outerConeAngle": math.radians(30.0)})
    # Pointing along (sin 60°, −cos 60°, 0): a rotation of +60° about +Z after the one down.
    a = math.radians(60.0) / 2.0
    qz = [0.0, 0.0, math.sin(a), math.cos(a)]
    qx = pointing_down()
    # q = qz · qx (Hamilton product, x y z w).
    q = [qz[3] * qx[0] + qz[0] * qx[3] + qz[1] * qx[2] - qz[2] * qx[1],
         qz[3] * qx[1] - qz[0] * qx[2] + qz[1] * qx[3] + qz[2] * qx[0],
         qz[3] * qx[2] + qz[0] * qx[1] - qz[1] * qx[0] + qz[2] * qx[3],
         qz[3] * qx[3] - qz[0] * qx[0] - qz[1] * qx[1] - qz[2] * qx[2]]
    light(g, {"name": "sun", "rotation": q}, type="directional", color=[1.0, 1.0, 0.9],
          intensity=1.5)
    g.triangles("blocker", box_points((0.8, 0.0, -1.6), (1.2, 0.6, -1.2)),
                g.lambertian("blocker", (0.5, 0.5, 0.5)))
    g.triangles("area light", quad((-1.0, 1.0, 1.2), scale(X, 0.3), scale(Z, 0.3)),
                g.emitter("area light", (8.0, 8.0, 8.0)))
    looking_down(g, (0.0, 4.0, 0.0), 80.0)
    return g.finish()


def point_light():
    g = StressScene("point-light")
    floor(g, 2.0, (0.5, 0.5, 0.5))
    light(g, {"name": "point", "translation": [0.0, 1.0, 0.0]}, type="point", intensity=2.0)
    looking_down(g, (0.0, 2.0, 0.0), 80.0)
    return g.finish()


SCENES = {"punctual-lights": punctual_lights, "point-light": point_light}


def main():
    _, paths = write_files(SCENES, Path(__file__).resolve().parents[2] / "scenes" / "punctual")
    for path in paths:
        print("%s: %d bytes" % (path, path.stat().st_size))


if __name__ == "__main__":
    main()

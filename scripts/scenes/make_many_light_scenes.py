#!/usr/bin/python3
"""Writes many-light scenes for the light tree's experiments (docs/EXPERIMENTS.md, "Many lights").

- lamp-field: 8192 small triangle lights (edges 0.05-0.15) scattered over a 32 x 32 field at
  heights 1-2 above a floor, tilted up to 60 degrees, radiances log-spaced over 10^3 and areas
  over 9, so powers span more than 10^4; 30% face up, away from the floor, and those are the
  brightest (x10), so selection by power spends most samples on lights that cannot light the
  floor. The camera, below the lamps, sees only the floor.
- lamp-grid: 576 small triangle lights on a 24 x 24 grid 0.5 apart, 1 above a floor, each
  tilted up to 45 degrees, a third of them (at random) facing up, away from the floor;
  radiances log-spaced over 10^4 in a random order over the grid, so power does not follow
  position or orientation. Compact: the field spreads 12 wide against the lamps' height of 1.
- emissive-bunny: the Stanford bunny (69 451 triangles, every one an emitter, front faces out)
  standing on a floor, scaled to 1.2 high; from a floor point only the faces turned toward it
  count, and the nearest of them most.

Lambertian floor, one camera, direct light only. The bunny's geometry is read from
../shared/scenes/stanford/bunny_zipper.glb (see that folder's README), so the files are written,
not committed.

Usage: scripts/scenes/make_many_light_scenes.py [OUTPUT_DIR]   (default: out/many-lights)
"""

import json
import math
import random
import struct
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from make_stress_scenes import StressScene, X, Z, add, cross, floor, normalize, quad, scale, sub  # noqa: E402
from make_test_gltf import UINT  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
BUNNY = ROOT.parent / "shared" / "scenes" / "stanford" / "bunny_zipper.glb"


def tilted_normal(rng, max_tilt, up):
    """A random tilt within max_tilt degrees of straight down (or up)."""
    theta, phi = math.radians(max_tilt) * math.sqrt(rng.random()), 2.0 * math.pi * rng.random()
    n = (math.sin(theta) * math.cos(phi), -math.cos(theta), math.sin(theta) * math.sin(phi))
    return scale(n, -1.0) if up else n


def lamp_triangle(c, n, size):
    """A right triangle of legs `size` at c, counter-clockwise about n: (a, b) with a x b = n."""
    a = normalize(cross(n, (1.0, 0.0, 0.0) if abs(n[0]) < 0.9 else (0.0, 0.0, 1.0)))
    b = cross(n, a)
    return [c, add(c, scale(a, size)), add(c, scale(b, size))]


def lamp_field():
    g = StressScene("lamp-field")
    g.triangles("floor", quad((0.0, 0.0, 0.0), scale(Z, 34.0), scale(X, 34.0)),
                g.lambertian("floor", (0.6, 0.6, 0.6)))
    rng = random.Random(17)
    levels = 16
    groups = {}
    for _ in range(8192):
        c = (rng.uniform(-16.0, 16.0), rng.uniform(1.0, 2.0), rng.uniform(-16.0, 16.0))
        up = rng.random() < 0.3
        level = rng.randrange(levels)
        n = tilted_normal(rng, 60.0, up)
        groups.setdefault((up, level), []).extend(lamp_triangle(c, n, rng.uniform(0.05, 0.15)))
    parts = []
    for (up, level), points in sorted(groups.items()):
        L = 10.0 ** (3.0 * level / (levels - 1)) * (10.0 if up else 1.0)
        parts.append((points, g.emitter("lamp %s %d" % ("up" if up else "down", level),
                                        (L, 0.85 * L, 0.7 * L))))
    g.triangle_set("lamps", parts)
    # Looking down 17 degrees with a 30 degree field of view from below the lamps: no ray
    # rises, none sees a lamp.
    g.camera((0.0, 0.9, 3.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), 30.0)
    return g.finish()


def lamp_grid():
    g = StressScene("lamp-grid")
    g.triangles("floor", quad((0.0, 0.0, 0.0), scale(Z, 16.0), scale(X, 16.0)),
                g.lambertian("floor", (0.6, 0.6, 0.6)))
    rng = random.Random(29)
    levels = 9
    groups = {}
    for i in range(24):
        for j in range(24):
            c = (-5.75 + 0.5 * i, 1.0, -5.75 + 0.5 * j)
            up = rng.random() < 1.0 / 3.0
            level = rng.randrange(levels)
            groups.setdefault(level, []).extend(lamp_triangle(c, tilted_normal(rng, 45.0, up), 0.12))
    parts = []
    for level, points in sorted(groups.items()):
        L = 10.0 ** (4.0 * level / (levels - 1))
        parts.append((points, g.emitter("lamp %d" % level, (L, 0.85 * L, 0.7 * L))))
    g.triangle_set("lamps", parts)
    # Below the lamps, looking down over the floor: no ray rises, none sees a lamp.
    g.camera((0.0, 0.8, 4.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), 40.0)
    return g.finish()


def read_glb_mesh(path):
    """Positions and triangle indices of the first primitive of a .glb (float VEC3, any uint)."""
    data = path.read_bytes()
    json_length = struct.unpack("<I", data[12:16])[0]
    doc = json.loads(data[20:20 + json_length])
    binary = data[20 + json_length + 8:]
    prim = doc["meshes"][0]["primitives"][0]

    def read(accessor_index):
        acc = doc["accessors"][accessor_index]
        view = doc["bufferViews"][acc["bufferView"]]
        offset = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
        fmt = {5126: "f", 5125: "I", 5123: "H", 5121: "B"}[acc["componentType"]]
        width = {"VEC3": 3, "SCALAR": 1}[acc["type"]]
        count = acc["count"] * width
        values = struct.unpack_from("<%d%s" % (count, fmt), binary, offset)
        return [values[i:i + width] for i in range(0, count, width)] if width > 1 else list(values)

    return read(prim["attributes"]["POSITION"]), read(prim["indices"])


def emissive_bunny():
    g = StressScene("emissive-bunny")
    floor(g, 4.0, (0.6, 0.6, 0.6))
    points, ids = read_glb_mesh(BUNNY)
    lo = [min(p[i] for p in points) for i in range(3)]
    hi = [max(p[i] for p in points) for i in range(3)]
    s = 1.2 / (hi[1] - lo[1])
    centre = ((lo[0] + hi[0]) / 2, lo[1], (lo[2] + hi[2]) / 2)
    moved = [tuple(round(s * (p[i] - centre[i]), 6) for i in range(3)) for p in points]
    position = g.positions(moved)
    index = g.indices(ids, component_type=UINT)
    material = g.emitter("bunny", (4.0, 3.2, 2.4))
    mesh = g._add("meshes", {"name": "bunny", "primitives": [
        {"attributes": {"POSITION": position}, "indices": index, "material": material}]})
    g.roots.append(g.node(name="bunny", mesh=mesh))
    g.camera((1.6, 1.5, 3.2), (0.0, 0.45, 0.0), (0.0, 1.0, 0.0), 45.0)
    return g.finish()


SCENES = {"lamp-field": lamp_field, "lamp-grid": lamp_grid, "emissive-bunny": emissive_bunny}


def main():
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "out" / "many-lights"
    out.mkdir(parents=True, exist_ok=True)
    for name, make in SCENES.items():
        path = out / (name + ".gltf")
        make().write(path)
        print("%s: %d bytes" % (path, path.stat().st_size))


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""Writes the environment-map scene of scenes/env/: no emitters, lit only by --env.

  sun-blocks   a grey Lambertian floor with a red Lambertian block and a white metal block
               (metallic 1, roughness 0.3, as scenes/glossy/white-metal-plane), seen from the
               side and above; under the sun map of scripts/scenes/make_sky_maps.py (its sun at
               35 degrees elevation, azimuth 60) the blocks cast their shadows toward the camera

Render with a map, e.g. `mcrt render scenes/env/sun-blocks.gltf --env out/sky/sun-sky.hdr`.

Usage: scripts/scenes/make_env_scenes.py [OUTPUT_DIR]   (default: scenes/env of this checkout)
"""
from pathlib import Path

from make_glass_scenes import box
from make_stress_scenes import StressScene, floor
from make_test_gltf import write_files


def sun_blocks():
    g = StressScene("sun-blocks")
    floor(g, 3.0, (0.7, 0.7, 0.7))
    g.triangles("red block", box((-1.1, 0.0, -0.6), (-0.3, 0.8, 0.2)),
                g.lambertian("red block", (0.8, 0.3, 0.2)))
    metal = g.material(name="metal block", pbrMetallicRoughness={
        "baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 1.0, "roughnessFactor": 0.3})
    g.triangles("metal block", box((0.3, 0.0, -0.7), (1.1, 0.6, 0.1)), metal)
    g.camera((0.0, 2.2, 3.2), (0.0, 0.2, 0.0), (0.0, 1.0, 0.0), 45.0)
    return g.finish()


SCENES = {"sun-blocks": sun_blocks}


def main():
    _, paths = write_files(SCENES, Path(__file__).resolve().parents[2] / "scenes" / "env")
    for path in paths:
        print("%s: %d bytes" % (path, path.stat().st_size))


if __name__ == "__main__":
    main()

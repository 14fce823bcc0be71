#!/usr/bin/python3
"""Writes the glossy test scenes of scenes/glossy/: one quad light over a plane of one glTF
metallic-roughness material, seen from above with the light's highlight in view (the glossy
twins of tests/materials/test_materials.cpp's planes).

  white-metal-plane   metallic 1, baseColor 1, roughness 0.3 (GGX alpha 0.09): the one glossy
                      material whose BRDF Mitsuba 3 has too (roughconductor, material "none",
                      GGX, Fresnel 1; Schlick with F0 = 1 is 1) up to Smith's G, separable in
                      Mitsuba, height-correlated in glTF (docs/EXPERIMENTS.md)
  mirror-plane        metallic 1, baseColor (0.9, 0.6, 0.3), roughness 0 (alpha 1e-3, the
                      least mcrt reads): light sampling fails on the near-delta lobe, BSDF
                      sampling holds, MIS holds
  dielectric-plane    metallic 0, baseColor (0.6, 0.5, 0.4), roughness 0.2, the default
                      specular layer (F0 0.04): a diffuse base under a sharp highlight
  cornell-metal-block the Cornell box (scenes/cornell, its .bin shared) with every surface
                      Lambertian in glTF terms (specularFactor 0) but the tall block, a white
                      metal of roughness 0.3: glossy paths Mitsuba can render with the same BRDFs

Usage: scripts/scenes/make_glossy_scenes.py [OUTPUT_DIR]   (default: scenes/glossy of this checkout)
"""
import json
from pathlib import Path

from make_stress_scenes import StressScene, X, Z, looking_down, quad, scale
from make_test_gltf import write_files


def plane_scene(name, pbr, extensions=None):
    g = StressScene(name)
    fields = {"name": "plane", "pbrMetallicRoughness": pbr}
    if extensions:
        fields["extensions"] = extensions
    g.triangles("plane", quad((0.0, 0.0, 0.0), scale(Z, 6.0), scale(X, 6.0)), g.material(**fields))
    g.triangles("light", quad((1.05, 1.0, 0.0), scale(X, 0.5), scale(Z, 0.5)),
                g.emitter("light", (5.0, 4.0, 3.0)))
    looking_down(g, (0.0, 3.0, 0.0), 40.0)
    return g.finish()


def white_metal_plane():
    return plane_scene("white-metal-plane", {"baseColorFactor": [1.0, 1.0, 1.0, 1.0],
                                             "metallicFactor": 1.0, "roughnessFactor": 0.3})


def mirror_plane():
    return plane_scene("mirror-plane", {"baseColorFactor": [0.9, 0.6, 0.3, 1.0],
                                        "metallicFactor": 1.0, "roughnessFactor": 0.0})


def dielectric_plane():
    return plane_scene("dielectric-plane", {"baseColorFactor": [0.6, 0.5, 0.4, 1.0],
                                            "metallicFactor": 0.0, "roughnessFactor": 0.2})


class CopiedGltf:
    """A glTF document written as it is (write(path), as the generators' scenes)."""

    def __init__(self, doc):
        self.doc = doc

    def write(self, path):
        path.write_text(json.dumps(self.doc, indent=1) + "\n")


def cornell_metal_block():
    root = Path(__file__).resolve().parents[2] / "scenes"
    doc = json.loads((root / "cornell" / "CornellBox-Original.gltf").read_text())
    for b in doc["buffers"]:
        b["uri"] = "../cornell/" + b["uri"]
    for m in doc["materials"]:
        pbr = m.setdefault("pbrMetallicRoughness", {})
        if m.get("name") == "tallBox":
            pbr.update({"baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 1.0,
                        "roughnessFactor": 0.3})
        else:
            m.setdefault("extensions", {})["KHR_materials_specular"] = {"specularFactor": 0.0}
    doc["extensionsUsed"] = sorted(set(doc.get("extensionsUsed", []) + ["KHR_materials_specular"]))
    doc["asset"]["generator"] = "mcrt scripts/scenes/make_glossy_scenes.py from CornellBox-Original.gltf"
    return CopiedGltf(doc)


SCENES = {"white-metal-plane": white_metal_plane, "mirror-plane": mirror_plane,
          "dielectric-plane": dielectric_plane, "cornell-metal-block": cornell_metal_block}


def main():
    _, paths = write_files(SCENES, Path(__file__).resolve().parents[2] / "scenes" / "glossy")
    for path in paths:
        print("%s: %d bytes" % (path, path.stat().st_size))


if __name__ == "__main__":
    main()

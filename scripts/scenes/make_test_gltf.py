#!/usr/bin/python3
"""Writes the small hand-made glTF files of tests/data/ used by tests/scene/test_gltf_import.cpp.

Each file is a self-contained .gltf whose one buffer is a base64 data URI. Most are broken on
purpose (each in one way, named by the file) and must make the importer throw InputError; the
others check one feature (mirroring, TRS order, sparse data, strips, ...).

Usage: scripts/scenes/make_test_gltf.py [OUTPUT_DIR]   (default: tests/data of this checkout)
"""

import base64
import json
import math
import struct
import sys
import zlib
from pathlib import Path

FLOAT, UBYTE, USHORT, UINT = 5126, 5121, 5123, 5125
TRIANGLES, LINES, STRIP, FAN = 4, 1, 5, 6

# One triangle in the z = 0 plane, counter-clockwise seen from +Z (front face towards +Z).
TRIANGLE = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)]


class Gltf:
    """A glTF document under construction, all binary data in one buffer."""

    def __init__(self):
        self.doc = {"asset": {"version": "2.0", "generator": "mcrt scripts/scenes/make_test_gltf.py"}}
        self.blob = bytearray()

    def _add(self, key, item):
        self.doc.setdefault(key, []).append(item)
        return len(self.doc[key]) - 1

    def view(self, data, stride=None):
        while len(self.blob) % 4:
            self.blob.append(0)
        view = {"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data)}
        if stride:
            view["byteStride"] = stride
        self.blob += data
        return self._add("bufferViews", view)

    def accessor(self, view, component_type, count, type_, **extra):
        accessor = {"componentType": component_type, "count": count, "type": type_}
        if view is not None:
            accessor["bufferView"] = view
        accessor.update(extra)
        return self._add("accessors", accessor)

    def positions(self, points):
        data = b"".join(struct.pack("<3f", *p) for p in points)
        return self.accessor(self.view(data), FLOAT, len(points), "VEC3")

    def indices(self, ids, component_type=USHORT):
        fmt = {UBYTE: "B", USHORT: "H", UINT: "I"}[component_type]
        data = struct.pack("<%d%s" % (len(ids), fmt), *ids)
        return self.accessor(self.view(data), component_type, len(ids), "SCALAR")

    def mesh(self, *primitives):
        return self._add("meshes", {"primitives": list(primitives)})

    def node(self, **fields):
        return self._add("nodes", fields)

    def material(self, **fields):
        return self._add("materials", fields)

    def scene(self, nodes, default=True):
        index = self._add("scenes", {"nodes": nodes})
        if default:
            self.doc["scene"] = index
        return index

    def write(self, path):
        if self.blob:
            uri = "data:application/octet-stream;base64," + base64.b64encode(self.blob).decode()
            self.doc["buffers"] = [{"byteLength": len(self.blob), "uri": uri}]
        path.write_text(json.dumps(self.doc, indent=1) + "\n")


def primitive(position, indices=None, material=None, mode=None):
    p = {"attributes": {"POSITION": position}}
    if indices is not None:
        p["indices"] = indices
    if material is not None:
        p["material"] = material
    if mode is not None:
        p["mode"] = mode
    return p


def one_triangle(points=TRIANGLE, ids=(0, 1, 2), material_fields=None, node_fields=None):
    """A scene with one node holding one indexed triangle."""
    g = Gltf()
    material = g.material(**material_fields) if material_fields else None
    mesh = g.mesh(primitive(g.positions(points), g.indices(list(ids)), material))
    g.scene([g.node(mesh=mesh, **(node_fields or {}))])
    return g


def emissive(strength=None, double_sided=False):
    fields = {"name": "light", "emissiveFactor": [1.0, 1.0, 1.0], "doubleSided": double_sided}
    if strength is not None:
        fields["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": strength}}
    return fields


# ----- broken files: each must throw mcrt::InputError naming the file ---------------------------

def index_out_of_range():
    return one_triangle(ids=(0, 1, 5))


def node_cycle():
    g = Gltf()
    mesh = g.mesh(primitive(g.positions(TRIANGLE), g.indices([0, 1, 2])))
    g.node(mesh=mesh, children=[1])
    g.node(children=[0])
    g.scene([0])
    return g


def child_out_of_range():
    return one_triangle(node_fields={"children": [7]})


def accessor_overrun():
    g = Gltf()
    view = g.view(b"".join(struct.pack("<3f", *p) for p in TRIANGLE))  # 3 positions, 36 bytes
    position = g.accessor(view, FLOAT, 4, "VEC3")                       # claims 4
    g.scene([g.node(mesh=g.mesh(primitive(position)))])
    return g


def buffer_view_overrun():
    g = one_triangle()
    g.doc["bufferViews"][0]["byteLength"] = 400  # the buffer holds 44 bytes
    return g


def nan_position():
    return one_triangle(points=[(0.0, 0.0, 0.0), (float("nan"), 0.0, 0.0), (0.0, 1.0, 0.0)])


def huge_position():
    return one_triangle(points=[(0.0, 0.0, 0.0), (1e38, 0.0, 0.0), (0.0, 1.0, 0.0)])


def negative_emissive_strength():
    return one_triangle(material_fields=emissive(strength=-2.0))


def camera_yfov_zero():
    g = one_triangle()
    g.doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.0, "znear": 0.1}}]
    g.doc["scenes"][0]["nodes"].append(g.node(camera=0, translation=[0.0, 0.0, 3.0]))
    return g


def mesh_out_of_range():
    g = one_triangle()
    g.doc["nodes"][0]["mesh"] = 3
    return g


def material_out_of_range():
    g = one_triangle()
    g.doc["meshes"][0]["primitives"][0]["material"] = 2
    return g


def rootless_cycle():
    """No scenes, and every node is a child (0 of 1, 1 of 2, 2 of 1): no root to start from."""
    g = Gltf()
    mesh = g.mesh(primitive(g.positions(TRIANGLE), g.indices([0, 1, 2])))
    g.node(mesh=mesh)
    g.node(children=[0, 2])
    g.node(children=[1])
    return g


def scene_out_of_range():
    g = one_triangle()
    g.doc["scene"] = 4
    return g


# ----- valid files ----------------------------------------------------------------------------

def empty_scene():
    """A scene whose only node holds nothing: loads, with no triangles."""
    g = Gltf()
    g.scene([g.node(name="empty")])
    return g


def no_scenes():
    """No scenes at all: the root nodes (0 and 2; node 1 is a child of 0) are rendered."""
    g = Gltf()
    mesh = g.mesh(primitive(g.positions(TRIANGLE), g.indices([0, 1, 2])))
    g.node(children=[1])
    g.node(mesh=mesh)
    g.node(mesh=mesh, translation=[0.0, 0.0, 5.0])
    return g


def mirrored_emitter():
    """Scale −1 on x: the front face must still face +Z after the mirror."""
    return one_triangle(material_fields=emissive(), node_fields={"scale": [-1.0, 1.0, 1.0]})


def mirrored_matrix_emitter():
    """The same mirror as a column-major matrix on a parent node."""
    g = Gltf()
    mesh = g.mesh(primitive(g.positions(TRIANGLE), g.indices([0, 1, 2]), g.material(**emissive())))
    child = g.node(mesh=mesh)
    mirror = [-1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]
    g.scene([g.node(matrix=mirror, children=[child])])
    return g


def png_1x1(rgb):
    """A 1×1 RGB PNG: signature, IHDR, one IDAT, IEND."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    ihdr = struct.pack(">IIBBBBB", 1, 1, 8, 2, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) +
            chunk(b"IDAT", zlib.compress(bytes([0, *rgb]))) + chunk(b"IEND", b""))


def texture_reference():
    """Two materials sharing one texture (a 1×1 PNG, decoded once), one with an emissive
    strength."""
    g = Gltf()
    png = base64.b64encode(png_1x1((255, 128, 0))).decode()
    g.doc["images"] = [{"uri": "data:image/png;base64," + png}]
    g.doc["textures"] = [{"source": 0}]
    textured = g.material(name="textured",
                          pbrMetallicRoughness={"baseColorFactor": [0.5, 0.25, 0.125, 1.0],
                                                "baseColorTexture": {"index": 0}})
    normal_mapped = g.material(**dict(emissive(strength=4.0), name="normal_mapped",
                                      normalTexture={"index": 0}))
    position = g.positions(TRIANGLE)
    uv = g.accessor(g.view(struct.pack("<6f", 0, 0, 1, 0, 0, 1)), FLOAT, 3, "VEC2")
    textured_primitive = primitive(position, g.indices([0, 1, 2]), textured)
    normal_mapped_primitive = primitive(position, g.indices([0, 2, 1]), normal_mapped)
    for p in (textured_primitive, normal_mapped_primitive):
        p["attributes"]["TEXCOORD_0"] = uv
    g.scene([g.node(mesh=g.mesh(textured_primitive, normal_mapped_primitive))])
    return g


def trs_transform():
    """translation (1,2,3) · rotation 90° about +Z · scale (2,3,4): T·R·S."""
    s = math.sqrt(0.5)
    return one_triangle(points=[(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)],
                        node_fields={"translation": [1.0, 2.0, 3.0], "rotation": [0.0, 0.0, s, s],
                                     "scale": [2.0, 3.0, 4.0]})


def shared_subtree():
    """Nodes 1 and 2 both list node 3 (a mesh): two instances, not a cycle."""
    g = Gltf()
    mesh = g.mesh(primitive(g.positions(TRIANGLE), g.indices([0, 1, 2])))
    g.node(children=[1, 2])
    g.node(translation=[10.0, 0.0, 0.0], children=[3])
    g.node(translation=[0.0, 10.0, 0.0], children=[3])
    g.node(mesh=mesh)
    g.scene([0])
    return g


def sparse_without_buffer_view():
    """A POSITION accessor with no bufferView: zeros, then the sparse values override 1 and 2."""
    g = Gltf()
    sparse = {
        "count": 2,
        "indices": {"bufferView": g.view(struct.pack("<2H", 1, 2)), "componentType": USHORT},
        "values": {"bufferView": g.view(struct.pack("<6f", 2.0, 0.0, 0.0, 0.0, 3.0, 0.0))},
    }
    position = g.accessor(None, FLOAT, 3, "VEC3", sparse=sparse)
    g.scene([g.node(mesh=g.mesh(primitive(position)))])
    return g


def strips_fans_lines():
    """A strip and a fan of 4 vertices (2 triangles each) and a line primitive (skipped)."""
    g = Gltf()
    quad = g.positions([(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (1.0, 1.0, 0.0)])
    fan = g.positions([(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (1.0, 1.0, 0.0), (0.0, 1.0, 0.0)])
    mesh = g.mesh(primitive(quad, mode=STRIP),
                  primitive(fan, g.indices([0, 1, 2, 3], UBYTE), mode=FAN),
                  primitive(quad, mode=LINES))
    g.scene([g.node(mesh=mesh)])
    return g


def interleaved_positions():
    """POSITION interleaved with a NORMAL: byteStride 24, positions at offset 0."""
    g = Gltf()
    data = b"".join(struct.pack("<6f", *p, 0.0, 0.0, 1.0) for p in TRIANGLE)
    view = g.view(data, stride=24)
    position = g.accessor(view, FLOAT, 3, "VEC3")
    normal = g.accessor(view, FLOAT, 3, "VEC3", byteOffset=12)
    p = primitive(position, g.indices([0, 1, 2], UINT))
    p["attributes"]["NORMAL"] = normal
    g.scene([g.node(mesh=g.mesh(p))])
    return g


FILES = {
    "index_out_of_range": index_out_of_range,
    "node_cycle": node_cycle,
    "child_out_of_range": child_out_of_range,
    "accessor_overrun": accessor_overrun,
    "buffer_view_overrun": buffer_view_overrun,
    "nan_position": nan_position,
    "huge_position": huge_position,
    "negative_emissive_strength": negative_emissive_strength,
    "camera_yfov_zero": camera_yfov_zero,
    "mesh_out_of_range": mesh_out_of_range,
    "material_out_of_range": material_out_of_range,
    "scene_out_of_range": scene_out_of_range,
    "rootless_cycle": rootless_cycle,
    "no_scenes": no_scenes,
    "empty_scene": empty_scene,
    "mirrored_emitter": mirrored_emitter,
    "mirrored_matrix_emitter": mirrored_matrix_emitter,
    "texture_reference": texture_reference,
    "trs_transform": trs_transform,
    "shared_subtree": shared_subtree,
    "sparse_without_buffer_view": sparse_without_buffer_view,
    "strips_fans_lines": strips_fans_lines,
    "interleaved_positions": interleaved_positions,
}


def write_files(files, default_dir):
    """Writes OUT/NAME.gltf of every NAME → make() of `files`, OUT the first command-line
    argument or `default_dir` (both generators' main); returns OUT and the paths."""
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else default_dir
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, make in files.items():
        paths.append(out / (name + ".gltf"))
        make().write(paths[-1])
    return out, paths


def main():
    out, _ = write_files(FILES, Path(__file__).resolve().parents[2] / "tests" / "data")
    print("wrote %d files to %s" % (len(FILES), out))


if __name__ == "__main__":
    main()

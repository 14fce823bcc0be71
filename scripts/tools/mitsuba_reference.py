#!/usr/bin/python3
"""An independent reference: render a glTF scene with Mitsuba 3's `direct` integrator.

Converts the scene as mcrt reads it (docs/DESIGN.md, radiometric and camera contracts) into a
Mitsuba 3 scene and renders it:

  geometry   every triangle primitive of the default scene, node transforms applied (matrix or
             TRS), written as binary PLY meshes in world space (one per material), flat shaded
             (`face_normals`), so the shading normal is the geometric one, as in mcrt; a
             textured material's mesh carries the texture coordinates its textures read (PLY
             u, v, passed as glTF has them: Mitsuba's bitmap puts uv (0, 0) at the image's
             first, top row, as glTF 2.0 "Images" does, checked on tests/data/textured/), and
             a normal-mapped one its vertex normals (smooth shading under the normal map);
  materials  `twosided` `diffuse` with reflectance = baseColorFactor RGB (mcrt shades both faces,
             the normal flipped toward the ray; Mitsuba's diffuse alone is one-sided): mcrt's
             `--materials lambert`, which --equal-time passes to mcrt. With --materials gltf,
             a metal (metallicFactor 1) is `twosided` `roughconductor` with material "none"
             (Fresnel 1), specular_reflectance = baseColor, distribution ggx, alpha =
             max(roughness^2, 1e-3), visible-normal sampling: glTF's metal exactly when
             baseColor is 1 (Schlick with F0 = 1 is 1), up to Smith's G (Mitsuba's is
             separable, glTF's height-correlated); a Lambertian surface (metallic 0,
             KHR_materials_specular.specularFactor 0) stays diffuse; any other material has no
             Mitsuba equivalent and is refused. --materials principled converts every other
             material to Mitsuba's `principled` (base_color, metallic, roughness, specular =
             0.5 × specularFactor: F0 0.04 × specularFactor as glTF's), an approximation
             (Mitsuba's is Burley's 2015 Disney BRDF: a retro-reflective diffuse lobe, not
             glTF's Lambertian base), for textured scenes such as Sponza. Glass
             (KHR_materials_transmission bounding a KHR_materials_volume) is `dielectric`
             (roughness 0) or `roughdielectric` with the material's ior, the transmission tinted
             by the base colour, blended with a Lambertian base where transmissionFactor < 1,
             an absorbing volume an interior `homogeneous` medium under `volpath`; thin-walled
             glass has no Mitsuba equivalent and is refused (MaterialConversion.glass_bsdf).
             Every opaque surface stays two-sided: mcrt culls a single-sided surface seen from
             behind (docs/DESIGN.md), but Mitsuba's `twosided` cannot hold a `null` back, so
             where a ray meets such a back face the two renderers differ (an emitter's back is
             black in Mitsuba, absent in mcrt);
  textures   (glTF 2.0 "Texture Data", "Metallic-Roughness Material", "Additional Textures")
             each slot becomes a `bitmap` with raw = true holding the values mcrt computes
             before filtering: baseColor and emissive texels sRGB-decoded (IEC 61966-2-1) and
             multiplied by their factors, metallic (B) × metallicFactor and roughness (G) ×
             roughnessFactor split into single-channel images (their square for
             roughconductor's alpha), normal texels with normalTexture.scale applied;
             filter_type nearest for magFilter NEAREST, else bilinear (no mipmaps, as mcrt);
             wrap_mode repeat / clamp / mirror from wrapS = wrapT. Mitsuba has one wrap mode
             for both axes: where wrapS ≠ wrapT the texture is tiled over the texture
             coordinates the mesh reaches (each axis wrapped at texel level, OpenGL 4.6 sec.
             8.14.2, then clamp), exact for both filters, or, past 2^24 texels, read with
             wrapS's mode (a warning). KHR_texture_transform (T·R·S, R = [[cos, sin], [−sin,
             cos]]) is the bitmap's to_uv, its texCoord overriding textureInfo's. A material
             reads one texture-coordinate set in Mitsuba (the base colour's, else its first
             slot's; a warning where slots differ). Normal maps are `normalmap` around the
             BSDF: Mitsuba's tangent frame is (dp/du, n × dp/du, n) — glTF's for tangent
             w = +1 — so triangles of w = −1 (TANGENT, else mirrored texture coordinates) read
             a copy with green flipped; --no-normal-maps leaves them out. Occlusion textures
             are ignored (they do not affect direct light);
  alpha      (glTF 2.0 "Alpha Coverage") MASK is a `mask` BSDF whose opacity is alpha =
             baseColorFactor.a × texture alpha thresholded at alphaCutoff per texel (the
             slot's filter then blurs the 0/1 edge over a texel), BLEND a `mask` of opacity
             alpha: Mitsuba passes a ray with probability 1 − opacity, mcrt's stochastic
             transparency. An emitter's radiance is multiplied by the same opacity, so holes
             neither emit nor block (alpha and emission in one texel grid: otherwise the
             emission keeps its own and a warning says alpha is left out of it). Scenes with
             alpha are rendered by `volpath`, whose shadow rays pass null surfaces (`direct`
             and `path` treat them as opaque), with the same depth;
  emitters   `area` with radiance = emissiveFactor × KHR_materials_emissive_strength (×
             emissiveTexture). Mitsuba's area emitters emit on the front side of the mesh
             normal, which for a PLY mesh is cross(p1 − p0, p2 − p0): glTF's
             counter-clockwise front, as mcrt. A `doubleSided`
             emitter gets a second, flipped copy 1e-6·diag behind it; KHR_lights_punctual
             lights are `point`, `spot` (its falloff between the cones approximate: a
             warning) and `directional` emitters; --env is an `envmap` (environment_emitter);
  camera     the first perspective camera node (--camera K: the first node of glTF camera K,
             as mcrt) or the bench camera of DESIGN.md, `perspective` with
             fov_axis y and fov = yfov; the glTF camera looks down −Z, Mitsuba's down +Z, so the
             sensor's to_world is a look_at built from the node's eye, −Z axis and +Y axis;
             `hdrfilm` of W×H with the `box` reconstruction filter (every sample inside its
             own pixel, uniformly jittered: mcrt's pixel estimate);
  integrator `direct` (emitter_samples = bsdf_samples = 1, combined by MIS — Mitsuba's only
             direct-light estimator), hide_emitters false; with --max-depth N > 1 (mcrt's
             reflections) `path` with max_depth = N + 1 (Mitsuba counts the camera segment)
             and rr_depth = --rr-depth, the same light paths as `mcrt render --max-depth N`.

Renders in --passes passes with different seeds and writes their mean as an EXR with R, G, B,
a variance layer (variance.R/G/B: the variance of the mean, from the spread of the passes) and a
float `spp` attribute, plus a JSON beside it (seconds of rendering, variant, spp, command).

--compare MCRT.exr: the mean relative difference between the two images and a difference image
(PNG): the agreement check of docs/EXPERIMENTS.md.

--equal-time REF.exr: right after the Mitsuba render, renders the scene with mcrt (--mcrt-args,
default the `mis` estimator with the `sobol` sampler) under --time-limit = Mitsuba's render
seconds, in the same run on the same machine, and prints both RMSEs against REF.exr (e.g. a
high-spp reference of scripts/experiments/experiment.py) with the times.

Needs Mitsuba 3 (scripts/tools/requirements-mitsuba.txt). When /usr/bin/python3 cannot import it, the
script re-runs itself with the Python of .venv-mitsuba/ or .venv/ at the repository root; set up
with
    /usr/bin/python3 -m venv --system-site-packages .venv-mitsuba
    .venv-mitsuba/bin/pip install -r scripts/tools/requirements-mitsuba.txt
    .venv-mitsuba/bin/python scripts/tools/mitsuba_reference.py SCENE --spp 1024 --out m.exr

Variant llvm_ad_rgb needs a libLLVM that Dr.Jit 1.5 can use: with Debian 12's LLVM 14/15 it aborts
("LLVM ERROR: Cannot select: ... fmaximum"); scalar_rgb is the default.

Usage: scripts/tools/mitsuba_reference.py SCENE --spp N [--width W --height H] --out X.exr
           [--variant scalar_rgb|llvm_ad_rgb] [--passes P] [--seed S] [--compare MCRT.exr]
           [--materials lambert|gltf|principled] [--camera K] [--no-normal-maps]
"""

import argparse
import base64
import importlib.util
import json
import math
import os
import shlex
import struct
import sys
import tempfile
import time
from pathlib import Path

import mcrt_run

mcrt_run.require("numpy")
import numpy as np  # noqa: E402

from mcrt_exr import write_exr  # noqa: E402

COMPONENTS = {5120: "<i1", 5121: "<u1", 5122: "<i2", 5123: "<u2", 5125: "<u4", 5126: "<f4"}
WIDTHS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}

# glTF 2.0 sampler enums (Properties Reference, "sampler") and Mitsuba's bitmap wrap modes.
NEAREST = 9728
REPEAT, CLAMP_TO_EDGE, MIRRORED_REPEAT = 10497, 33071, 33648
MITSUBA_WRAP = {REPEAT: "repeat", CLAMP_TO_EDGE: "clamp", MIRRORED_REPEAT: "mirror"}
MAX_TILED_TEXELS = 1 << 24


def warn(message):
    print("mitsuba_reference: warning: " + message, file=sys.stderr)


# ----- a minimal glTF reader ---------------------------------------------------------------------

class Gltf:
    """What mcrt reads of a glTF 2.0 file: triangles in world space with their material and the
    corners' attributes textures read, the materials, their textures' images, the cameras."""

    def __init__(self, path):
        path = Path(path)
        data = path.read_bytes()
        self.glb_bin = None
        if data[:4] == b"glTF":  # .glb: JSON chunk, then an optional BIN chunk
            length, = struct.unpack_from("<I", data, 12)
            self.doc = json.loads(data[20:20 + length])
            rest = 20 + length
            if rest + 8 <= len(data):
                bin_length, = struct.unpack_from("<I", data, rest)
                self.glb_bin = data[rest + 8:rest + 8 + bin_length]
        else:
            self.doc = json.loads(data)
        self.dir = path.parent
        self.buffers = [self._buffer(b) for b in self.doc.get("buffers", [])]

    def _buffer(self, b):
        uri = b.get("uri")
        if uri is None:
            return self.glb_bin
        if uri.startswith("data:"):
            return base64.b64decode(uri.split(",", 1)[1])
        return (self.dir / uri).read_bytes()

    def accessor(self, index):
        a = self.doc["accessors"][index]
        if "sparse" in a:
            raise ValueError("accessor %d: sparse accessors are not supported here" % index)
        dtype = np.dtype(COMPONENTS[a["componentType"]])
        width = WIDTHS[a["type"]]
        view = self.doc["bufferViews"][a["bufferView"]]
        buffer = self.buffers[view["buffer"]]
        start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
        stride = view.get("byteStride") or dtype.itemsize * width
        count = a["count"]
        rows = np.ndarray((count, width), dtype, buffer, start, (stride, dtype.itemsize))
        return np.array(rows)

    def attribute(self, index):
        """An accessor as float64, normalized integers mapped to [0, 1] or [−1, 1] (glTF 2.0
        "Meshes": TEXCOORD may be normalized unsigned bytes or shorts; "Animations" gives
        the mapping, max(c / (2^(n−1) − 1), −1) for signed)."""
        a = self.doc["accessors"][index]
        values = self.accessor(index)
        if a.get("normalized") and values.dtype.kind in "iu":
            top = float(np.iinfo(values.dtype).max)
            return np.maximum(values / top, -1.0)
        return values.astype(np.float64)

    def image(self, index):
        """(bytes, suffix) of image `index`: a file, a data URI or a bufferView."""
        image = self.doc["images"][index]
        uri = image.get("uri")
        mime = image.get("mimeType", "")
        if uri is None:
            view = self.doc["bufferViews"][image["bufferView"]]
            start = view.get("byteOffset", 0)
            data = bytes(self.buffers[view["buffer"]][start:start + view["byteLength"]])
        elif uri.startswith("data:"):
            mime = uri[5:uri.index(";")] if ";" in uri else mime
            data = base64.b64decode(uri.split(",", 1)[1])
        else:
            from urllib.parse import unquote
            data = (self.dir / unquote(uri)).read_bytes()
        suffix = ".png" if data[:8] == b"\x89PNG\r\n\x1a\n" else ".jpg" if data[:3] == b"\xff\xd8\xff" \
            else {"image/png": ".png", "image/jpeg": ".jpg"}.get(mime, ".png")
        return data, suffix

    def node_matrix(self, node):
        if "matrix" in node:
            return np.array(node["matrix"], np.float64).reshape(4, 4).T  # column-major
        t = np.eye(4)
        t[:3, 3] = node.get("translation", [0, 0, 0])
        x, y, z, w = node.get("rotation", [0, 0, 0, 1])
        r = np.eye(4)
        r[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
        s = np.diag(list(node.get("scale", [1, 1, 1])) + [1])
        return t @ r @ s

    def walk(self):
        """(node, world matrix) of every node of the default scene, depth first."""
        scene = self.doc["scenes"][self.doc.get("scene", 0)]
        stack = [(n, np.eye(4)) for n in reversed(scene.get("nodes", []))]
        while stack:
            index, parent = stack.pop()
            node = self.doc["nodes"][index]
            world = parent @ self.node_matrix(node)
            yield node, world
            for child in reversed(node.get("children", [])):
                stack.append((child, world))

    def primitives(self):
        """material index (−1: the default material) → list of Corners (world-space triangles
        and what their corners carry), one per triangle primitive instance."""
        out = {}
        for node, world in self.walk():
            if "mesh" not in node:
                continue
            for prim in self.doc["meshes"][node["mesh"]]["primitives"]:
                mode = prim.get("mode", 4)
                if mode not in (4, 5, 6):
                    print("mitsuba_reference: skipping a primitive of mode %d" % mode,
                          file=sys.stderr)
                    continue
                attributes = prim["attributes"]
                p = self.accessor(attributes["POSITION"]).astype(np.float64)
                count = len(p)
                if "indices" in prim:
                    idx = self.accessor(prim["indices"]).reshape(-1).astype(np.int64)
                else:
                    idx = np.arange(count)
                if mode == 4:
                    tri = idx[:len(idx) // 3 * 3].reshape(-1, 3)
                elif mode == 5:  # strip: every other triangle reversed to keep the winding
                    tri = np.array([(idx[i], idx[i + 1], idx[i + 2]) if i % 2 == 0 else
                                    (idx[i + 1], idx[i], idx[i + 2]) for i in range(len(idx) - 2)])
                else:  # fan
                    tri = np.array([(idx[0], idx[i], idx[i + 1]) for i in range(1, len(idx) - 1)])
                if len(tri) == 0:
                    continue
                linear = world[:3, :3]
                mirrored = np.linalg.det(linear) < 0
                if mirrored:  # a mirroring transform flips the winding
                    tri = tri[:, [0, 2, 1]]
                corners = Corners(p @ linear.T + world[:3, 3], tri)
                for n in (0, 1):
                    if "TEXCOORD_%d" % n in attributes:
                        corners.uv[n] = self.attribute(attributes["TEXCOORD_%d" % n])[:, :2][tri]
                if "NORMAL" in attributes:
                    normals = self.attribute(attributes["NORMAL"]) @ np.linalg.inv(linear)
                    corners.normals = normals[tri]
                if "TANGENT" in attributes:
                    t = self.attribute(attributes["TANGENT"])
                    # bitangent = w · cross(N, T) (glTF 2.0 "Meshes"): a mirror flips w
                    corners.tangent_w = (t[:, 3] * (-1.0 if mirrored else 1.0))[tri]
                out.setdefault(prim.get("material", -1), []).append(corners)
        return out

    def punctual_lights(self):
        """KHR_lights_punctual as mcrt reads them (docs/DESIGN.md): (type, colour × intensity,
        world position, world direction the light points along (the node's −Z), inner and outer
        cone angles) of every node of the default scene that carries one."""
        lights = self.doc.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
        out = []
        for node, world in self.walk():
            index = node.get("extensions", {}).get("KHR_lights_punctual", {}).get("light")
            if index is None:
                continue
            light = lights[index]
            value = [c * light.get("intensity", 1.0) for c in light.get("color", [1, 1, 1])]
            direction = -world[:3, 2]
            direction = direction / np.linalg.norm(direction)
            spot = light.get("spot", {})
            out.append((light["type"], value, world[:3, 3].copy(), direction,
                        spot.get("innerConeAngle", 0.0), spot.get("outerConeAngle", math.pi / 4)))
        return out

    def triangles(self):
        """material index (−1: the default material) → (n, 3, 3) world-space triangles."""
        return {m: np.concatenate([c.positions for c in parts])
                for m, parts in self.primitives().items()}

    def material(self, index):
        """(albedo RGB, emitted radiance RGB, doubleSided) of a material; glTF's default
        material for −1."""
        m = self.doc["materials"][index] if index >= 0 else {}
        albedo = m.get("pbrMetallicRoughness", {}).get("baseColorFactor", [1, 1, 1, 1])[:3]
        strength = m.get("extensions", {}).get("KHR_materials_emissive_strength", {}) \
            .get("emissiveStrength", 1.0)
        emission = [c * strength for c in m.get("emissiveFactor", [0, 0, 0])]
        return albedo, emission, bool(m.get("doubleSided", False))

    def camera(self, bounds, index=None):
        """(eye, forward, up, yfov radians): the first perspective camera node, or with `index`
        the first node of glTF camera `index` (as mcrt's --camera K), else (no camera at all)
        the bench camera."""
        cameras = self.doc.get("cameras", [])
        if index is not None:
            if not 0 <= index < len(cameras):
                raise ValueError("camera %d: the scene has %d cameras" % (index, len(cameras)))
            if cameras[index].get("type") != "perspective":
                raise ValueError("camera %d is %s; only perspective cameras are rendered"
                                 % (index, cameras[index].get("type")))
        found = False
        for node, world in self.walk():
            if "camera" in node:
                cam = cameras[node["camera"]]
                if cam.get("type") != "perspective":
                    continue
                found = True
                if index is not None and node["camera"] != index:
                    continue
                eye = world[:3, 3]
                forward = -world[:3, 2] / np.linalg.norm(world[:3, 2])
                up = world[:3, 1] / np.linalg.norm(world[:3, 1])
                return eye, forward, up, cam["perspective"]["yfov"]
        if index is not None:
            raise ValueError("camera %d is on no node of the default scene" % index)
        lo, hi = bounds
        c, diag = (lo + hi) / 2, np.linalg.norm(hi - lo)
        eye = c + diag * np.array([0.35, 0.30, 0.55])
        forward = (c - eye) / np.linalg.norm(c - eye)
        return eye, forward, np.array([0.0, 1.0, 0.0]), math.radians(45.0)


class Corners:
    """Triangles of one primitive instance: positions (n, 3, 3) in world space and, per corner,
    the texture coordinates of TEXCOORD_0 / _1 (n, 3, 2), normals (n, 3, 3) and tangent signs
    (n, 3) where the primitive has them."""

    def __init__(self, points, tri):
        self.positions = points[tri]
        self.uv = [None, None]
        self.normals = None
        self.tangent_w = None

    def __len__(self):
        return len(self.positions)

    def handedness(self, texcoord):
        """+1 where the glTF tangent frame (T, w·N × T, N) agrees with Mitsuba's (dp/du,
        N × dp/du, N), −1 where it is mirrored: the sign of TANGENT.w, or without TANGENT the
        sign of (N × dp/du) · (−dp/dv), −dp/dv being image up (glTF normal maps are +Y up,
        uv (0, 0) the upper left corner)."""
        if self.tangent_w is not None:
            return np.where(self.tangent_w.mean(axis=1) < 0, -1, 1)
        uv = self.uv[texcoord]
        if uv is None:
            return np.ones(len(self), int)
        p = self.positions
        e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
        d1, d2 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
        det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
        det = np.where(det == 0, 1.0, det)
        dp_du = (d2[:, 1:2] * e1 - d1[:, 1:2] * e2) / det[:, None]
        dp_dv = (-d2[:, 0:1] * e1 + d1[:, 0:1] * e2) / det[:, None]
        n = np.cross(e1, e2)
        return np.where(np.sum(np.cross(n, dp_du) * -dp_dv, axis=1) < 0, -1, 1)


DEBIAN_LLVM19 = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"


def write_ply(path, triangles, uv=None, normals=None):
    """Binary PLY of unshared vertices: positions (n, 3, 3), optionally per-corner texture
    coordinates (n, 3, 2) as u, v and normals (n, 3, 3) as nx, ny, nz."""
    n = len(triangles)
    columns, names = [triangles.reshape(-1, 3)], ["x", "y", "z"]
    if normals is not None:
        columns.append(normals.reshape(-1, 3))
        names += ["nx", "ny", "nz"]
    if uv is not None:
        columns.append(uv.reshape(-1, 2))
        names += ["u", "v"]
    header = ("ply\nformat binary_little_endian 1.0\nelement vertex %d\n" % (3 * n)
              + "".join("property float %s\n" % name for name in names)
              + "element face %d\nproperty list uchar int vertex_indices\nend_header\n" % n).encode()
    vertices = np.concatenate(columns, axis=1).astype("<f4").tobytes()
    faces = np.zeros(n, dtype=[("k", "u1"), ("i", "<i4", (3,))])
    faces["k"] = 3
    faces["i"] = np.arange(3 * n, dtype=np.int64).reshape(n, 3)
    Path(path).write_bytes(header + vertices + faces.tobytes())


# ----- textures ------------------------------------------------------------------------------------

def srgb_to_linear(c):
    """The sRGB EOTF (IEC 61966-2-1) of values in [0, 1]."""
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


class TextureSlot:
    """A material's textureInfo resolved: image, sampler, texture-coordinate set and the
    KHR_texture_transform matrix (2 × 3, (u', v') = M (u, v, 1))."""

    def __init__(self, gltf, info, where):
        texture = gltf.doc["textures"][info["index"]]
        if "source" not in texture:
            raise ValueError("%s: texture %d has no source image" % (where, info["index"]))
        sampler = gltf.doc["samplers"][texture["sampler"]] if "sampler" in texture else {}
        self.image = texture["source"]
        self.wrap = (sampler.get("wrapS", REPEAT), sampler.get("wrapT", REPEAT))
        self.nearest = sampler.get("magFilter") == NEAREST  # LINEAR when absent, as mcrt
        self.texcoord = info.get("texCoord", 0)
        self.matrix = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
        transform = info.get("extensions", {}).get("KHR_texture_transform")
        if transform is not None:
            # KHR_texture_transform: T(offset) R(rotation) S(scale), R = [[cos, sin], [−sin, cos]]
            # (its README's example: offset (0, 1), rotation π/2, scale 0.5 selects the lower
            # left quadrant), and its texCoord overrides textureInfo's.
            ox, oy = transform.get("offset", [0.0, 0.0])
            sx, sy = transform.get("scale", [1.0, 1.0])
            r = transform.get("rotation", 0.0)
            c, s = math.cos(r), math.sin(r)
            self.matrix = np.array([[c * sx, s * sy, ox], [-s * sx, c * sy, oy]])
            self.texcoord = transform.get("texCoord", self.texcoord)
        self.where = where

    def grid_key(self):
        """Slots whose texels line up: the same image size is checked by the caller."""
        return (self.wrap, self.nearest, self.texcoord, self.matrix.tobytes())


class Textures:
    """Turns texture slots into Mitsuba bitmap textures (loaded once per distinct content)."""

    def __init__(self, mi, gltf, scratch):
        self.mi, self.gltf, self.scratch = mi, gltf, Path(scratch)
        self.decoded, self.loaded = {}, {}

    def texels(self, image):
        """(H, W, 4) float64 values in [0, 1] of image `image` as stored (grey widened, alpha 1
        where absent); Mitsuba's own PNG/JPEG readers, colour metadata ignored (glTF 2.0
        "Images")."""
        if image not in self.decoded:
            data, suffix = self.gltf.image(image)
            path = self.scratch / ("image%d%s" % (image, suffix))
            path.write_bytes(data)
            bitmap = self.mi.Bitmap(str(path))
            a = np.array(bitmap)
            top = float(np.iinfo(a.dtype).max) if a.dtype.kind in "iu" else 1.0
            a = a.astype(np.float64) / top
            if a.ndim == 2:
                a = a[:, :, None]
            c = a.shape[2]
            rgb = a[:, :, :1].repeat(3, axis=2) if c < 3 else a[:, :, :3]
            alpha = a[:, :, c - 1:c] if c in (2, 4) else np.ones_like(a[:, :, :1])
            self.decoded[image] = np.concatenate([rgb, alpha], axis=2)
        return self.decoded[image]

    def bitmap(self, slot, values, key, uv_range):
        """A loaded `bitmap` texture of `values` (H, W, C), read as `slot` says; uv_range
        (u min, u max, v min, v max of the transformed coordinates the mesh reaches) sizes the
        tiling of mixed wrap modes."""
        h, w = values.shape[:2]
        matrix, wrap = slot.matrix, MITSUBA_WRAP.get(slot.wrap[0], "repeat")
        if slot.wrap[0] != slot.wrap[1]:
            tiled = self.tile(slot, values, uv_range)
            if tiled is None:
                warn("%s: wrapS %d ≠ wrapT %d over too large a range: read with wrapS's mode"
                     % (slot.where, slot.wrap[0], slot.wrap[1]))
            else:
                values, i0, j0 = tiled
                hb, wb = values.shape[:2]
                # texel i0 + a of the original is texel a of the tiled image
                to_tiled = np.array([[w / wb, 0.0, -i0 / wb], [0.0, h / hb, -j0 / hb], [0, 0, 1]])
                matrix = (to_tiled @ np.vstack([matrix, [0, 0, 1]]))[:2]
                wrap = "clamp"
                key = key + ("tiled", i0, j0, hb, wb)
        key = key + (slot.nearest, wrap, matrix.tobytes())
        if key not in self.loaded:
            desc = {"type": "bitmap", "raw": True, "wrap_mode": wrap,
                    "filter_type": "nearest" if slot.nearest else "bilinear",
                    "bitmap": self.mi.Bitmap(np.ascontiguousarray(values, np.float32))}
            if not np.array_equal(matrix, [[1, 0, 0], [0, 1, 0]]):
                desc["to_uv"] = self.mi.ScalarTransform3f(np.vstack([matrix, [0, 0, 1]]))
            self.loaded[key] = self.mi.load_dict(desc)
        return self.loaded[key]

    @staticmethod
    def tile(slot, values, uv_range):
        """(tiled values, first column, first row): the texels the transformed coordinates in
        uv_range reach plus one around, each axis wrapped at texel level by its own mode
        (OpenGL 4.6 sec. 8.14.2); None past MAX_TILED_TEXELS."""
        h, w = values.shape[:2]
        umin, umax, vmin, vmax = uv_range
        i0, i1 = int(math.floor(umin * w)) - 1, int(math.ceil(umax * w)) + 1
        j0, j1 = int(math.floor(vmin * h)) - 1, int(math.ceil(vmax * h)) + 1
        if (i1 - i0) * (j1 - j0) > MAX_TILED_TEXELS:
            return None

        def wrapped(i, size, mode):
            if mode == REPEAT:
                return np.mod(i, size)
            if mode == MIRRORED_REPEAT:
                m = np.mod(i, 2 * size)
                return np.where(m < size, m, 2 * size - 1 - m)
            return np.clip(i, 0, size - 1)
        cols = wrapped(np.arange(i0, i1), w, slot.wrap[0])
        rows = wrapped(np.arange(j0, j1), h, slot.wrap[1])
        return values[rows][:, cols], i0, j0

    # --- what each slot holds, as mcrt computes it before filtering ------------------------
    def color(self, slot, factor, uv_range, srgb=True):
        """RGB: decoded texels × factor (baseColor, emissive)."""
        t = self.texels(slot.image)[:, :, :3]
        values = (srgb_to_linear(t) if srgb else t) * np.asarray(factor, np.float64)
        return self.bitmap(slot, values, (slot.image, "rgb", srgb, tuple(factor)), uv_range)

    def channel(self, slot, index, factor, uv_range, square=False):
        """One linear channel × factor (metallic: B, roughness: G), squared for GGX's alpha."""
        v = self.texels(slot.image)[:, :, index:index + 1] * factor
        if square:
            v = np.maximum(v * v, 1e-3)
        return self.bitmap(slot, v, (slot.image, "channel", index, factor, square), uv_range)

    def opacity(self, slot, factor, cutoff, uv_range):
        """alpha × factor, thresholded at the cutoff for MASK (cutoff None: BLEND)."""
        a = self.texels(slot.image)[:, :, 3:4] * factor
        if cutoff is not None:
            a = (a >= cutoff).astype(np.float64)
        return self.bitmap(slot, a, (slot.image, "opacity", factor, cutoff), uv_range)

    def normal(self, slot, scale, flip_green, uv_range):
        """Tangent-space normals with normalTexture.scale on x and y, renormalized (glTF 2.0
        "Additional Textures"), back in [0, 1]; green flipped for a mirrored tangent frame."""
        n = self.texels(slot.image)[:, :, :3] * 2.0 - 1.0
        n = n * np.array([scale, -scale if flip_green else scale, 1.0])
        n = n / np.maximum(np.linalg.norm(n, axis=2, keepdims=True), 1e-12)
        return self.bitmap(slot, (n + 1.0) / 2.0, (slot.image, "normal", scale, flip_green), uv_range)

    def emission(self, emissive, le, alpha_slot, alpha_factor, cutoff, uv_range, name):
        """Radiance: Le (× decoded emissive texels) × the opacity of MASK/BLEND, the product
        baked in one texel grid (alpha_slot None: OPAQUE, or constant alpha_factor)."""
        le = np.asarray(le, np.float64)

        def weight(a):
            return (a >= cutoff).astype(np.float64) if cutoff is not None else a
        if alpha_slot is not None and emissive is not None and (
                alpha_slot.grid_key() != emissive.grid_key()
                or self.texels(alpha_slot.image).shape != self.texels(emissive.image).shape):
            warn("%s: its alpha and emissive textures do not share a texel grid: the emission "
                 "leaves alpha out" % name)
            alpha_slot = None
        base = emissive or alpha_slot
        values = np.ones(self.texels(base.image).shape[:2] + (3,)) * le
        if emissive is not None:
            values = values * srgb_to_linear(self.texels(emissive.image)[:, :, :3])
        if alpha_slot is not None:
            values = values * weight(self.texels(alpha_slot.image)[:, :, 3:4] * alpha_factor)
        else:
            values = values * weight(np.float64(alpha_factor))
        key = (base.image, "emission", tuple(le), emissive is not None,
               None if alpha_slot is None else alpha_slot.image, alpha_factor, cutoff)
        return self.bitmap(base, values, key, uv_range)


# ----- the Mitsuba scene -------------------------------------------------------------------------

def texture_slots(gltf, material, name):
    """{slot name: TextureSlot} of the texture slots mcrt reads."""
    pbr = material.get("pbrMetallicRoughness", {})
    infos = {"baseColor": pbr.get("baseColorTexture"),
             "metallicRoughness": pbr.get("metallicRoughnessTexture"),
             "normal": material.get("normalTexture"), "emissive": material.get("emissiveTexture")}
    return {k: TextureSlot(gltf, v, "%s.%sTexture" % (name, k)) for k, v in infos.items() if v}


class MaterialConversion:
    """A glTF material as Mitsuba sees it: its BSDF, its emitted radiance (None: no emitter),
    the texture-coordinate set its textures read and whether it has a normal map (its meshes
    split by tangent handedness)."""

    def __init__(self, gltf, index, materials, normal_maps):
        self.material = gltf.doc["materials"][index] if index >= 0 else {}
        self.name = self.material.get("name", "material %d" % index)
        self.albedo, self.le, self.double_sided = gltf.material(index)
        self.slots = texture_slots(gltf, self.material, self.name)
        if not normal_maps:
            self.slots.pop("normal", None)
        sets = sorted({s.texcoord for s in self.slots.values()})
        self.texcoord = self.slots["baseColor"].texcoord if "baseColor" in self.slots else \
            (sets[0] if sets else 0)
        if len(sets) > 1:
            warn("%s: its textures read TEXCOORD_%s; Mitsuba's mesh has one set: TEXCOORD_%d "
                 "for all" % (self.name, " and _".join(str(s) for s in sets), self.texcoord))
        self.materials = materials
        pbr = self.material.get("pbrMetallicRoughness", {})
        self.alpha = pbr.get("baseColorFactor", [1, 1, 1, 1])[3]
        self.alpha_mode = self.material.get("alphaMode", "OPAQUE")
        self.cutoff = self.material.get("alphaCutoff", 0.5) if self.alpha_mode == "MASK" else None
        self.interior = None  # an absorbing glass volume's medium (glass_bsdf)

    @property
    def has_normal_map(self):
        return "normal" in self.slots

    @property
    def has_alpha(self):
        return self.alpha_mode in ("MASK", "BLEND")

    @property
    def emits(self):
        return max(self.le) > 0

    def bsdf(self, textures, uv_range, handedness=1):
        """The Mitsuba BSDF (see "materials", "textures" and "alpha" above)."""
        core = self.core_bsdf(textures, uv_range)
        if self.has_normal_map:
            slot = self.slots["normal"]
            scale = self.material["normalTexture"].get("scale", 1.0)
            core = {"type": "normalmap", "bsdf": core,
                    "normalmap": textures.normal(slot, scale, handedness < 0, uv_range)}
        if self.has_alpha:
            core = {"type": "mask", "bsdf": core, "opacity": self.opacity(textures, uv_range)}
        return core

    def opacity(self, textures, uv_range):
        if "baseColor" in self.slots:
            return textures.opacity(self.slots["baseColor"], self.alpha, self.cutoff, uv_range)
        if self.cutoff is not None:
            return float(self.alpha >= self.cutoff)
        return float(self.alpha)

    def base_color(self, textures, uv_range):
        if "baseColor" in self.slots:
            return textures.color(self.slots["baseColor"], self.albedo, uv_range)
        return {"type": "rgb", "value": list(self.albedo)}

    def core_bsdf(self, textures, uv_range):
        base = self.base_color(textures, uv_range)
        diffuse = {"type": "twosided", "material": {"type": "diffuse", "reflectance": base}}
        if self.materials == "lambert":
            return diffuse
        pbr = self.material.get("pbrMetallicRoughness", {})
        metallic = pbr.get("metallicFactor", 1.0)
        roughness = pbr.get("roughnessFactor", 1.0)
        specular_ext = self.material.get("extensions", {}).get("KHR_materials_specular", {})
        specular = specular_ext.get("specularFactor", 1.0)
        transmission = self.material.get("extensions", {}).get(
            "KHR_materials_transmission", {}).get("transmissionFactor", 0.0)
        if transmission > 0.0:
            return self.glass_bsdf(base, diffuse, metallic, roughness, specular, transmission)
        if metallic == 0.0 and specular == 0.0:
            return diffuse
        mr = self.slots.get("metallicRoughness")
        if self.materials == "principled":
            if specular_ext.get("specularColorFactor", [1, 1, 1]) != [1, 1, 1]:
                warn("%s: specularColorFactor is left out of Mitsuba's principled" % self.name)
            return {"type": "twosided", "material": {
                "type": "principled", "base_color": base, "specular": 0.5 * specular,
                "metallic": textures.channel(mr, 2, metallic, uv_range) if mr else metallic,
                "roughness": textures.channel(mr, 1, roughness, uv_range) if mr else roughness}}
        all_metal = metallic == 1.0 and (mr is None or
                                         np.all(textures.texels(mr.image)[:, :, 2] == 1.0))
        if all_metal:
            if "baseColor" in self.slots or any(abs(c - 1.0) > 1e-6 for c in self.albedo):
                warn("%s: a coloured metal's Schlick Fresnel rises to 1 at grazing, Mitsuba's "
                     "constant one does not: approximate" % self.name)
            alpha = (textures.channel(mr, 1, roughness, uv_range, square=True) if mr else
                     max(roughness * roughness, 1e-3))
            return {"type": "twosided", "material": {
                "type": "roughconductor", "material": "none", "distribution": "ggx",
                "alpha": alpha, "sample_visible": True, "specular_reflectance": base}}
        what = ("its metallicRoughnessTexture mixes metal and dielectric" if metallic == 1.0
                 else "metallic %g with a specular layer" % metallic)
        raise mcrt_run.ScriptError(
            "%s: %s: glTF's dielectric (a Lambertian base under a Schlick-weighted GGX layer) has "
            "no Mitsuba 3 equivalent; use --materials lambert or the approximate --materials "
            "principled" % (self.name, what))

    def glass_bsdf(self, base, diffuse, metallic, roughness, specular, transmission):
        """mcrt's glass (docs/MATERIALS.md "Glass") as Mitsuba's `dielectric` (roughness 0:
        mcrt's pair of delta lobes) or `roughdielectric` (GGX, alpha = max(roughness^2, 1e-3),
        visible normals; both Walter et al. 2007), int_ior = KHR_materials_ior's ior, ext_ior 1,
        transmission tinted by the base colour (specular_transmittance), reflection not;
        transmissionFactor T < 1 blends it with the Lambertian base (`blendbsdf`, weight T),
        the extension's mix. Only a volume (KHR_materials_volume thicknessFactor > 0) has an
        equivalent: mcrt's thin-walled surface is one interface that light passes straight
        through, Mitsuba's `thindielectric` a slab of two. Absorption (attenuationColor at
        attenuationDistance) is the interior `homogeneous` medium of sigma_t = -ln(c)/d and
        albedo 0, Beer-Lambert as mcrt's (set_media() turns the integrator into `volpath`)."""
        ext = self.material.get("extensions", {})
        if metallic != 0.0:
            raise mcrt_run.ScriptError("%s: glass mixed with metal (metallic %g) has no Mitsuba 3 "
                                       "equivalent here" % (self.name, metallic))
        if "KHR_materials_ior" in ext:
            ior = ext["KHR_materials_ior"].get("ior", 1.5)
        else:
            ior = 1.5
        if not (1.0 <= ior <= 1e4):  # 0 is the specular-glossiness mode; below 1 mcrt warns
            raise mcrt_run.ScriptError("%s: ior %g: mcrt reads it specially (docs/MATERIALS.md "
                                       "\"Bad input\"); no conversion" % (self.name, ior))
        volume = ext.get("KHR_materials_volume", {})
        if not volume.get("thicknessFactor", 0.0) > 0.0:
            raise mcrt_run.ScriptError(
                "%s: thin-walled glass (no KHR_materials_volume thickness) is one interface in "
                "mcrt, light passing straight through; Mitsuba 3's thindielectric is a slab of "
                "two interfaces: no equivalent" % self.name)
        if "transmissionTexture" in ext.get("KHR_materials_transmission", {}):
            warn("%s: transmissionTexture is left out of the Mitsuba scene (the factor holds "
                 "everywhere there)" % self.name)
        glass = {"type": "dielectric", "int_ior": float(ior), "ext_ior": 1.0,
                 "specular_transmittance": base}
        if roughness > 0.0:
            glass = {"type": "roughdielectric", "distribution": "ggx", "int_ior": float(ior),
                     "ext_ior": 1.0, "alpha": max(roughness * roughness, 1e-3),
                     "sample_visible": True, "specular_transmittance": base}
        distance = volume.get("attenuationDistance", math.inf)
        color = volume.get("attenuationColor", [1.0, 1.0, 1.0])
        if 0.0 < distance < math.inf and any(c < 1.0 for c in color):
            sigma = [-math.log(max(min(c, 1.0), 1e-30)) / distance for c in color]
            self.interior = {"type": "homogeneous", "albedo": 0.0,
                             "sigma_t": {"type": "rgb", "value": sigma}}
        if transmission < 1.0:
            if specular != 0.0:
                raise mcrt_run.ScriptError(
                    "%s: transmissionFactor %g mixes glass with glTF's dielectric base, which has "
                    "no Mitsuba 3 equivalent (only a Lambertian base, specularFactor 0, converts)"
                    % (self.name, transmission))
            glass = {"type": "blendbsdf", "weight": float(transmission),
                     "bsdf_0": diffuse, "bsdf_1": glass}
        return glass

    def radiance(self, textures, uv_range):
        """The area emitter's radiance: a constant or a texture."""
        emissive = self.slots.get("emissive")
        alpha_slot = self.slots.get("baseColor") if self.has_alpha else None
        alpha = self.alpha if self.has_alpha else 1.0
        if emissive is None and alpha_slot is None:
            weight = float(alpha >= self.cutoff) if self.cutoff is not None else alpha
            return {"type": "rgb", "value": [c * weight for c in self.le]}
        return textures.emission(emissive, self.le, alpha_slot, alpha, self.cutoff, uv_range,
                                 self.name)


def uv_range(slots, uv):
    """(u min, u max, v min, v max) over the slots' transformed coordinates of corners uv."""
    if uv is None or not slots:
        return (0.0, 1.0, 0.0, 1.0)
    flat = uv.reshape(-1, 2)
    lo, hi = np.full(2, np.inf), np.full(2, -np.inf)
    for s in slots:
        t = flat @ s.matrix[:, :2].T + s.matrix[:, 2]
        lo, hi = np.minimum(lo, t.min(axis=0)), np.maximum(hi, t.max(axis=0))
    return (lo[0], hi[0], lo[1], hi[1])


def integrator(max_depth, rr_depth, emitter_samples=1, bsdf_samples=1, null_surfaces=False):
    """Mitsuba's integrator for mcrt's --max-depth (reflections): `direct` at 1 (emitter_samples
    light and bsdf_samples BSDF samples per pixel sample; 1 and 0 is light sampling alone), else
    `path`; with null_surfaces (MASK or BLEND materials, or an absorbing glass volume) `volpath`,
    max_depth N + 1, whose
    shadow rays pass them (its surface part is `path`'s, a null crossing not counted)."""
    if null_surfaces:
        return {"type": "volpath", "max_depth": max(max_depth, 1) + 1, "rr_depth": rr_depth,
                "hide_emitters": False}
    if max_depth <= 1:
        return {"type": "direct", "hide_emitters": False, "emitter_samples": emitter_samples,
                "bsdf_samples": bsdf_samples}
    return {"type": "path", "max_depth": max_depth + 1, "rr_depth": rr_depth,
            "hide_emitters": False}


def environment_emitter(mi, path, scale, rotate):
    """mcrt's --env FILE --env-scale S --env-rotate DEG as Mitsuba's `envmap`: the same
    latitude-longitude convention (+Y up, docs/DESIGN.md), turned about +Y by DEG. mcrt reads a
    texel's radiance as constant over it (nearest), Mitsuba's envmap interpolates bilinearly:
    the map is handed over with each texel repeated k × k times (k up to 8, the width up to
    8192), so the two differ only within half a repeated texel of each texel's edge."""
    bitmap = mi.Bitmap(str(path)).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32,
                                          srgb_gamma=False)
    texels = np.array(bitmap, dtype=np.float32)[..., :3]
    k = max(1, min(8, 8192 // max(1, texels.shape[1])))
    texels = np.repeat(np.repeat(texels, k, axis=0), k, axis=1)
    return {"type": "envmap", "bitmap": mi.Bitmap(texels), "scale": float(scale),
            "to_world": mi.ScalarTransform4f().rotate(axis=[0, 1, 0], angle=float(rotate))}


def punctual_emitters(mi, gltf):
    """KHR_lights_punctual as Mitsuba's `point`, `spot` and `directional` emitters (radiant
    intensity, and irradiance for directional, as mcrt reads them). A spot's falloff differs
    in the ring between its cones: glTF's (and mcrt's) is clamp((cos θ − cos outer) /
    (cos inner − cos outer), 0, 1)², Mitsuba's linear in the angle; they agree inside the inner
    cone and outside the outer one (a warning says so)."""
    emitters = {}
    for k, (kind, value, position, direction, inner, outer) in enumerate(gltf.punctual_lights()):
        rgb = {"type": "rgb", "value": list(value)}
        if kind == "point":
            emitters["punctual%d" % k] = {"type": "point", "position": position.tolist(),
                                          "intensity": rgb}
        elif kind == "directional":
            emitters["punctual%d" % k] = {"type": "directional", "direction": direction.tolist(),
                                          "irradiance": rgb}
        elif kind == "spot":
            warn("spot light %d: Mitsuba's falloff between the cones (%.1f° to %.1f°) is linear "
                 "in the angle, glTF's a squared ramp in cos θ: approximate there"
                 % (k, math.degrees(inner), math.degrees(outer)))
            up = [0.0, 1.0, 0.0] if abs(direction[1]) < 0.9 else [1.0, 0.0, 0.0]
            emitters["punctual%d" % k] = {
                "type": "spot", "intensity": rgb,
                "cutoff_angle": math.degrees(outer), "beam_width": math.degrees(inner),
                "to_world": mi.ScalarTransform4f().look_at(
                    origin=position.tolist(), target=(position + direction).tolist(), up=up)}
    return emitters


def mitsuba_scene(mi, gltf, width, height, spp, scratch, max_depth=1, rr_depth=5, sky=None,
                  materials="lambert", integrator_desc=None, camera=None, normal_maps=True,
                  environment=None):
    """(scene dict, emitter count) of a glTF; PLY meshes are written to `scratch`. The
    integrator is integrator_desc when given, else integrator(max_depth, rr_depth). `camera`:
    the index of the scene's camera, or (eye, target, up, vertical fov in degrees), mcrt's
    --look-from, --look-at, --up, --fov."""
    primitives = gltf.primitives()
    if not primitives:
        raise ValueError("the scene has no triangles")
    allp = np.concatenate([c.positions.reshape(-1, 3) for parts in primitives.values() for c in parts])
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    diag = float(np.linalg.norm(hi - lo))
    if camera is None or isinstance(camera, int):  # the first camera node, or glTF camera K
        eye, forward, up, yfov = gltf.camera((lo, hi), camera)
    else:
        eye, target, up, fov = (np.asarray(v, np.float64) for v in camera)
        forward, yfov = (target - eye) / np.linalg.norm(target - eye), math.radians(fov)
    conversions = {m: MaterialConversion(gltf, m, materials, normal_maps) for m in primitives}
    null_surfaces = any(c.has_alpha for c in conversions.values())
    scene = {
        "type": "scene",
        "integrator": integrator_desc or integrator(max_depth, rr_depth,
                                                    null_surfaces=null_surfaces),
        "sensor": {
            "type": "perspective", "fov_axis": "y", "fov": math.degrees(yfov),
            "near_clip": 1e-4 * diag, "far_clip": 1e3 * diag,
            "to_world": mi.ScalarTransform4f().look_at(origin=eye.tolist(),
                                                       target=(eye + forward).tolist(),
                                                       up=up.tolist()),
            "film": {"type": "hdrfilm", "width": width, "height": height,
                     "rfilter": {"type": "box"}, "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp},
        },
    }
    emitters = 0
    if sky:  # mcrt's --sky with a direct or path estimator: a uniform light at infinity
        scene["sky"] = {"type": "constant", "radiance": {"type": "rgb", "value": list(sky)}}
        emitters += 1
    if environment:  # mcrt's --env, --env-scale, --env-rotate
        scene["environment"] = environment_emitter(mi, *environment)
        emitters += 1
    punctual = punctual_emitters(mi, gltf)
    scene.update(punctual)
    emitters += len(punctual)
    textures = Textures(mi, gltf, scratch)
    for k, material in enumerate(sorted(primitives)):
        conv = conversions[material]
        parts = primitives[material]
        tri = np.concatenate([c.positions for c in parts])
        uv = None
        if conv.slots:
            missing = [c for c in parts if c.uv[conv.texcoord] is None]
            if missing:
                warn("%s: a primitive without TEXCOORD_%d reads its textures at (0, 0)"
                     % (conv.name, conv.texcoord))
            uv = np.concatenate([c.uv[conv.texcoord] if c.uv[conv.texcoord] is not None
                                 else np.zeros((len(c), 3, 2)) for c in parts])
        normals = None
        if conv.has_normal_map and all(c.normals is not None for c in parts):
            normals = np.concatenate([c.normals for c in parts])
        hand = (np.concatenate([c.handedness(conv.texcoord) for c in parts])
                if conv.has_normal_map else np.ones(len(tri), int))
        reach = uv_range(conv.slots.values(), uv)
        for sign in (1, -1):
            sel = hand == sign
            if not np.any(sel):
                continue
            bsdf = conv.bsdf(textures, reach, sign)
            radiance = conv.radiance(textures, reach) if conv.emits else None
            t = tri[sel]
            t_uv = uv[sel] if uv is not None else None
            t_n = normals[sel] if normals is not None else None
            copies = [(t, t_uv, t_n, "")]
            if radiance is not None and conv.double_sided:
                n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
                n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
                copies.append((t[:, [0, 2, 1]] - 1e-6 * diag * n[:, None, :],
                               t_uv[:, [0, 2, 1]] if t_uv is not None else None,
                               -t_n[:, [0, 2, 1]] if t_n is not None else None, "-back"))
            for pts, c_uv, c_n, suffix in copies:
                name = "mesh%d%s%s" % (k, "" if sign > 0 else "-mirrored", suffix)
                ply = Path(scratch) / (name + ".ply")
                write_ply(ply, pts, c_uv, c_n)
                shape = {"type": "ply", "filename": str(ply), "face_normals": c_n is None,
                         "bsdf": bsdf}
                if radiance is not None:
                    shape["emitter"] = {"type": "area", "radiance": radiance}
                    emitters += 1
                if conv.interior is not None:
                    shape["interior"] = conv.interior
                scene["shape" + name[4:]] = shape
    if integrator_desc is None and any(c.interior is not None for c in conversions.values()):
        # An absorbing glass volume: `volpath` attenuates the segments inside it.
        scene["integrator"] = integrator(max_depth, rr_depth, null_surfaces=True)
    return scene, emitters


def import_mitsuba(variant):
    """The mitsuba module with `variant` set."""
    # Dr.Jit's LLVM backend needs LLVM 19 (DESIGN.md "Dependencies"): Debian's libllvm19.
    if variant.startswith("llvm") and Path(DEBIAN_LLVM19).exists():
        os.environ.setdefault("DRJIT_LIBLLVM_PATH", DEBIAN_LLVM19)
    import mitsuba as mi
    mi.set_variant(variant)
    return mi


def load_scene(mi, path, width, height, spp, max_depth=1, rr_depth=5, sky=None,
               materials="lambert", integrator_desc=None, camera=None, normal_maps=True,
               info=None, environment=None):
    """(loaded Mitsuba scene, emitter count, seconds of mi.load_dict) of the glTF at `path`
    (mitsuba_scene's arguments); `info`, a dict, receives the integrator's description."""
    gltf = Gltf(path)
    with tempfile.TemporaryDirectory(prefix="mcrt-mitsuba-") as scratch:
        desc, emitters = mitsuba_scene(mi, gltf, width, height, spp, scratch, max_depth,
                                       rr_depth, sky, materials, integrator_desc, camera,
                                       normal_maps, environment)
        if info is not None:
            info["integrator"] = ", ".join("%s=%s" % kv for kv in desc["integrator"].items())
        start = time.monotonic()
        scene = mi.load_dict(desc)
        return scene, emitters, time.monotonic() - start


def render(args):
    mi = import_mitsuba(args.variant)
    passes = max(1, min(args.passes, args.spp))
    spp_pass = args.spp // passes
    described = {}
    scene, emitters, seconds_load = load_scene(mi, args.scene, args.width, args.height, spp_pass,
                                               args.max_depth, args.rr_depth, args.sky,
                                               args.materials, camera=args.camera,
                                               normal_maps=not args.no_normal_maps,
                                               info=described,
                                               environment=(args.env, args.env_scale,
                                                            args.env_rotate) if args.env else None)
    sum1 = np.zeros((args.height, args.width, 3))
    sum2 = np.zeros_like(sum1)
    seconds = []
    for p in range(passes):
        start = time.monotonic()
        image = np.array(mi.render(scene, spp=spp_pass, seed=args.seed * 100003 + p),
                         dtype=np.float64)[..., :3]
        seconds.append(time.monotonic() - start)
        sum1 += image
        sum2 += image * image
    mean = sum1 / passes
    # variance of the mean of the passes: sample variance of a pass (P − 1) / P
    variance = (np.maximum(sum2 / passes - mean ** 2, 0) * passes / max(passes - 1, 1)
                / passes if passes > 1 else np.zeros_like(mean))
    spp = spp_pass * passes
    channels = {c: mean[..., i] for i, c in enumerate("RGB")}
    channels.update({"variance." + c: variance[..., i] for i, c in enumerate("RGB")})
    write_exr(args.out, channels, float_attributes={"spp": spp})
    info = {"scene": str(args.scene), "variant": args.variant, "spp": spp, "passes": passes,
            "width": args.width, "height": args.height, "emitter_shapes": emitters,
            "integrator": described["integrator"],
            "camera": args.camera, "materials": args.materials,
            "seconds_render": sum(seconds), "seconds_first_pass": seconds[0],
            "seconds_load": seconds_load, "mitsuba_version": mi.__version__,
            "image_mean": float(mean.mean()),
            "standard_error_layer": float(np.mean(np.sqrt(variance))),
            "command": shlex.join(sys.argv)}
    Path(str(args.out) + ".json").write_text(json.dumps(info, indent=1) + "\n")
    print("mitsuba_reference: %s: %d spp in %.2f s (%s), image mean %.5g"
          % (args.out, spp, sum(seconds), args.variant, mean.mean()), file=sys.stderr)
    return mean, variance


# ----- comparison with an mcrt image ---------------------------------------------------------------

def read_hwc(path):
    """(rgb, variance or None) of an EXR as (H, W, 3) float64 arrays."""
    rgb, variance = mcrt_run.read_image_file(path)
    return (np.moveaxis(rgb, 0, -1),
            None if variance is None else np.moveaxis(variance, 0, -1))


def compare(mitsuba_rgb, mitsuba_var, mcrt_path, png_path):
    """Mean relative difference and its expected size from the two variance layers."""
    mcrt_rgb, mcrt_var = read_hwc(mcrt_path)
    if mcrt_var is None:
        raise mcrt_run.ScriptError("%s has no variance layer (an mcrt render has)" % mcrt_path)
    if mcrt_rgb.shape != mitsuba_rgb.shape:
        raise mcrt_run.ScriptError("%s is %s, the Mitsuba image %s"
                                   % (mcrt_path, mcrt_rgb.shape, mitsuba_rgb.shape))
    diff = mcrt_rgb - mitsuba_rgb
    # Combined variance, floored at float rounding (1e-5 relative): where neither image has
    # noise (a light seen directly) the two differ by a float32 rounding of L_e.
    combined = mcrt_var + mitsuba_var + (1e-5 * np.abs(mitsuba_rgb)) ** 2
    result = {
        "mcrt_image_mean": float(mcrt_rgb.mean()),
        "mitsuba_image_mean": float(mitsuba_rgb.mean()),
        # difference of the image means, relative: systematic disagreement
        "relative_difference_of_means": float(diff.mean() / mitsuba_rgb.mean()),
        # its standard error: both images' variance layers, pixels independent
        "relative_difference_of_means_stderr":
            float(math.sqrt((mcrt_var + mitsuba_var).sum()) / diff.size / mitsuba_rgb.mean()),
        # mean over pixels of |difference| / the mean image (noise included)
        "mean_abs_relative_difference": float(np.abs(diff).mean() / mitsuba_rgb.mean()),
        # per channel
        "relative_difference_per_channel":
            [float(diff[..., c].mean() / mitsuba_rgb[..., c].mean()) for c in range(3)],
        # fraction of pixel values within 3 combined standard errors
        "within_3_sigma": float(np.mean(np.abs(diff) <= 3 * np.sqrt(combined) + 1e-12)),
        # z² averaged over the values with a nonzero standard error: 1 when the difference is
        # noise as the layers predict
        "mean_z2": float(np.mean(diff[combined > 0] ** 2 / combined[combined > 0])),
    }
    if png_path:
        plt = mcrt_run.pyplot()
        ref = 0.5 * (mcrt_rgb + mitsuba_rgb)
        scale = 1.0 / max(np.percentile(ref.mean(axis=-1), 99), 1e-6)

        def srgb(x):
            x = np.clip(x * scale, 0, 1)
            return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)
        z = diff.mean(axis=-1) / np.sqrt(np.maximum(combined.mean(axis=-1) / 3, 1e-30))
        h, w = ref.shape[:2]
        fig, axes = plt.subplots(1, 3, figsize=(9.0, 3.0 * h / w + 0.6), dpi=100)
        axes[0].imshow(srgb(mcrt_rgb), interpolation="nearest")
        axes[0].set_title("mcrt", fontsize=8)
        axes[1].imshow(srgb(mitsuba_rgb), interpolation="nearest")
        axes[1].set_title("Mitsuba 3", fontsize=8)
        im = axes[2].imshow(z, cmap="RdBu_r", vmin=-4, vmax=4, interpolation="nearest")
        axes[2].set_title("(mcrt − Mitsuba) / combined σ, mean of RGB", fontsize=8)
        fig.colorbar(im, ax=axes[2], fraction=0.046, pad=0.02).ax.tick_params(labelsize=6)
        for ax in axes:
            ax.set_xticks([])
            ax.set_yticks([])
        fig.suptitle("relative difference of image means %.3f%% ± %.3f%%, mean z² %.2f" % (
            100 * result["relative_difference_of_means"],
            100 * result["relative_difference_of_means_stderr"], result["mean_z2"]), fontsize=8)
        fig.tight_layout()
        mcrt_run.save_png(fig, png_path)
        plt.close(fig)
    return result


def camera_arguments(camera):
    """mcrt's options for the camera of mitsuba_scene."""
    if camera is None:
        return []
    if isinstance(camera, int):
        return ["--camera", str(camera)]
    eye, target, up, fov = camera
    return ["--look-from", ",".join(map(repr, eye)), "--look-at", ",".join(map(repr, target)),
            "--up", ",".join(map(repr, up)), "--fov", repr(fov)]


def equal_time(args, mitsuba_rgb):
    """mcrt (each --mcrt-args) for the seconds Mitsuba took; the RMSEs against the reference."""
    info = json.loads(Path(str(args.out) + ".json").read_text())
    seconds = info["seconds_render"]
    ref, ref_variance = read_hwc(args.equal_time)
    floor = math.sqrt(float(np.mean(ref_variance))) if ref_variance is not None else 0.0
    rmse = lambda x: math.sqrt(float(np.mean((x - ref) ** 2)))  # noqa: E731
    result = {"reference": str(args.equal_time), "reference_rmse_floor_layer": floor,
              "mitsuba": {"variant": args.variant, "spp": info["spp"], "seconds": seconds,
                          "rmse": rmse(mitsuba_rgb)}, "mcrt": []}
    for options in args.mcrt_args or ["--estimator mis --sampler sobol --light-select power"]:
        with tempfile.TemporaryDirectory(prefix="mcrt-equal-time-") as scratch:
            r = mcrt_run.render(args.scene, Path(scratch) / "m", [
                "--width", args.width, "--height", args.height, "--spp", "16777216",
                "--time-limit", repr(seconds), "--seed", args.seed + 17,
                "--materials", "gltf" if args.materials == "principled" else args.materials]
                + camera_arguments(args.camera) + shlex.split(options),
                mcrt=args.mcrt)
        result["mcrt"].append({"options": options, "spp": r.stats["spp"],
                               "seconds_render": r.stats["seconds_render"],
                               "seconds_total": r.stats["seconds_total"],
                               "wall_seconds": r.wall_seconds,
                               "rmse": rmse(np.moveaxis(r.rgb, 0, -1))})
    return result


def use_mitsuba_venv(script=__file__):
    """Re-executes `script` (this one by default) with a repository venv's Python, with the
    same arguments, when mitsuba is not importable."""
    if importlib.util.find_spec("mitsuba") is not None:
        return
    root = mcrt_run.ROOT
    for venv in (".venv-mitsuba", ".venv"):
        python = root / venv / "bin" / "python"
        if python.exists() and Path(sys.prefix).resolve() != (root / venv).resolve():
            os.execv(str(python), [str(python), str(Path(script).resolve())] + sys.argv[1:])
    raise mcrt_run.ScriptError("Mitsuba 3 is not installed (see --help)")


def vector(text):
    """X,Y,Z as three floats."""
    v = [float(x) for x in text.split(",")]
    if len(v) != 3 or not all(math.isfinite(x) for x in v):
        raise argparse.ArgumentTypeError("%r is not X,Y,Z" % text)
    return v


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog=__doc__.split("\n\n", 1)[1])
    p.add_argument("scene")
    p.add_argument("--spp", type=int, default=256)
    p.add_argument("--width", type=int, default=512)
    p.add_argument("--height", type=int, default=512)
    p.add_argument("--out", required=True, help="output EXR (a JSON is written beside it)")
    p.add_argument("--variant", default="scalar_rgb", help="scalar_rgb or llvm_ad_rgb")
    p.add_argument("--passes", type=int, default=16,
                   help="passes with different seeds; their spread gives the variance layer")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--materials", choices=["lambert", "gltf", "principled"], default="lambert",
                   help="how surfaces are converted (see materials above; default lambert)")
    p.add_argument("--camera", type=int,
                   help="glTF camera K, as mcrt's --camera (default: the first camera node)")
    p.add_argument("--look-from", type=vector, help="X,Y,Z: replaces the scene's camera, as mcrt's")
    p.add_argument("--look-at", type=vector,
                   help="X,Y,Z (with --look-from; --look-at=-1,2,3 where X is negative)")
    p.add_argument("--up", type=vector, default=[0.0, 1.0, 0.0], help="X,Y,Z (default 0,1,0)")
    p.add_argument("--fov", type=float, default=45.0,
                   help="vertical field of view in degrees with --look-from (default 45)")
    p.add_argument("--no-normal-maps", action="store_true",
                   help="leave normal textures out (shade with the geometric normal)")
    p.add_argument("--max-depth", type=int, default=1,
                   help="reflections, as mcrt's --max-depth: 1 is `direct`, N > 1 `path` with "
                   "max_depth N + 1")
    p.add_argument("--rr-depth", type=int, default=5, help="with --max-depth > 1: `path`'s rr_depth")
    p.add_argument("--sky", type=lambda t: [float(x) for x in (t.split(",") * 3)[:3]],
                   help="R,G,B (or one value): a `constant` emitter, as mcrt's --sky light")
    p.add_argument("--env", help="an environment map (.exr, .hdr), as mcrt's --env: `envmap`")
    p.add_argument("--env-scale", type=float, default=1.0, help="as mcrt's --env-scale")
    p.add_argument("--env-rotate", type=float, default=0.0,
                   help="degrees about +Y, as mcrt's --env-rotate")
    p.add_argument("--compare", help="an mcrt EXR of the same size to compare with")
    p.add_argument("--diff-png", help="with --compare: write the difference image here")
    p.add_argument("--equal-time", metavar="REF.exr",
                   help="also render with mcrt for Mitsuba's time and compare both with REF.exr")
    mcrt_run.add_mcrt_option(p)
    p.add_argument("--mcrt-args", action="append",
                   help="mcrt render options for --equal-time, repeatable (default: --estimator "
                   "mis --sampler sobol --light-select power)")
    args = p.parse_args()
    if (args.look_from is None) != (args.look_at is None):
        p.error("--look-from and --look-at go together")
    if args.env and args.sky:
        p.error("--env and --sky exclude each other, as in mcrt")
    if args.look_from is not None:
        args.camera = (args.look_from, args.look_at, args.up, args.fov)
    use_mitsuba_venv()
    if args.diff_png and importlib.util.find_spec("matplotlib") is None:
        # checked before the render, not re-executed after it: this Python is Mitsuba's
        raise mcrt_run.ScriptError("--diff-png needs matplotlib in %s (a venv made with "
                                   "--system-site-packages has Debian's)" % sys.executable)
    try:
        rgb, variance = render(args)
    except (OSError, ValueError) as e:  # an unreadable scene, an unsupported accessor
        raise mcrt_run.ScriptError("%s: %s" % (args.scene, e))
    if args.compare:
        result = compare(rgb, variance, args.compare, args.diff_png)
        print(json.dumps(result, indent=1))
    if args.equal_time:
        print(json.dumps(equal_time(args, rgb), indent=1))


if __name__ == "__main__":
    sys.exit(mcrt_run.script_main(main))

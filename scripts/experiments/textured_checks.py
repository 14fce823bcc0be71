#!/usr/bin/python3
"""The Khronos feature-test models of ../shared/scenes/textured checked against their own
expectations (each model's README.md), from pixel values of mcrt renders (docs/EXPERIMENTS.md,
"Textured scenes").

Each check renders the model from a frontal view (MultiUVTest: its own camera) in one of four
modes, chosen so that the quantity the test is about is exact or nearly so:

  albedo     `ambient-cosine` with --ao-distance 1e-6 under --sky 1: every direction counts as
             open, so a pixel is L_e + baseColor (texture × factor) averaged over the pixel;
             minus the emission image it is the base colour alone, without noise;
  emission   --max-depth 0: L_e at the first hit, exact (emissive texture, strength, alpha);
  lit        a copy of the glTF with an emissive quad added above, left of and in front of the
             board (and no sky), `mis` direct light: shading that shows a normal's direction;
  sky        the glTF materials under a uniform sky, `mis`, with the variance layer.

A copy of a glTF (a light added, nodes left out, materials made emissive) is written to a
temporary folder beside symbolic links to the model's buffers and images.

The pixels of each part of a model are found by casting the camera's pixel-centre rays at the
model's triangles here (scripts/tools/mitsuba_reference.py reads the glTF), which also gives the
texture coordinates under each pixel; one pixel is eroded from every region's edge. Where a test
names what a failure looks like (a texture transform ignored or reversed, v flipped, the wrong
texture-coordinate set, a cutoff not respected), the render is compared with the image each
outcome predicts: the texture sampled here at the pixel centres (bilinear, the sampler's wrap
modes, sRGB decoded), and passes when it is near the correct prediction and far from the others.

Prints one table row per check with its numbers and PASS or FAIL, and a summary.

Usage: scripts/experiments/textured_checks.py [--scenes DIR] [--only A,B] [--spp 64] [--mcrt BIN]
"""

import argparse
import base64
import contextlib
import copy
import json
import math
import os
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))  # mcrt_run, mcrt_exr
import mcrt_run  # noqa: E402

mcrt_run.require("numpy")
import numpy as np  # noqa: E402

import mitsuba_reference as gltf_reader  # noqa: E402  the glTF reader (no Mitsuba needed)

ROOT = mcrt_run.ROOT
DEFAULT_SCENES = ROOT.parent / "shared" / "scenes" / "textured"
REPEAT, CLAMP_TO_EDGE, MIRRORED_REPEAT = 10497, 33071, 33648


# ----- the camera and the pixels' rays ---------------------------------------------------------

class Camera:
    """mcrt's camera contract (docs/DESIGN.md): eye, right, up, forward, vertical fov."""

    def __init__(self, eye, forward, up_hint, yfov, width, height):
        self.eye = np.asarray(eye, np.float64)
        self.forward = np.asarray(forward, np.float64) / np.linalg.norm(forward)
        self.right = np.cross(self.forward, up_hint)
        self.right /= np.linalg.norm(self.right)
        self.up = np.cross(self.right, self.forward)
        self.tan = math.tan(yfov / 2)
        self.width, self.height = width, height
        self.aspect = width / height

    @staticmethod
    def front(x, y, distance, fov, width, height):
        """From (x, y, distance) toward (x, y, 0): a board in the XY plane facing +Z."""
        return Camera((x, y, distance), (0, 0, -1), (0, 1, 0), math.radians(fov), width, height)

    def options(self):
        target = self.eye + self.forward
        return ["--look-from", ",".join(repr(float(v)) for v in self.eye),
                "--look-at=" + ",".join(repr(float(v)) for v in target),
                "--up", ",".join(repr(float(v)) for v in self.up),
                "--fov", repr(math.degrees(2 * math.atan(self.tan))),
                "--width", self.width, "--height", self.height]

    def project(self, points):
        """World points (..., 3) → continuous pixel coordinates (..., 2) and camera depth."""
        d = points - self.eye
        z = d @ self.forward
        x = (d @ self.right) / (z * self.tan * self.aspect)
        y = (d @ self.up) / (z * self.tan)
        return np.stack([(x + 1) / 2 * self.width, (1 - y) / 2 * self.height], -1), z

    def rays(self, px, py):
        """Directions through continuous pixel coordinates."""
        x = (2 * px / self.width - 1) * self.tan * self.aspect
        y = (1 - 2 * py / self.height) * self.tan
        d = x[..., None] * self.right + y[..., None] * self.up + self.forward
        return d / np.linalg.norm(d, axis=-1, keepdims=True)


class Hits:
    """The first triangle under each of `s` × `s` points per pixel (sub-pixel centres; s = 1:
    the pixel centre): triangle index (−1: none), its material, its barycentric coordinates, and
    from them the point and texture coordinates, at s times the camera's resolution; down()
    averages such an image over each pixel, as a pixel's samples are averaged. `mat` is per
    pixel: the material of every point of the pixel, else −3."""

    def __init__(self, gltf, camera, s=1):
        self.s, self.pixel_camera = s, camera
        camera = copy.copy(camera)
        camera.width, camera.height = camera.width * s, camera.height * s
        parts = [(m, c) for m, cs in gltf.primitives().items() for c in cs]
        self.tri = np.concatenate([c.positions for _, c in parts])
        self.material = np.concatenate([np.full(len(c), m) for m, c in parts])
        self.uv = [np.concatenate([c.uv[k] if c.uv[k] is not None
                                   else np.full((len(c), 3, 2), np.nan) for _, c in parts])
                   for k in (0, 1)]
        w, h = camera.width, camera.height
        self.camera = camera
        self.index = np.full((h, w), -1)
        self.t = np.full((h, w), np.inf)
        self.b = np.zeros((h, w, 2))
        screen, depth = camera.project(self.tri)
        for k in range(len(self.tri)):
            if np.all(depth[k] > 0):
                x0, y0 = np.floor(screen[k].min(0) - 1).astype(int)
                x1, y1 = np.ceil(screen[k].max(0) + 1).astype(int)
                x0, y0, x1, y1 = max(x0, 0), max(y0, 0), min(x1, w), min(y1, h)
                if x0 >= x1 or y0 >= y1:
                    continue
            elif np.all(depth[k] <= 0):
                continue
            else:
                x0, y0, x1, y1 = 0, 0, w, h
            py, px = np.mgrid[y0:y1, x0:x1] + 0.5
            d = camera.rays(px, py)
            # Möller–Trumbore
            p0, p1, p2 = self.tri[k]
            e1, e2 = p1 - p0, p2 - p0
            pvec = np.cross(d, e2)
            det = pvec @ e1
            ok = np.abs(det) > 1e-14
            inv = np.where(ok, 1 / np.where(ok, det, 1), 0)
            o = camera.eye - p0
            u = (pvec @ o) * inv
            q = np.cross(o, e1)
            v = (q * d).sum(-1) * inv
            t = (q @ e2) * inv
            hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0)
            region = self.t[y0:y1, x0:x1]
            closer = hit & (t < region)
            region[closer] = t[closer]
            self.index[y0:y1, x0:x1][closer] = k
            self.b[y0:y1, x0:x1][closer] = np.stack([u, v], -1)[closer]
        safe = np.maximum(self.index, 0)
        self._safe = safe
        fine = np.where(self.index >= 0, self.material[safe], -2)
        blocks = fine.reshape(camera.height // s, s, camera.width // s, s)
        first = blocks[:, :1, :, :1]
        self.mat = np.where(np.all(blocks == first, axis=(1, 3)), first[:, 0, :, 0], -3)

    def down(self, image):
        """An image at the points' resolution averaged over each pixel."""
        if self.s == 1:
            return image
        h, w = image.shape[0] // self.s, image.shape[1] // self.s
        return image.reshape((h, self.s, w, self.s) + image.shape[2:]).mean(axis=(1, 3))

    def interpolate(self, corners):
        """Per-corner values (n, 3, k) → (H, W, k) at the hits."""
        c = corners[self._safe]
        u, v = self.b[..., 0:1], self.b[..., 1:2]
        return (1 - u - v) * c[..., 0, :] + u * c[..., 1, :] + v * c[..., 2, :]

    def texcoord(self, k):
        return self.interpolate(self.uv[k])

    def point(self):
        return self.interpolate(self.tri)

    def geometric_normal(self):
        e1 = self.tri[:, 1] - self.tri[:, 0]
        e2 = self.tri[:, 2] - self.tri[:, 0]
        n = np.cross(e1, e2)
        n /= np.maximum(np.linalg.norm(n, axis=-1, keepdims=True), 1e-30)
        return n[self._safe]

    def mask(self, materials, erode=1, where=None):
        """Pixels whose hit has one of `materials`, shrunk by `erode` pixels (8-neighbourhood)."""
        m = np.isin(self.mat, list(np.atleast_1d(materials)))
        if where is not None:
            m &= where
        return erode_mask(m, erode)


def erode_mask(m, n):
    for _ in range(n):
        p = np.pad(m, 1)
        m = m & p[:-2, 1:-1] & p[2:, 1:-1] & p[1:-1, :-2] & p[1:-1, 2:] \
            & p[:-2, :-2] & p[:-2, 2:] & p[2:, :-2] & p[2:, 2:]
    return m


def dilate_mask(m, n):
    for _ in range(n):
        p = np.pad(m, 1)
        m = m | p[:-2, 1:-1] | p[2:, 1:-1] | p[1:-1, :-2] | p[1:-1, 2:]
    return m


def components(mask, min_pixels=20):
    """4-connected components of a mask, as lists of (row, column) index arrays."""
    seen = np.zeros_like(mask, bool)
    h, w = mask.shape
    out = []
    for y0, x0 in zip(*np.nonzero(mask)):
        if seen[y0, x0]:
            continue
        stack, pixels = [(y0, x0)], []
        seen[y0, x0] = True
        while stack:
            y, x = stack.pop()
            pixels.append((y, x))
            for yy, xx in ((y - 1, x), (y + 1, x), (y, x - 1), (y, x + 1)):
                if 0 <= yy < h and 0 <= xx < w and mask[yy, xx] and not seen[yy, xx]:
                    seen[yy, xx] = True
                    stack.append((yy, xx))
        if len(pixels) >= min_pixels:
            out.append(tuple(np.array(pixels).T))
    return out


# ----- textures as the glTF says they are read -------------------------------------------------

class Texture:
    """A texture slot's image as linear values (H, W, 4) and its sampler; sample(uv) reads it
    bilinearly between texel centres (or NEAREST) after decoding, with the wrap modes per axis
    applied to texel indices (OpenGL 4.6 sec. 8.14.2)."""

    def __init__(self, gltf, info, srgb, where=""):
        from PIL import Image
        import io
        self.slot = gltf_reader.TextureSlot(gltf, info, where)
        data, _ = gltf.image(self.slot.image)
        image = np.asarray(Image.open(io.BytesIO(data)).convert("RGBA"), np.float64) / 255
        if srgb:
            image[..., :3] = gltf_reader.srgb_to_linear(image[..., :3])
        self.image = image

    @staticmethod
    def wrap(i, size, mode):
        if mode == CLAMP_TO_EDGE:
            return np.clip(i, 0, size - 1)
        if mode == MIRRORED_REPEAT:
            k = np.mod(i, 2 * size)
            return np.where(k < size, k, 2 * size - 1 - k)
        return np.mod(i, size)

    def sample(self, uv, matrix=None):
        m = self.slot.matrix if matrix is None else matrix
        u = m[0, 0] * uv[..., 0] + m[0, 1] * uv[..., 1] + m[0, 2]
        v = m[1, 0] * uv[..., 0] + m[1, 1] * uv[..., 1] + m[1, 2]
        h, w = self.image.shape[:2]
        ws, wt = self.slot.wrap
        ok = np.isfinite(u) & np.isfinite(v)
        u, v = np.where(ok, u, 0), np.where(ok, v, 0)
        if self.slot.nearest:
            i = self.wrap(np.floor(u * w).astype(int), w, ws)
            j = self.wrap(np.floor(v * h).astype(int), h, wt)
            return self.image[j, i]
        x, y = u * w - 0.5, v * h - 0.5
        i0, j0 = np.floor(x).astype(int), np.floor(y).astype(int)
        fx, fy = (x - i0)[..., None], (y - j0)[..., None]
        i1, j1 = self.wrap(i0 + 1, w, ws), self.wrap(j0 + 1, h, wt)
        i0, j0 = self.wrap(i0, w, ws), self.wrap(j0, h, wt)
        return ((1 - fx) * (1 - fy) * self.image[j0, i0] + fx * (1 - fy) * self.image[j0, i1]
                + (1 - fx) * fy * self.image[j1, i0] + fx * fy * self.image[j1, i1])


def transform_matrix(offset=(0.0, 0.0), rotation=0.0, scale=(1.0, 1.0)):
    """KHR_texture_transform's T·R·S as a 2 × 3 matrix (as TextureSlot builds it)."""
    c, s = math.cos(rotation), math.sin(rotation)
    return np.array([[c * scale[0], s * scale[1], offset[0]],
                     [-s * scale[0], c * scale[1], offset[1]]])


# ----- renders ---------------------------------------------------------------------------------

class Renderer:
    def __init__(self, args, scratch):
        self.args, self.scratch, self.count = args, Path(scratch), 0

    def run(self, gltf_path, camera, options, spp=None):
        self.count += 1
        stem = self.scratch / ("r%d" % self.count)
        r = mcrt_run.render(gltf_path, stem, camera.options() + [
            "--spp", spp or self.args.spp, "--seed", self.args.seed] + options, mcrt=self.args.mcrt)
        return np.moveaxis(r.rgb, 0, -1), np.moveaxis(r.variance, 0, -1)

    def emission(self, path, camera):
        return self.run(path, camera, ["--max-depth", 0, "--estimator", "mis"], spp=16)[0]

    def albedo(self, path, camera, emission=None):
        """baseColor under each pixel: the ambient image with every direction open, less L_e."""
        rgb = self.run(path, camera, ["--estimator", "ambient-cosine", "--ao-distance", "1e-6",
                                      "--sky", 1], spp=16)[0]
        return rgb - (emission if emission is not None else self.emission(path, camera))

    def lit(self, path, camera, materials="lambert", sky=None, spp=None):
        options = ["--estimator", "mis", "--materials", materials]
        if sky:
            options += ["--sky", sky]
        return self.run(path, camera, options, spp)

    def sky(self, path, camera, depth=1, spp=None):
        return self.run(path, camera, ["--estimator", "mis", "--sky", 1, "--max-depth", depth], spp)


@contextlib.contextmanager
def edited(gltf_path, edit):
    """A copy of the glTF changed by edit(doc) in a temporary folder, beside links to the
    model's files; yields its path."""
    src = Path(gltf_path)
    with tempfile.TemporaryDirectory(prefix="mcrt-checks-") as folder:
        for f in src.parent.iterdir():
            if f.is_file() and f.suffix != ".gltf":
                os.symlink(f, Path(folder) / f.name)
        doc = json.loads(src.read_text())
        edit(doc)
        out = Path(folder) / src.name
        out.write_text(json.dumps(doc))
        yield out


def add_light(doc, corner, edge_u, edge_v, radiance):
    """Adds an emissive, double-sided quad corner + [0, 1] edge_u + [0, 1] edge_v to the default
    scene (its own buffer, a data URI)."""
    corner, edge_u, edge_v = (np.asarray(v, np.float32) for v in (corner, edge_u, edge_v))
    positions = np.array([corner, corner + edge_u, corner + edge_u + edge_v, corner + edge_v],
                         np.float32)
    indices = np.array([0, 1, 2, 0, 2, 3], np.uint16)
    data = positions.tobytes() + indices.tobytes()
    buffer = len(doc.setdefault("buffers", []))
    doc["buffers"].append({"byteLength": len(data), "uri": "data:application/octet-stream;base64,"
                           + base64.b64encode(data).decode()})
    views = doc.setdefault("bufferViews", [])
    views += [{"buffer": buffer, "byteOffset": 0, "byteLength": 48},
              {"buffer": buffer, "byteOffset": 48, "byteLength": 12}]
    accessors = doc.setdefault("accessors", [])
    accessors += [{"bufferView": len(views) - 2, "componentType": 5126, "count": 4, "type": "VEC3",
                   "min": positions.min(0).tolist(), "max": positions.max(0).tolist()},
                  {"bufferView": len(views) - 1, "componentType": 5123, "count": 6,
                   "type": "SCALAR"}]
    materials = doc.setdefault("materials", [])
    materials.append({"name": "AddedLight", "emissiveFactor": [1, 1, 1], "doubleSided": True,
                      "extensions": {"KHR_materials_emissive_strength":
                                     {"emissiveStrength": radiance}},
                      "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]}})
    doc.setdefault("extensionsUsed", []).append("KHR_materials_emissive_strength")
    meshes = doc.setdefault("meshes", [])
    meshes.append({"primitives": [{"attributes": {"POSITION": len(accessors) - 2},
                                   "indices": len(accessors) - 1,
                                   "material": len(materials) - 1}]})
    doc["nodes"].append({"mesh": len(meshes) - 1})
    doc["scenes"][doc.get("scene", 0)]["nodes"].append(len(doc["nodes"]) - 1)


def light_upper_left(doc, centre, distance, size, radiance):
    """A square light of side `size` centred at `centre` + distance × (−1, 1, 1.5)/|·|, facing
    the centre (its orientation does not matter: double-sided)."""
    c = np.asarray(centre, np.float64)
    d = np.array([-1.0, 1.0, 1.5]) / np.linalg.norm([-1.0, 1.0, 1.5])
    p = c + distance * d
    u = np.cross(d, [0, 1, 0])
    u /= np.linalg.norm(u)
    v = np.cross(u, d)
    add_light(doc, p - 0.5 * size * (u + v), size * u, size * v, radiance)
    return p


# ----- results ---------------------------------------------------------------------------------

class Results:
    def __init__(self):
        self.rows = []

    def add(self, scene, check, numbers, passed):
        self.rows.append((scene, check, numbers, passed))
        print("| %s | %s | %s | %s |" % (scene, check, numbers,
                                         {True: "PASS", False: "FAIL", None: "—"}[passed]),
              flush=True)


def mean(image, mask):
    return image[mask].mean(axis=0)


def outcomes(render, predictions, correct, mask, factor=3.0, limit=0.05):
    """The render against the image each outcome predicts, over the pixels of `mask` where that
    outcome and the correct one differ (by more than 0.1 in a channel): (text, verdict). Passes
    when, for every other outcome, the render's mean abs. error there against the correct
    prediction is below `limit` and `factor` times below its error against the other one."""
    good = predictions[correct][..., :3]
    parts, ok = [], True
    for name, prediction in predictions.items():
        if name == correct:
            continue
        differ = mask & (np.abs(prediction[..., :3] - good).max(axis=-1) > 0.1)
        if not differ.any():
            parts.append("%s: same image" % name)
            continue
        e_good = float(np.abs(render[differ][:, :3] - good[differ]).mean())
        e_other = float(np.abs(render[differ][:, :3] - prediction[differ][:, :3]).mean())
        parts.append("%s (%d px differ): %.3f against %.3f" % (name, differ.sum(), e_good, e_other))
        ok &= e_good < limit and e_good * factor < e_other
    return "; ".join(parts), ok


def luminance(rgb):
    return rgb[..., 0] * 0.2126 + rgb[..., 1] * 0.7152 + rgb[..., 2] * 0.0722


# ----- the checks ------------------------------------------------------------------------------

def check_texture_transform(path, gltf, r, res):
    """Top row: the offset tiles show the quadrant the offset selects, not the yellow one of no
    transform. Bottom row: each arrow ends on its green marker, not at the yellow (transform
    ignored) or red (rotation reversed) one."""
    cam = Camera.front(0, 0, 3.2, 44, 320, 240)
    hits = Hits(gltf, cam, s=4)
    albedo = r.albedo(path, cam)
    mats = gltf.doc["materials"]
    uv = hits.texcoord(0)
    for m in range(6):
        info = mats[m]["pbrMetallicRoughness"]["baseColorTexture"]
        tex = Texture(gltf, info, srgb=True)
        t = info["extensions"]["KHR_texture_transform"]
        mask = hits.mask(m, erode=2)
        matrices = {"as specified": None, "ignored": transform_matrix()}
        if "rotation" in t:
            matrices["rotation reversed"] = transform_matrix(
                t.get("offset", (0, 0)), -t["rotation"], t.get("scale", (1, 1)))
        predicted = {k: hits.down(tex.sample(uv, mx)) for k, mx in matrices.items()}
        text, ok = outcomes(albedo, predicted, "as specified", mask)
        res.add("TextureTransformTest", "%s tile: albedo error, transform as specified against"
                % mats[m]["name"], text, ok)
    # Where each arrow points: its axis (the principal axis of its black texels, albedo
    # luminance below 0.25) and, per marker (the tiles' children, unit squares scaled), the
    # marker centre's distance from that line and the gap between the marker and the arrow, in
    # tile widths (a tile is 1 × 1). The arrow points at the marker on its line nearest to it.
    dark = luminance(albedo) < 0.25
    pixels_per_unit = cam.project(np.array([1.0, 0, 0]))[0][0] - cam.project(np.zeros(3))[0][0]
    marker_kind = {6: "green", 7: "yellow", 8: "red"}
    for tile in ("Rotation", "Scale", "All"):
        m_tile = next(k for k, m in enumerate(mats) if m["name"] == tile)
        node = next(n for n in gltf.doc["nodes"] if n.get("name") == tile)
        ys, xs = np.nonzero(dark & hits.mask(m_tile, erode=0))
        points = np.stack([xs + 0.5, ys + 0.5], -1)
        centroid = points.mean(axis=0)
        axis = np.linalg.svd(points - centroid, full_matrices=False)[2][0]
        found = []
        for child in node.get("children", []):
            cn = gltf.doc["nodes"][child]
            kind = gltf.doc["meshes"][cn["mesh"]]["primitives"][0]["material"]
            centre = np.array(node["translation"]) + np.array(cn["translation"])
            half = 0.5 * cn["scale"][0]
            (x0, y1), _ = cam.project(centre - [half, half, 0])
            (x1, y0), _ = cam.project(centre + [half, half, 0])
            c = np.array([(x0 + x1) / 2, (y0 + y1) / 2]) - centroid
            off_line = abs(c[0] * axis[1] - c[1] * axis[0]) / pixels_per_unit
            gx = np.maximum(0, np.maximum(x0 - points[:, 0], points[:, 0] - x1))
            gy = np.maximum(0, np.maximum(y0 - points[:, 1], points[:, 1] - y1))
            gap = float(np.hypot(gx, gy).min()) / pixels_per_unit
            found.append((marker_kind[kind], off_line, gap))
        green = next(f for f in found if f[0] == "green")
        ok = green[1] < 0.05 and green[2] < 0.1 and all(
            f[1] > 2 * green[1] + 0.05 or f[2] > 2 * green[2] + 0.1
            for f in found if f is not green)
        res.add("TextureTransformTest", "%s: each marker's distance from the arrow's line, and "
                "gap to the arrow (tile widths)" % tile,
                ", ".join("%s %.3f, %.3f" % f for f in found), ok)


def check_texture_coordinate(path, gltf, r, res):
    """Each quad shows its corner of the template (labels in the right corners): the texture as
    read with uv (0, 0) at the image's top left, not flipped in v or u."""
    cam = Camera.front(0, 0, 4.4, 35, 256, 256)
    hits = Hits(gltf, cam, s=4)
    albedo = r.albedo(path, cam)
    uv = hits.texcoord(0)
    for m in (3, 4, 1, 2):
        mat = gltf.doc["materials"][m]
        pbr = mat["pbrMetallicRoughness"]
        tex = Texture(gltf, pbr["baseColorTexture"], srgb=True)
        factor = np.array(pbr["baseColorFactor"][:3])
        mask = hits.mask(m, erode=2)
        flips = {"as read": uv, "v flipped": np.stack([uv[..., 0], 1 - uv[..., 1]], -1),
                 "u flipped": np.stack([1 - uv[..., 0], uv[..., 1]], -1)}
        text, ok = outcomes(albedo, {k: hits.down(tex.sample(f)[..., :3]) * factor
                                      for k, f in flips.items()},
                            "as read", mask)
        res.add("TextureCoordinateTest", "%s: albedo error, texture as read against" % mat["name"],
                text, ok)


def quads(corners):
    """Triangles of one material grouped into rectangles by their x centroid (the boards' test
    and sample boxes), as (min, max) world corners, left to right."""
    c = corners.mean(axis=1)
    order = np.argsort(c[:, 0])
    groups, current = [], [order[0]]
    for k in order[1:]:
        if c[k, 0] - c[current[-1], 0] > 1.0:
            groups.append(current)
            current = [k]
        else:
            current.append(k)
    groups.append(current)
    return [(corners[g].reshape(-1, 3).min(0), corners[g].reshape(-1, 3).max(0)) for g in groups]


def box_mask(cam, lo, hi, shrink=2):
    """The pixels of a box's front view (its back plane, z = lo), `shrink` pixels inside it."""
    (x0, y1), _ = cam.project(np.array([lo[0], lo[1], lo[2]]))
    (x1, y0), _ = cam.project(np.array([hi[0], hi[1], lo[2]]))
    yy, xx = np.mgrid[0:cam.height, 0:cam.width] + 0.5
    return (xx > x0 + shrink) & (xx < x1 - shrink) & (yy > y0 + shrink) & (yy < y1 - shrink), \
        (x0, y0, x1, y1)


def pixels_per_unit_camera(x, y, distance, pixels_per_unit, width, height):
    """A frontal view whose scale at the board (z = 0) is `pixels_per_unit`: boxes a whole
    number of pixels apart are compared pixel for pixel."""
    fov = math.degrees(2 * math.atan(height / 2 / (pixels_per_unit * distance)))
    return Camera.front(x, y, distance, fov, width, height)


def shifted_difference(image, cam, box_a, box_b, shrink=2, variance=None, search=2):
    """Mean abs. difference between two equal boxes of a frontal board: box_a's pixels against
    box_b's at the same place relative to the box (the views below make the boxes a whole
    number of pixels apart), at the shift within ±`search` pixels of that where they agree best
    (a test's tiles may place their pattern a texel apart); the std of box_b's pixels (its
    contrast, less the noise); what the noise of two independent pixels alone gives,
    E|a − b| = √(2/π (σ_a² + σ_b²)), from the variance layer; and the extra shift."""
    mask, (ax0, ay0, _, _) = box_mask(cam, *box_a, shrink + search)
    _, (bx0, by0, _, _) = box_mask(cam, *box_b, shrink)
    ys, xs = np.nonzero(mask)
    best = None
    for ey in range(-search, search + 1):
        for ex in range(-search, search + 1):
            dx, dy = int(round(bx0 - ax0)) + ex, int(round(by0 - ay0)) + ey
            a = image[ys, xs, :3]
            b = image[ys + dy, xs + dx, :3]
            d = float(np.abs(a - b).mean())
            if best is None or d < best[0]:
                best = (d, dx, dy, (ex, ey))
    d, dx, dy, extra = best
    b = image[ys + dy, xs + dx, :3]
    noise, contrast2 = 0.0, float(b.var())
    if variance is not None:
        va, vb = variance[ys, xs, :3], variance[ys + dy, xs + dx, :3]
        noise = float(np.sqrt(2 / math.pi * (va + vb)).mean())
        contrast2 -= float(vb.mean())
    return d, math.sqrt(max(contrast2, 0.0)), extra, noise


def colour_shares(image, mask):
    """Shares of clearly green and clearly red pixels in a region (albedo)."""
    p = image[mask][:, :3]
    green = (p[:, 1] > p[:, 0] + 0.15) & (p[:, 1] > p[:, 2] + 0.15)
    red = (p[:, 0] > p[:, 1] + 0.15) & (p[:, 0] > p[:, 2] + 0.15)
    return float(green.mean()), float(red.mean())


def check_texture_settings(path, gltf, r, res):
    """Every Test box looks like its Sample pass box: green check marks (solid green for the two
    clamp rows), no red X. The single-sided row puts a polygon facing away from the viewer in
    front of its test polygon: glTF culls it (doubleSided false)."""
    # The Test and Sample pass boxes are 2.146 apart: 100 pixels.
    cam = pixels_per_unit_camera(1.53, -1.1, 17.0, 100 / 2.146, 160, 400)
    albedo = r.albedo(path, cam)
    prims = gltf.primitives()
    for m in (8, 7, 6, 3, 5, 2, 1, 0):
        name = gltf.doc["materials"][m]["name"]
        boxes = quads(np.concatenate([c.positions for c in prims[m]]))
        test, sample = boxes[0], boxes[-1]
        diff, _, shift, _ = shifted_difference(albedo, cam, test, sample)
        g_t, r_t = colour_shares(albedo, box_mask(cam, *test)[0])
        g_s, r_s = colour_shares(albedo, box_mask(cam, *sample)[0])
        ok = r_t < 0.01 and abs(g_t - g_s) < 0.05 and diff < 0.1
        res.add("TextureSettingsTest", "%s: Test box against Sample pass" % name,
                "green %.1f%% / %.1f%%, red %.1f%% / %.1f%%, mean abs. albedo difference %.3f "
                "(best at %+d, %+d px)"
                % (100 * g_t, 100 * g_s, 100 * r_t, 100 * r_s, diff, *shift), ok)


def check_alpha_blend(path, gltf, r, res):
    """The boards' coverage: OPAQUE whole, BLEND alpha, MASK alpha ≥ cutoff (0.25, default 0.5,
    0.75). The bed, decals and arrows are left out and the boards made emitters of L_e = 1, so
    the emission image is each pixel's coverage."""
    boards = {"TestOpaque": 5, "TestBlend": 1, "TestCutoff25": 2, "TestCutoffDefault": 4,
              "TestCutoff75": 3}

    def edit(doc):
        keep = [i for i, n in enumerate(doc["nodes"]) if n.get("name") in boards]
        doc["scenes"][doc.get("scene", 0)]["nodes"] = keep
        for m in boards.values():
            doc["materials"][m]["emissiveFactor"] = [1, 1, 1]

    cam = Camera.front(0, 1.035, 7.0, 20, 320, 112)
    with edited(path, edit) as copy_path:
        coverage = r.run(copy_path, cam, ["--max-depth", 0, "--estimator", "mis"],
                         spp=r.args.spp)[0][..., 1]
        hits = Hits(gltf_reader.Gltf(copy_path), cam, s=4)
    uv = hits.texcoord(0)
    for name, m in boards.items():
        mat = gltf.doc["materials"][m]
        tex = Texture(gltf, mat["pbrMetallicRoughness"]["baseColorTexture"], srgb=True)
        alpha = tex.sample(uv)[..., 3]
        mask = hits.mask(m, erode=1)
        mode = mat.get("alphaMode", "OPAQUE")
        measured = float(coverage[mask].mean())
        expected = {"OPAQUE": 1.0, "BLEND": float(hits.down(alpha)[mask].mean())}
        for cutoff in (0.25, 0.5, 0.75):
            expected["MASK %.2f" % cutoff] = float(
                hits.down((alpha >= cutoff).astype(float))[mask].mean())
        own = mode if mode != "MASK" else "MASK %.2f" % mat.get("alphaCutoff", 0.5)
        others = [abs(measured - v) for k, v in expected.items() if k != own and
                  abs(v - expected[own]) > 0.02]
        ok = abs(measured - expected[own]) < 0.01 and all(abs(measured - expected[own]) < o
                                                          for o in others)
        res.add("AlphaBlendModeTest", "%s (%s): covered share of the board" % (name, own),
                "%.4f; expected %.4f (%s)" % (
                    measured, expected[own], ", ".join("%s %.3f" % kv for kv in expected.items()
                                                       if kv[0] != own)), ok)


def check_linear_interpolation(path, gltf, r, res):
    """Sphere 2's emission, magnified from a 2 × 1 texture, is filtered after sRGB decoding:
    0.5 green, as sphere 1's factor (filtering before decoding would give 0.214)."""
    cam = Camera.front(0, 0.5, 10, 32, 224, 224)
    hits = Hits(gltf, cam)
    e = r.emission(path, cam)
    g1 = mean(e, hits.mask(0, 2))
    g2 = mean(e, hits.mask(1, 2))
    wrong = float(gltf_reader.srgb_to_linear(0.5))
    res.add("TextureLinearInterpolationTest", "sphere 2 (texture) against sphere 1 (factor)",
            "L_e green %.5f against %.5f (filtered before decoding: %.3f)" % (g2[1], g1[1], wrong),
            abs(g2[1] - g1[1]) < 1e-3 and abs(g1[1] - 0.5) < 1e-3)


def check_encoding(path, gltf, r, res):
    """Each row's four spheres (factors; a 1×1 texture; the same with gAMA/cHRM; with iCCP)
    are the same material: base colour and emission sRGB-decoded (0.246 green), metallic-
    roughness linear (roughness 136/255 = 0.533), PNG metadata ignored."""
    cam = Camera.front(1.5, 0.5, 26, 28, 256, 176)
    hits = Hits(gltf, cam)
    e = r.emission(path, cam)
    a = r.albedo(path, cam, emission=e)
    for label, image, row in (("base colour", a, (0, 1, 2, 3)), ("emission", e, (4, 5, 6, 7))):
        values = [float(mean(image, hits.mask(m, 2))[1]) for m in row]
        ok = all(abs(v - values[0]) < 1e-3 for v in values) and abs(values[0] - 0.2462) < 1e-3
        res.add("TextureEncodingTest", "%s row: green of factor / texture / gamma / ICC" % label,
                " / ".join("%.4f" % v for v in values) + " (decoded as linear: 0.533)", ok)
    # Metallic-roughness: each sphere alone (the others would be reflected differently from
    # each column), seen from the same relative place under the sky, metal reflecting it; plus
    # the factor sphere with roughness 0.246, what decoding the texture as sRGB would give.
    row = [(9, 8, None), (10, 9, None), (11, 10, None), (12, 11, None), (9, 8, 0.2462)]
    means = []
    for node, m, roughness in row:
        def edit(doc, node=node, m=m, roughness=roughness):
            doc["nodes"][0]["children"] = [node]
            if roughness is not None:
                doc["materials"][m]["pbrMetallicRoughness"]["roughnessFactor"] = roughness
        t = np.array(gltf.doc["nodes"][0]["translation"]) + np.array(
            gltf.doc["nodes"][node]["translation"])
        c = Camera.front(t[0], t[1], 6.0, 22, 64, 64)
        with edited(path, edit) as copy_path:
            rgb, var = r.sky(copy_path, c, depth=1, spp=4 * r.args.spp)
        means.append((float(rgb.mean()), math.sqrt(float(var.sum())) / var.size))
    base, base_se = means[0]
    parts, ok = [], True
    for (v, se), label in zip(means[1:], ("texture", "gamma", "ICC", "roughness 0.246")):
        z = (v - base) / math.hypot(se, base_se)
        parts.append("%s %+.2f%% (%+.1fσ)" % (label, 100 * (v / base - 1), z))
        ok &= abs(z) < 4 if label != "roughness 0.246" else abs(z) > 6
    res.add("TextureEncodingTest", "metallic-roughness row: image mean against the factor sphere "
            "(%.4f)" % base, ", ".join(parts), ok)


def check_multi_uv(path, gltf, r, res):
    """Base colour read with TEXCOORD_0 and emission with TEXCOORD_1 (texCoord 1): the emissive
    logo, not the 'Multiple UVs not supported' text of TEXCOORD_0."""
    cam_node = gltf.camera(None)
    cam = Camera(cam_node[0], cam_node[1], cam_node[2], cam_node[3], 256, 144)
    hits = Hits(gltf, cam, s=4)
    e = r.emission(path, cam)
    a = r.albedo(path, cam, emission=e)
    mat = gltf.doc["materials"][0]
    mask = hits.mask(0, 2)
    uvs = {"TEXCOORD_0": hits.texcoord(0), "TEXCOORD_1": hits.texcoord(1)}
    tex_e = Texture(gltf, mat["emissiveTexture"], srgb=True)
    tex_b = Texture(gltf, mat["pbrMetallicRoughness"]["baseColorTexture"], srgb=True)
    predicted = {k: hits.down(tex_e.sample(uv)) for k, uv in uvs.items()}
    text, ok = outcomes(e, predicted, "TEXCOORD_1", mask)
    res.add("MultiUVTest", "emission: error, read with TEXCOORD_1 (texCoord 1) against", text, ok)
    predicted = {k: hits.down(tex_b.sample(uv)) for k, uv in uvs.items()}
    text, ok = outcomes(a, predicted, "TEXCOORD_0", mask)
    res.add("MultiUVTest", "base colour: error, read with TEXCOORD_0 against", text, ok)


def check_emissive_strength(path, gltf, r, res):
    """Five cubes of emissiveFactor (0.1, 0.5, 0.9) × strength 1, 2, 4, 8, 16: each twice the
    one to its left."""
    cam = Camera.front(0, 0, 20, 12, 320, 80)
    hits = Hits(gltf, cam)
    e = r.emission(path, cam)
    values, parts, ok = [], [], True
    for m, strength in ((3, 1), (2, 2), (0, 4), (4, 8), (5, 16)):
        front_face = hits.geometric_normal()[..., 2] > 0.99
        v = mean(e, hits.mask(m, 2, front_face))
        values.append(v)
        expected = np.array([0.1, 0.5, 0.9]) * strength
        ok &= bool(np.all(np.abs(v / expected - 1) < 1e-5))
        parts.append("×%d: %.4f, %.4f, %.4f" % (strength, *v))
    ratios = [float(values[k + 1][1] / values[k][1]) for k in range(4)]
    res.add("EmissiveStrengthTest", "cube fronts' L_e (R, G, B)", "; ".join(parts), ok)
    res.add("EmissiveStrengthTest", "ratio of each cube's L_e to its left neighbour's",
            ", ".join("%.6f" % x for x in ratios), all(abs(x - 2) < 1e-4 for x in ratios))


def check_normal_tangent(name, path, gltf, r, res, view):
    """Lit by a light above, left of and in front of the board: every normal-mapped bump is lit
    from the side its geometric twin is. Per bump, the direction from its centroid to its
    brightness-weighted centroid (image up = 90°)."""
    cam = Camera.front(*view)
    hits = Hits(gltf, cam)
    mat = gltf.doc["materials"][0]
    with edited(path, lambda doc: light_upper_left(doc, (0, 0, 0), 8.0, 2.0, 150.0)) as lit_path:
        rgb = r.lit(lit_path, cam, materials="lambert")[0]
    shade = luminance(rgb)
    board = hits.mask(0, erode=1)
    n_geo = hits.geometric_normal()
    tex = Texture(gltf, mat["normalTexture"], srgb=False)
    n_map = tex.sample(hits.texcoord(0))[..., :3] * 2 - 1
    n_map /= np.maximum(np.linalg.norm(n_map, axis=-1, keepdims=True), 1e-9)
    flat = np.abs(n_geo[..., 2]) > 0.999
    geometric = board & ~flat
    mapped = board & flat & (n_map[..., 2] < 0.97)

    def directions(mask):
        out = []
        for ys, xs in components(mask, 30):
            w = shade[ys, xs]
            cx, cy = xs.mean(), ys.mean()
            dx = float((w * (xs - cx)).sum() / w.sum())
            dy = float((w * (ys - cy)).sum() / w.sum())
            out.append((cx, cy, math.degrees(math.atan2(-dy, dx)), math.hypot(dx, dy)))
        return out

    geo, nm = directions(geometric), directions(mapped)
    differences = []
    for cx, cy, angle, _ in nm:
        twin = min(geo, key=lambda g: 100 * (g[1] - cy) ** 2 + (g[0] - cx) ** 2)  # its row
        differences.append(abs((angle - twin[2] + 180) % 360 - 180))
    angles_g = [g[2] for g in geo]
    angles_m = [m[2] for m in nm]
    worst = max(differences) if differences else float("nan")
    res.add(name, "bumps lit from the same side: geometric / normal-mapped",
            "%d / %d bumps; direction of the light in the image: geometric %.0f° to %.0f°, "
            "normal-mapped %.0f° to %.0f°; largest difference from the nearest geometric twin "
            "%.0f°" % (len(geo), len(nm), min(angles_g), max(angles_g), min(angles_m),
                       max(angles_m), worst),
            bool(differences) and worst < 30 and all(90 < a < 180 for a in angles_m))
    # The glTF materials under the sky (paths of 4 reflections): a bump reflects the sky or the
    # lit board, so none of it is dark, normal-mapped or not (the screenshots: "all of the test
    # blocks show similar reflections").
    lum = luminance(r.sky(path, cam, depth=4)[0])
    dark_g, dark_m = float((lum[geometric] < 0.1).mean()), float((lum[mapped] < 0.1).mean())
    res.add(name, "glTF materials under the sky: share of dark (luminance < 0.1) bump pixels, "
            "geometric / normal-mapped", "%.1f%% / %.1f%%" % (100 * dark_g, 100 * dark_m),
            abs(dark_m - dark_g) < 0.02)


def check_transform_multi(path, gltf, r, res):
    """Rows of three tiles (UV 0, UV 1, Sample) that look alike: the transformed texCoord 0 and 1
    tiles against the Sample tile, for each input mcrt reads (base colour, emission, normal,
    metallic-roughness; unlit read as base colour). Occlusion and clearcoat are not modelled:
    blank rows, which the README counts as a pass."""
    # The columns are 0.25 apart: 40 pixels. A distant light lights the tiles alike.
    cam = pixels_per_unit_camera(0.35, -0.25, 4.4, 160, 160, 400)
    e = r.emission(path, cam)
    a = r.albedo(path, cam, emission=e)
    with edited(path, lambda doc: light_upper_left(doc, (0.35, -0.25, 0), 20.0, 6.0, 60.0)) \
            as lit_path:
        lit, lit_var = r.lit(lit_path, cam, materials="gltf", sky=0.2, spp=4 * r.args.spp)
    zero = np.zeros_like(a)
    prims = gltf.primitives()
    rows = [("BaseColor", (0, 1, 2), a, zero), ("Emission", (5, 6, 7), e, zero),
            ("Normal", (8, 9, 10), lit, lit_var), ("Metal/Rough", (11, 12, 13), lit, lit_var),
            ("Occlusion", (14, 15, 16), lit, lit_var), ("Unlit", (17, 18, 19), a, zero),
            ("Clearcoat", (20, 21, 22), lit, lit_var),
            ("Clearcoat Rough", (23, 24, 25), lit, lit_var),
            ("Clearcoat Normal", (26, 27, 28), lit, lit_var)]
    for label, mats, image, variance in rows:
        boxes = [np.concatenate([c.positions for c in prims[m]]) for m in mats]
        boxes = [(b.reshape(-1, 3).min(0), b.reshape(-1, 3).max(0)) for b in boxes]
        d0, contrast, e0, noise = shifted_difference(image, cam, boxes[0], boxes[2], 3, variance)
        d1, _, e1, _ = shifted_difference(image, cam, boxes[1], boxes[2], 3, variance)
        numbers = ("mean abs. difference %.4f / %.4f at %+d,%+d / %+d,%+d px (noise alone: %.4f), "
                   "the Sample tile's contrast (std less noise) %.4f"
                   % (d0, d1, *e0, *e1, noise, contrast))
        if label in ("Occlusion", "Clearcoat", "Clearcoat Rough", "Clearcoat Normal"):
            res.add("TextureTransformMultiTest", "%s row: not modelled, the tiles alike" % label,
                    numbers, None)
            continue
        ok = max(d0, d1) < noise + 0.2 * contrast
        res.add("TextureTransformMultiTest", "%s row: UV 0 and UV 1 tiles against Sample" % label,
                numbers, ok)


CHECKS = {
    "TextureTransformTest": check_texture_transform,
    "TextureTransformMultiTest": check_transform_multi,
    "TextureCoordinateTest": check_texture_coordinate,
    "TextureSettingsTest": check_texture_settings,
    "AlphaBlendModeTest": check_alpha_blend,
    "TextureLinearInterpolationTest": check_linear_interpolation,
    "TextureEncodingTest": check_encoding,
    "MultiUVTest": check_multi_uv,
    "EmissiveStrengthTest": check_emissive_strength,
    "NormalTangentTest": lambda p, g, r, res: check_normal_tangent(
        "NormalTangentTest", p, g, r, res, (0, -0.12, 4.0, 35, 256, 240)),
    "NormalTangentMirrorTest": lambda p, g, r, res: check_normal_tangent(
        "NormalTangentMirrorTest", p, g, r, res, (-0.01, -0.07, 4.2, 35, 288, 216)),
}


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog=__doc__.split("\n\n", 1)[1])
    p.add_argument("--scenes", default=str(DEFAULT_SCENES),
                   help="folder of the textured scenes (default ../shared/scenes/textured)")
    p.add_argument("--only", type=mcrt_run.comma_list, help="models to check, A,B,...")
    p.add_argument("--spp", type=int, default=64, help="samples per pixel of the noisy renders")
    p.add_argument("--seed", type=int, default=0)
    mcrt_run.add_mcrt_option(p)
    args = p.parse_args()
    mcrt_run.require("numpy")
    scenes = Path(args.scenes)
    if not scenes.is_dir():
        print("textured_checks: %s is absent: nothing to check" % scenes)
        return 0
    names = args.only or list(CHECKS)
    unknown = [n for n in names if n not in CHECKS]
    if unknown:
        raise mcrt_run.ScriptError("no check for %s (one of %s)" % (", ".join(unknown),
                                                                    ", ".join(CHECKS)))
    res = Results()
    print("| model | check | measured | verdict |")
    print("|---|---|---|---|")
    with tempfile.TemporaryDirectory(prefix="mcrt-checks-renders-") as scratch:
        r = Renderer(args, scratch)
        for name in names:
            path = scenes / name / (name + ".gltf")
            if not path.exists():
                print("textured_checks: %s is absent: skipped" % path)
                continue
            CHECKS[name](path, gltf_reader.Gltf(path), r, res)
    verdicts = [row[3] for row in res.rows if row[3] is not None]
    print("textured_checks: %d of %d checks pass (%d not applicable)"
          % (sum(verdicts), len(verdicts), len(res.rows) - len(verdicts)))
    return 0


if __name__ == "__main__":
    sys.exit(mcrt_run.script_main(main))

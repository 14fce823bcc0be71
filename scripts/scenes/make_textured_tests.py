#!/usr/bin/python3
"""Writes the analytic textured test scenes of tests/data/textured/ and what a test must see in
them (EXPECTED.json, numbers; EXPECTED.md, the formulas), byte for byte the same on every run.

Every scene is tests/support/analytic_scenes.h's PlaneScene geometry: the Lambertian floor y = 0,
[-3, 3]², baseColorFactor (0.6, 0.5, 0.4), under the quad light x ∈ [0.8, 1.3], z ∈ [-0.25, 0.25]
at y = 1 facing down, Le (5, 4, 3) (the floor scenes also have PlaneScene's triangle light).
Camera 0 looks straight down from (0, 3, 0) (40°, image up = −Z) and sees the floor only;
camera 1 (the light scenes) looks straight up from (1.05, 0.3, 0) (60°, image up = +Z) and sees
the light's front face. A texture changes one thing, so each pixel has a closed form: Lambert's
formula for polygon lights (Arvo 1995, eq. 1) summed over the pieces a texture cuts a light into.

  floor_untextured      PlaneScene itself (factor only): the twin of the checker and wrap scenes
  checker               floor baseColorTexture 4×4 sRGB checker, NEAREST, REPEAT, u = x + 3
  checker_linear        the same, magFilter LINEAR (bilinear after sRGB decoding)
  checker_transform     KHR_texture_transform offset (0.25, 0.5), rotation 90°, scale 2
  checker_texcoord1     the checker on TEXCOORD_1 (texCoord 1), TEXCOORD_0 garbage
  checker_transform_texcoord1  the transform with KHR_texture_transform.texCoord 1 overriding
                        textureInfo.texCoord 0 (TEXCOORD_0 garbage)
  wrap_repeat, wrap_clamp, wrap_mirror, wrap_clamp_mirror, wrap_mirror_repeat
                        a 4×4 RGB texture with u = 2x + 0.5, v = 2z + 0.5 (−1.5 … 2.5 where
                        |x|, |z| ≤ 1), per-axis wrapS / wrapT
  quad_floor            the floor under the quad light alone: the twin of the light scenes
  emissive_light        the light's emissiveTexture 2×2 sRGB (NEAREST) × emissiveFactor
  mask_light            the light's baseColorTexture alpha a 4×4 0/255 pattern, MASK, cutoff 0.5:
                        holes neither emit nor block
  mask_cutoff_light     2×2 alpha bytes 100, 140, 150, 135 with alphaCutoff 0.54 (alpha is
                        linear: sRGB-decoding it or ignoring the cutoff changes which emit)
  mask_occluder         an opaque grey plane at y = 0.99 under the light, MASK holes (6×6 texels,
                        default cutoff) letting light through
  blend_occluder        the plane with baseColorFactor alpha 0.5, BLEND: the floor's irradiance
                        is halved in expectation (stochastic transparency)
  blend_light           the light itself BLEND at alpha 0.5: seen and reflected radiance halved
  blend_texture_light   the light's alpha from a 2×2 texture (64, 128, 191, 255)

Files are separate (.gltf, .bin, .png); PNGs are written with stored (uncompressed) deflate
blocks, so their bytes do not depend on the zlib version.

Usage: scripts/scenes/make_textured_tests.py [OUTPUT_DIR]   (default: tests/data/textured)
"""

import json
import math
import struct
import sys
import zlib
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from make_stress_scenes import StressScene, cross, normalize, sub  # noqa: E402
from make_test_gltf import FLOAT, USHORT  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]

# glTF 2.0 sampler enums ("Samplers", Properties Reference: sampler).
NEAREST, LINEAR = 9728, 9729
REPEAT, CLAMP, MIRROR = 10497, 33071, 33648
WRAP_NAMES = {REPEAT: "REPEAT", CLAMP: "CLAMP_TO_EDGE", MIRROR: "MIRRORED_REPEAT"}

RESOLUTION = (64, 64)   # the resolution EXPECTED.json's pixels refer to
QUADRATURE = 8          # q × q midpoint rule per pixel, as tests/support/analytic_scenes.h
LABEL_MARGIN = 0.1      # a labelled pixel's footprint, grown by this many pixels, lies in one piece

FLOOR_ALBEDO = (0.6, 0.5, 0.4)
LIGHT_RECT = (0.8, 1.3, -0.25, 0.25, 1.0)      # x0, x1, z0, z1, y: PlaneScene's quad light
LIGHT_LE = (5.0, 4.0, 3.0)
TRIANGLE_LIGHT = ([(-1.4, 0.7, 0.2), (-1.0, 0.7, 0.2), (-1.2, 0.75, 0.5)], (40.0, 30.0, 60.0))
OCCLUDER_RECT = (0.75, 1.35, -0.3, 0.3, 0.99)  # just under the light, outside camera 0's view
CAMERA_DOWN = ((0.0, 3.0, 0.0), (0.0, 2.0, 0.0), (0.0, 0.0, -1.0), 40.0)
CAMERA_UP = ((1.05, 0.3, 0.0), (1.05, 1.3, 0.0), (0.0, 0.0, 1.0), 60.0)


def f32(x):
    """x rounded to float32, as the .bin stores it and mcrt reads it, back in double."""
    return np.asarray(x, np.float32).astype(np.float64)


def srgb_to_linear(byte):
    """The sRGB EOTF of an 8-bit value (IEC 61966-2-1; glTF 2.0 "Metallic-Roughness Material":
    baseColorTexture and emissiveTexture are sRGB-encoded, alpha is linear)."""
    c = np.asarray(byte, np.float64) / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


# ----- PNG without a compressor --------------------------------------------------------------------

def png_bytes(pixels):
    """PNG of an (H, W, C) uint8 array, C = 1 grey, 2 grey+alpha, 3 RGB, 4 RGBA (PNG spec 11.2.2),
    filter 0 on every row, the zlib stream made of stored deflate blocks (RFC 1950, RFC 1951
    3.2.4): the same bytes whatever zlib is installed."""
    h, w, c = pixels.shape
    raw = b"".join(b"\x00" + pixels[row].tobytes() for row in range(h))
    blocks, start = [], 0
    while True:
        piece = raw[start:start + 65535]
        start += len(piece)
        final = start >= len(raw)
        blocks.append(struct.pack("<BHH", 1 if final else 0, len(piece), len(piece) ^ 0xFFFF) + piece)
        if final:
            break
    stream = b"\x78\x01" + b"".join(blocks) + struct.pack(">I", zlib.adler32(raw))

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data))
    colour_type = {1: 0, 2: 4, 3: 2, 4: 6}[c]
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, colour_type, 0, 0, 0))
            + chunk(b"IDAT", stream) + chunk(b"IEND", b""))


# ----- the textures ----------------------------------------------------------------------------------

def checker_image():
    """4×4 RGBA, texel k = 4·row + column distinct in every channel; alpha 255."""
    img = np.zeros((4, 4, 4), np.uint8)
    for r in range(4):
        for c in range(4):
            img[r, c] = (40 + 60 * c, 40 + 60 * r, 255 - 15 * (4 * r + c), 255)
    return img


def wrap_image():
    """4×4 RGB (a colour type of its own), every texel distinct."""
    img = np.zeros((4, 4, 3), np.uint8)
    for r in range(4):
        for c in range(4):
            img[r, c] = (50 + 50 * c, 200 - 50 * r, 20 + 15 * (4 * r + c))
    return img


def emissive_image():
    return np.array([[[255, 255, 255], [200, 120, 60]], [[90, 160, 230], [128, 128, 128]]], np.uint8)


MASK_PATTERN = [[1, 0, 1, 1], [0, 1, 1, 0], [1, 1, 0, 1], [0, 1, 0, 1]]  # 1 opaque, 0 hole


def mask_image():
    """4×4 grey+alpha: grey 0, alpha 255 where MASK_PATTERN is 1."""
    a = np.array(MASK_PATTERN, np.uint8) * 255
    return np.stack([np.zeros_like(a), a], axis=-1)


def mask_cutoff_image():
    """2×2 RGBA, black, alpha bytes 100, 140 / 150, 135: with cutoff 0.54, 140 and 150 emit."""
    a = np.array([[100, 140], [150, 135]], np.uint8)
    return np.stack([np.zeros_like(a)] * 3 + [a], axis=-1)


OCCLUDER_HOLES = [[0, 0, 1, 0, 0, 0], [0, 1, 1, 0, 1, 0], [1, 0, 0, 0, 1, 0],
                  [0, 0, 1, 1, 0, 0], [0, 1, 0, 0, 0, 1], [0, 0, 0, 1, 0, 0]]  # 1 hole


def occluder_image():
    """6×6 RGBA, grey 128, alpha 0 at the holes and 255 elsewhere."""
    a = (1 - np.array(OCCLUDER_HOLES, np.uint8)) * 255
    g = np.full_like(a, 128)
    return np.stack([g, g, g, a], axis=-1)


def blend_alpha_image():
    a = np.array([[64, 128], [191, 255]], np.uint8)
    return np.stack([np.zeros_like(a)] * 3 + [a], axis=-1)


IMAGES = {"checker4x4.png": checker_image, "wrap4x4.png": wrap_image,
          "emissive2x2.png": emissive_image, "mask4x4.png": mask_image,
          "mask_cutoff2x2.png": mask_cutoff_image, "occluder6x6.png": occluder_image,
          "blend_alpha2x2.png": blend_alpha_image}


# ----- texture lookups (glTF 2.0 "Samplers"; KHR_texture_transform) ---------------------------------

class Texture:
    """A texture slot as the scene uses it: image texels, sampler, KHR_texture_transform and the
    texture coordinates, here an affine function of the world point (the meshes are flat)."""

    def __init__(self, image, wrap=(REPEAT, REPEAT), mag=NEAREST, transform=None, texcoord=0,
                 transform_texcoord=None):
        self.image = image
        self.pixels = IMAGES[image]()
        self.wrap, self.mag = wrap, mag
        self.transform, self.texcoord, self.transform_texcoord = transform, texcoord, transform_texcoord

    def texcoord_set(self):
        """The TEXCOORD_n read: KHR_texture_transform's texCoord overrides textureInfo's."""
        return self.texcoord if self.transform_texcoord is None else self.transform_texcoord

    def info(self, scene):
        """The textureInfo of this slot in `scene`'s document."""
        info = {"index": scene.texture(self.image, self.wrap, self.mag)}
        if self.texcoord:
            info["texCoord"] = self.texcoord
        if self.transform:
            ext = dict(self.transform)
            if self.transform_texcoord is not None:
                ext["texCoord"] = self.transform_texcoord
            info["extensions"] = {"KHR_texture_transform": ext}
        return info

    def matrix(self):
        """KHR_texture_transform's (u', v') = T(offset) R(rotation) S(scale) (u, v, 1): the 2×3
        matrix. R = [[cos, sin], [−sin, cos]]: "rotate the UVs counter-clockwise" with v down,
        the rows of the extension's GLSL mat3; its example (offset (0, 1), rotation π/2, scale
        0.5 → the lower left quadrant) fixes the sign."""
        t = self.transform or {}
        ox, oy = t.get("offset", (0.0, 0.0))
        sx, sy = t.get("scale", (1.0, 1.0))
        r = t.get("rotation", 0.0)
        c, s = math.cos(r), math.sin(r)
        return np.array([[c * sx, s * sy, ox], [-s * sx, c * sy, oy]])

    def uv(self, uv):
        m = self.matrix()
        return uv @ m[:, :2].T + m[:, 2]

    def wrapped(self, t, mode):
        """t ∈ ℝ → [0, 1] by the wrap mode (glTF 2.0 "Wrapping")."""
        if mode == REPEAT:
            return t - np.floor(t)
        if mode == MIRROR:  # flips when the integer part (towards −∞) is odd
            f = t - np.floor(t)
            return np.where(np.floor(t) % 2 == 1, 1.0 - f, f)
        return np.clip(t, 0.0, 1.0)

    def texel(self, uv):
        """NEAREST: the (column, row) of the texel at each transformed uv (row 0 at v = 0, the
        image's top row: glTF 2.0 "Images")."""
        h, w = self.pixels.shape[:2]
        uvt = self.uv(uv)
        col = np.clip(np.floor(self.wrapped(uvt[..., 0], self.wrap[0]) * w), 0, w - 1).astype(int)
        row = np.clip(np.floor(self.wrapped(uvt[..., 1], self.wrap[1]) * h), 0, h - 1).astype(int)
        return col, row

    def linear_rgb(self):
        """(H, W, 3) decoded sRGB colours (grey widened)."""
        rgb = self.pixels[..., :3] if self.pixels.shape[2] >= 3 else self.pixels[..., :1].repeat(3, -1)
        return srgb_to_linear(rgb)

    def alpha(self):
        """(H, W) linear alpha, 1 where the image has none."""
        c = self.pixels.shape[2]
        return self.pixels[..., c - 1] / 255.0 if c in (2, 4) else np.ones(self.pixels.shape[:2])

    def bilinear(self, uv, values):
        """LINEAR: `values` (H, W, K) interpolated between texel centres, neighbours wrapped at
        texel level (OpenGL 4.6 sec. 8.14.2; REPEAT alone here)."""
        h, w = values.shape[:2]
        uvt = self.uv(uv)
        s, t = uvt[..., 0] * w - 0.5, uvt[..., 1] * h - 0.5
        i0, j0 = np.floor(s).astype(int), np.floor(t).astype(int)
        a, b = (s - i0)[..., None], (t - j0)[..., None]
        assert self.wrap == (REPEAT, REPEAT)
        i1, j1, i0, j0 = (i0 + 1) % w, (j0 + 1) % h, i0 % w, j0 % h
        return ((1 - a) * (1 - b) * values[j0, i0] + a * (1 - b) * values[j0, i1]
                + (1 - a) * b * values[j1, i0] + a * b * values[j1, i1])


# ----- the scene model ------------------------------------------------------------------------------

class Rect:
    """A horizontal rectangle [x0, x1] × [z0, z1] at height y, facing up (+1) or down (−1), with
    texture coordinates u = uv[0]·x + uv[1], v = uv[2]·z + uv[3] (and a second set, uv1)."""

    def __init__(self, x0, x1, z0, z1, y, facing, uv=None, uv1=None):
        self.x0, self.x1, self.z0, self.z1, self.y = (float(f) for f in f32([x0, x1, z0, z1, y]))
        self.facing, self.uv_map, self.uv1_map = facing, uv, uv1

    def corners(self):
        """Counter-clockwise seen from the side it faces."""
        a, b, c, d = ((self.x0, self.z0), (self.x1, self.z0), (self.x1, self.z1), (self.x0, self.z1))
        order = [a, b, c, d] if self.facing < 0 else [a, d, c, b]
        return [(x, self.y, z) for x, z in order]

    def uv(self, x, z, uv_map=None):
        m = uv_map or self.uv_map
        return np.stack([m[0] * x + m[1], m[2] * z + m[3]], axis=-1)

    def vertex_uvs(self, uv_map=None):
        """The corners' texture coordinates as written (rounded: 0 and 1 stay exact)."""
        return [tuple(round(float(c), 6) for c in self.uv(x, z, uv_map)) for x, _, z in self.corners()]

    def contains(self, x, z):
        return (x >= self.x0) & (x <= self.x1) & (z >= self.z0) & (z <= self.z1)

    def cells(self, tex):
        """The texel cells a NEAREST texture with uv ∈ [0, 1]² cuts the rectangle into:
        (x0, x1, z0, z1, column, row) each."""
        h, w = tex.pixels.shape[:2]
        # uv interpolates the corners' written values over the float bounds: invert that.
        uvs = {(x, z): uv for (x, _, z), uv in zip(self.corners(), self.vertex_uvs())}
        u0, u1 = uvs[(self.x0, self.z0)][0], uvs[(self.x1, self.z0)][0]
        v0, v1 = uvs[(self.x0, self.z0)][1], uvs[(self.x0, self.z1)][1]
        out = []
        for r in range(h):
            for c in range(w):
                xs = sorted(self.x0 + (k / w - u0) / (u1 - u0) * (self.x1 - self.x0) for k in (c, c + 1))
                zs = sorted(self.z0 + (k / h - v0) / (v1 - v0) * (self.z1 - self.z0) for k in (r, r + 1))
                out.append((xs[0], xs[1], zs[0], zs[1], c, r))
        return out


def lambert(polygons, p):
    """Irradiance at points p (N, 3) on the floor (normal +Y) from unit-radiance convex polygons
    (N, m, 3) wholly above p's horizon: E = 1/2 |Σ_i Θ_i (Γ_i · n)| (Lambert 1760; Arvo 1995,
    "Applications of Irradiance Tensors", eq. 1), Θ_i the angle edge i subtends at p, Γ_i the
    unit normal of the plane through p and the edge. Degenerate polygons give 0."""
    ax, ay, az = (polygons[..., k] - p[:, None, k] for k in range(3))
    n = np.sqrt(ax * ax + ay * ay + az * az)
    ax, ay, az = ax / n, ay / n, az / n
    bx, by, bz = (np.roll(c, -1, axis=1) for c in (ax, ay, az))
    cx, cy, cz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
    cn = np.sqrt(cx * cx + cy * cy + cz * cz)
    theta = np.arctan2(cn, ax * bx + ay * by + az * bz)
    gamma_y = np.where(cn > 0, cy / np.where(cn > 0, cn, 1.0), 0.0)
    return 0.5 * np.abs(np.sum(theta * gamma_y, axis=-1))


def rect_polygons(x0, x1, z0, z1, y):
    """(N, 4, 3) rectangles from per-point bounds (arrays of N) at height y."""
    x0, x1, z0, z1 = (np.asarray(v, np.float64) for v in (x0, x1, z0, z1))
    y = np.full(x0.shape, y)
    return np.stack([np.stack([x0, y, z0], -1), np.stack([x1, y, z0], -1),
                     np.stack([x1, y, z1], -1), np.stack([x0, y, z1], -1)], axis=1)


_IRRADIANCE = {}


class Scene:
    """One test scene: the floor (a Rect with its albedo factor and optional texture), light
    pieces and at most one occluder, written as glTF and evaluated exactly."""

    def __init__(self, name, purpose):
        self.name, self.purpose = name, purpose
        self.floor_texture = None
        self.floor_uv, self.floor_uv1 = (1.0, 3.0, 1.0, 3.0), None
        self.light = None            # dict: rect, Le, emissive texture, alpha mode, textures
        self.triangle_light = False
        self.occluder = None         # dict: rect, alpha mode, alpha factor, texture
        self.cameras = [CAMERA_DOWN]
        self.twin = None             # the untextured scene the test divides by
        self.ratio_to_twin = None    # a constant ratio to the twin at every pixel, if any

    # --- light pieces: (rect bounds, radiance) with the alpha weight folded in -----------------
    def light_pieces(self):
        """[(x0, x1, z0, z1, y, Le RGB, name)]: the light cut by its textures (NEAREST), each
        piece's radiance Le × emissive texel × alpha weight (BLEND: alpha, the expectation of
        stochastic transparency; MASK: 1 where alpha ≥ alphaCutoff, else 0)."""
        l = self.light
        rect, le = l["rect"], np.array(l["Le"])
        tex = l.get("emissive") or l.get("alpha_texture")
        if tex is None:
            weight = self.alpha_weight(l.get("alpha", 1.0))
            return [(rect.x0, rect.x1, rect.z0, rect.z1, rect.y, le * weight, "L")]
        pieces = []
        for x0, x1, z0, z1, c, r in rect.cells(tex):
            value = le.copy()
            if l.get("emissive") is not None:
                value = value * l["emissive"].linear_rgb()[r, c]
            alpha = l.get("alpha", 1.0)
            if l.get("alpha_texture") is not None:
                alpha = alpha * l["alpha_texture"].alpha()[r, c]
            value = value * self.alpha_weight(alpha)
            pieces.append((x0, x1, z0, z1, rect.y, value, "L%d%d" % (c, r)))
        return pieces

    def alpha_weight(self, alpha):
        """The light's expected emission per unit Le at this alpha."""
        mode = self.light.get("mode", "OPAQUE")
        if mode == "BLEND":
            return alpha
        if mode == "MASK":
            return 1.0 if alpha >= self.light.get("cutoff", 0.5) else 0.0
        return 1.0

    def occluder_holes(self):
        """Occluder cells that let light through, with their transmission: MASK holes (1), a
        BLEND plane's whole rectangle (1 − alpha)."""
        o = self.occluder
        if o["mode"] == "BLEND":
            r = o["rect"]
            return [(r.x0, r.x1, r.z0, r.z1, 1.0 - o["alpha"])]
        return [(x0, x1, z0, z1, 1.0) for x0, x1, z0, z1, c, r in o["rect"].cells(o["texture"])
                if o["texture"].alpha()[r, c] < o.get("cutoff", 0.5)]

    # --- exact values ------------------------------------------------------------------------
    def floor_irradiance_weighted(self, p):
        """Σ over light pieces of Le_piece · E_piece(p) (RGB, (N, 3)) at floor points p, through
        the occluder's holes when there is one (remembered: the floor scenes share their
        lights)."""
        key = (repr(self.light_pieces()), repr(self.occluder_holes() if self.occluder else None),
               self.triangle_light, hash(p.tobytes()))
        if key not in _IRRADIANCE:
            _IRRADIANCE[key] = self._floor_irradiance_weighted(p)
        return _IRRADIANCE[key]

    def _floor_irradiance_weighted(self, p):
        total = np.zeros((len(p), 3))
        pieces = self.light_pieces()
        if self.occluder is None:
            for x0, x1, z0, z1, y, le, _ in pieces:
                if max(le) > 0:
                    poly = np.broadcast_to(rect_polygons(*([v] for v in (x0, x1, z0, z1)), y), (len(p), 4, 3))
                    total += lambert(poly, p)[:, None] * le
        else:
            o = self.occluder["rect"]
            # Every ray from the light to a point in view crosses the occluder's rectangle.
            for x0, x1, z0, z1, y, le, _ in pieces:
                k = o.y / y
                for px, pz in ((x0, z0), (x1, z1)):
                    assert np.all(o.contains(p[:, 0] + (px - p[:, 0]) * k, p[:, 2] + (pz - p[:, 2]) * k))
            s = pieces[0][4] / o.y  # a hole seen from p, projected onto the light's plane
            for hx0, hx1, hz0, hz1, transmission in self.occluder_holes():
                hx = [p[:, 0] + (h - p[:, 0]) * s for h in (hx0, hx1)]
                hz = [p[:, 2] + (h - p[:, 2]) * s for h in (hz0, hz1)]
                for x0, x1, z0, z1, y, le, _ in pieces:
                    cx0, cx1 = np.maximum(hx[0], x0), np.minimum(hx[1], x1)
                    cz0, cz1 = np.maximum(hz[0], z0), np.minimum(hz[1], z1)
                    ok = (cx1 > cx0) & (cz1 > cz0)
                    if not np.any(ok):
                        continue
                    e = np.zeros(len(p))
                    e[ok] = lambert(rect_polygons(cx0[ok], cx1[ok], cz0[ok], cz1[ok], y), p[ok])
                    total += transmission * e[:, None] * le
        if self.triangle_light:
            tri = np.broadcast_to(f32(TRIANGLE_LIGHT[0]), (len(p), 3, 3))
            total += lambert(tri, p)[:, None] * np.array(TRIANGLE_LIGHT[1])
        return total

    def floor_albedo(self, p):
        """(N, 3) albedo at floor points, and the texel key (or None): factor × decoded texel."""
        factor = np.array(FLOOR_ALBEDO)
        t = self.floor_texture
        if t is None:
            return np.broadcast_to(factor, (len(p), 3)), None
        floor = self.floor_rect()
        uv = floor.uv(p[:, 0], p[:, 2], floor.uv1_map if t.texcoord_set() == 1 else None)
        if t.mag == LINEAR:
            return factor * t.bilinear(uv, t.linear_rgb()), None
        col, row = t.texel(uv)
        return factor * t.linear_rgb()[row, col], row * t.pixels.shape[1] + col

    def floor_rect(self):
        return Rect(-3, 3, -3, 3, 0, +1, self.floor_uv, self.floor_uv1)

    def floor_value(self, eye, d):
        """Exact radiance along rays eye + t d that meet the floor first (camera 0), and the
        texel key."""
        t = -eye[1] / d[:, 1]
        p = eye + t[:, None] * d
        for rect in self.blockers():  # nothing but the floor in camera 0's view
            th = (rect.y - eye[1]) / d[:, 1]
            q = eye + th[:, None] * d
            assert not np.any(rect.contains(q[:, 0], q[:, 2]) & (th > 0) & (th < t))
        albedo, key = self.floor_albedo(p)
        return albedo / math.pi * self.floor_irradiance_weighted(p), key

    def blockers(self):
        out = [self.light["rect"]] if self.light else []
        return out + ([self.occluder["rect"]] if self.occluder else [])

    def light_view_value(self, eye, d):
        """Exact expected radiance along rays going up (camera 1): through the occluder (MASK
        holes pass, opaque texels are black: lit from above only; BLEND passes 1 − alpha) to
        the light's pieces; nothing beyond. With the key of the value."""
        n = len(d)
        weight = np.ones(n)
        if self.occluder is not None:
            o = self.occluder["rect"]
            th = (o.y - eye[1]) / d[:, 1]
            q = eye + th[:, None] * d
            inside = o.contains(q[:, 0], q[:, 2])
            through = np.zeros(n)
            for x0, x1, z0, z1, transmission in self.occluder_holes():
                through += transmission * ((q[:, 0] >= x0) & (q[:, 0] < x1) & (q[:, 2] >= z0) & (q[:, 2] < z1))
            weight = np.where(inside, through, 1.0)
        value = np.zeros((n, 3))
        rect = self.light["rect"]
        th = (rect.y - eye[1]) / d[:, 1]
        q = eye + th[:, None] * d
        for x0, x1, z0, z1, y, le, _ in self.light_pieces():
            hit = (q[:, 0] >= x0) & (q[:, 0] < x1) & (q[:, 2] >= z0) & (q[:, 2] < z1)
            value[hit] = le
        value *= weight[:, None]
        return value, None

    # --- glTF --------------------------------------------------------------------------------
    def gltf(self):
        g = TexturedGltf(self.name)
        for eye, target, up, fov in self.cameras:
            g.camera(eye, target, up, fov)
        pbr = {"baseColorFactor": [*FLOOR_ALBEDO, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}
        if self.floor_texture is not None:
            pbr["baseColorTexture"] = self.floor_texture.info(g)
        floor = g.material(name="floor", pbrMetallicRoughness=pbr, extensions=dict(g.LAMBERTIAN))
        texcoords = () if self.floor_texture is None else (
            [self.floor_uv] if self.floor_uv1 is None else [None, self.floor_uv1])
        g.rect("floor", self.floor_rect(), floor, texcoords)
        if self.light is not None:
            l = self.light
            textured = l.get("emissive") is not None or l.get("alpha_texture") is not None
            g.rect("light", l["rect"], self.light_material(g), [l["rect"].uv_map] if textured else ())
        if self.triangle_light:
            g.triangles("triangle light", TRIANGLE_LIGHT[0], g.emitter("triangle light", TRIANGLE_LIGHT[1]))
        if self.occluder is not None:
            o = self.occluder
            pbr = {"baseColorFactor": [0.5, 0.5, 0.5, o.get("alpha", 1.0)], "metallicFactor": 0.0,
                   "roughnessFactor": 1.0}
            if o.get("texture") is not None:
                pbr["baseColorFactor"] = [1.0, 1.0, 1.0, 1.0]
                pbr["baseColorTexture"] = o["texture"].info(g)
            fields = {"name": "occluder", "pbrMetallicRoughness": pbr, "alphaMode": o["mode"],
                      "doubleSided": True, "extensions": dict(g.LAMBERTIAN)}
            if "cutoff" in o:
                fields["alphaCutoff"] = o["cutoff"]
            g.rect("occluder", o["rect"], g.material(**fields),
                   [o["rect"].uv_map] if o.get("texture") is not None else ())
        return g.finish()

    def light_material(self, g):
        l = self.light
        strength = max(l["Le"])
        pbr = {"baseColorFactor": [0.0, 0.0, 0.0, l.get("alpha", 1.0)], "metallicFactor": 0.0}
        if l.get("alpha_texture") is not None:
            pbr["baseColorTexture"] = l["alpha_texture"].info(g)
        fields = {"name": "light", "emissiveFactor": [round(c / strength, 6) for c in l["Le"]],
                  "pbrMetallicRoughness": pbr,
                  "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": strength},
                                 **g.LAMBERTIAN}}
        if l.get("emissive") is not None:
            fields["emissiveTexture"] = l["emissive"].info(g)
        if l.get("mode", "OPAQUE") != "OPAQUE":
            fields["alphaMode"] = l["mode"]
        if "cutoff" in l:
            fields["alphaCutoff"] = l["cutoff"]
        return g.material(**fields)


class TexturedGltf(StressScene):
    """A StressScene with texture coordinates, textures, several cameras and its buffer in a
    .bin file beside the .gltf."""

    def __init__(self, name):
        super().__init__(name)
        self.doc["asset"]["generator"] = "mcrt scripts/scenes/make_textured_tests.py"
        self.camera_nodes = []

    def camera(self, eye, target, up, yfov_degrees):
        """As StressScene.camera, but cameras accumulate: the k-th call is camera k."""
        back = normalize(sub(eye, target))
        right = normalize(cross(up, back))
        true_up = cross(back, right)
        self.doc.setdefault("cameras", []).append({
            "type": "perspective", "name": "camera %d" % len(self.camera_nodes),
            "perspective": {"yfov": math.radians(yfov_degrees), "aspectRatio": 1.0, "znear": 1e-4}})
        matrix = [*right, 0.0, *true_up, 0.0, *back, 0.0, *eye, 1.0]
        self.camera_nodes.append(self.node(name="camera %d" % len(self.camera_nodes),
                                           camera=len(self.camera_nodes), matrix=matrix))

    def texture(self, uri, wrap, mag):
        """The index of a texture of image `uri` with this sampler (shared when equal)."""
        images = self.doc.setdefault("images", [])
        if {"uri": uri} not in images:
            images.append({"uri": uri})
        sampler = {"magFilter": mag, "minFilter": mag, "wrapS": wrap[0], "wrapT": wrap[1]}
        samplers = self.doc.setdefault("samplers", [])
        if sampler not in samplers:
            samplers.append(sampler)
        texture = {"sampler": samplers.index(sampler), "source": images.index({"uri": uri})}
        textures = self.doc.setdefault("textures", [])
        if texture not in textures:
            textures.append(texture)
        return textures.index(texture)

    def vec2(self, values):
        data = b"".join(struct.pack("<2f", *v) for v in values)
        return self.accessor(self.view(data), FLOAT, len(values), "VEC2")

    def rect(self, name, rect, material, texcoords=()):
        """A node with the rectangle as 4 indexed vertices and TEXCOORD_n from texcoords[n]:
        a uv map of the rect, or None for garbage."""
        attributes = {"POSITION": self.positions(rect.corners())}
        for n, uv_map in enumerate(texcoords):
            attributes["TEXCOORD_%d" % n] = self.vec2(
                rect.vertex_uvs(uv_map) if uv_map is not None else
                [(0.13, 0.71), (0.97, 0.05), (0.41, 0.29), (0.66, 0.88)])
        prim = {"attributes": attributes, "indices": self.indices([0, 1, 2, 0, 2, 3], USHORT),
                "material": material}
        mesh = self._add("meshes", {"name": name, "primitives": [prim]})
        self.roots.append(self.node(name=name, mesh=mesh))

    def finish(self):
        self.scene(self.camera_nodes + self.roots)
        used = set()

        def scan(x):
            if isinstance(x, dict):
                used.update(x.get("extensions", {}).keys())
                for v in x.values():
                    scan(v)
            elif isinstance(x, list):
                for v in x:
                    scan(v)
        scan(self.doc)
        self.doc["extensionsUsed"] = sorted(used)
        return self

    def write(self, path):
        """The .gltf (StressScene's layout) and its buffer as NAME.bin beside it."""
        path = Path(path)
        bin_path = path.with_suffix(".bin")
        bin_path.write_bytes(bytes(self.blob))
        blob, self.blob = self.blob, bytearray()
        self.doc["buffers"] = [{"byteLength": len(blob), "uri": bin_path.name}]
        super().write(path)
        self.blob = blob


# ----- the scenes -----------------------------------------------------------------------------------

def light_rect():
    x0, x1, z0, z1, y = LIGHT_RECT
    # u along +x, v along +z over the light, 0 … 1.
    return Rect(x0, x1, z0, z1, y, -1, (1 / (x1 - x0), -x0 / (x1 - x0), 1 / (z1 - z0), -z0 / (z1 - z0)))


def occluder_rect():
    x0, x1, z0, z1, y = OCCLUDER_RECT
    return Rect(x0, x1, z0, z1, y, +1, (1 / (x1 - x0), -x0 / (x1 - x0), 1 / (z1 - z0), -z0 / (z1 - z0)))


def floor_scene(name, purpose, texture=None, uv=(1.0, 3.0, 1.0, 3.0), uv1=None):
    s = Scene(name, purpose)
    s.floor_texture, s.floor_uv, s.floor_uv1 = texture, uv, uv1
    s.light = {"rect": light_rect(), "Le": LIGHT_LE}
    s.triangle_light = True
    if texture is not None:
        s.twin = "floor_untextured"
    return s


def light_scene(name, purpose, **light):
    s = Scene(name, purpose)
    s.light = dict({"rect": light_rect(), "Le": LIGHT_LE}, **light)
    s.cameras = [CAMERA_DOWN, CAMERA_UP]
    s.twin = "quad_floor"
    return s


CHECKER_UV = (1.0, 3.0, 1.0, 3.0)            # u = x + 3, v = z + 3: 6 repeats over the floor
TRANSFORM_UV = (0.5, 1.5, 0.5, 1.5)          # u = (x + 3)/2, before the transform's scale 2
TRANSFORM = {"offset": [0.25, 0.5], "rotation": math.pi / 2, "scale": [2.0, 2.0]}
WRAP_UV = (2.0, 0.5, 2.0, 0.5)               # u = 2x + 0.5: −1.5 at x = −1, 2.5 at x = 1


def scenes():
    out = [floor_scene("floor_untextured", "PlaneScene of tests/support/analytic_scenes.h, untextured: "
                       "the twin the checker and wrap scenes are divided by")]
    out.append(floor_scene("checker", "baseColorTexture × baseColorFactor, sRGB decoded, "
                           "NEAREST, REPEAT, TEXCOORD_0", Texture("checker4x4.png"), CHECKER_UV))
    out.append(floor_scene("checker_linear", "magFilter LINEAR: bilinear between texel centres, "
                           "after sRGB decoding", Texture("checker4x4.png", mag=LINEAR), CHECKER_UV))
    out.append(floor_scene("checker_transform", "KHR_texture_transform offset (0.25, 0.5), "
                           "rotation 90°, scale 2", Texture("checker4x4.png", transform=TRANSFORM),
                           TRANSFORM_UV))
    out.append(floor_scene("checker_texcoord1", "texCoord 1: TEXCOORD_1 carries the checker's "
                           "UVs, TEXCOORD_0 garbage", Texture("checker4x4.png", texcoord=1),
                           None, CHECKER_UV))
    out.append(floor_scene("checker_transform_texcoord1", "KHR_texture_transform.texCoord 1 "
                           "overrides textureInfo.texCoord 0 (TEXCOORD_0 garbage)",
                           Texture("checker4x4.png", transform=TRANSFORM, transform_texcoord=1),
                           None, TRANSFORM_UV))
    for wrap in [(REPEAT, REPEAT), (CLAMP, CLAMP), (MIRROR, MIRROR), (CLAMP, MIRROR),
                 (MIRROR, REPEAT)]:
        names = {REPEAT: "repeat", CLAMP: "clamp", MIRROR: "mirror"}
        name = "wrap_" + (names[wrap[0]] if wrap[0] == wrap[1] else names[wrap[0]] + "_" + names[wrap[1]])
        out.append(floor_scene(name, "wrapS %s, wrapT %s with UVs −1.5 … 2.5 over |x|, |z| ≤ 1"
                               % (WRAP_NAMES[wrap[0]], WRAP_NAMES[wrap[1]]),
                               Texture("wrap4x4.png", wrap=wrap), WRAP_UV))
    quad = light_scene("quad_floor", "the floor under the quad light alone, untextured: the twin "
                       "of the light scenes")
    quad.twin = None
    out.append(quad)
    out.append(light_scene("emissive_light", "emissiveTexture (2×2 sRGB, NEAREST) × "
                           "emissiveFactor × emissiveStrength: the light is four sub-quads",
                           emissive=Texture("emissive2x2.png")))
    out.append(light_scene("mask_light", "alphaMode MASK (cutoff 0.5) on an emitter: the holes "
                           "of its baseColorTexture alpha neither emit nor block",
                           alpha_texture=Texture("mask4x4.png"), mode="MASK", cutoff=0.5))
    out.append(light_scene("mask_cutoff_light", "MASK with alphaCutoff 0.54 on alpha bytes 100, "
                           "140, 150, 135: alpha is linear; 140 and 150 emit",
                           alpha_texture=Texture("mask_cutoff2x2.png"), mode="MASK", cutoff=0.54))
    s = light_scene("mask_occluder", "an opaque grey plane under the light, MASK (default cutoff): "
                    "light reaches the floor through its holes only")
    s.occluder = {"rect": occluder_rect(), "mode": "MASK", "texture": Texture("occluder6x6.png")}
    out.append(s)
    s = light_scene("blend_occluder", "a grey plane with baseColorFactor alpha 0.5, BLEND, under "
                    "the light: the floor's irradiance halves in expectation")
    s.occluder = {"rect": occluder_rect(), "mode": "BLEND", "alpha": 0.5}
    s.ratio_to_twin = 0.5
    out.append(s)
    s = light_scene("blend_light", "the light BLEND at baseColorFactor alpha 0.5: seen radiance "
                    "and the floor's light halve in expectation", alpha=0.5, mode="BLEND")
    s.ratio_to_twin = 0.5
    out.append(s)
    out.append(light_scene("blend_texture_light", "BLEND with alpha from a 2×2 texture (bytes 64, "
                           "128, 191, 255, linear): each sub-quad emits alpha × Le",
                           alpha_texture=Texture("blend_alpha2x2.png"), mode="BLEND"))
    return out


# ----- pixels -----------------------------------------------------------------------------------------

def camera_rays(camera, w, h, jitter):
    """(eye, directions (H, W, S, 3)) through each pixel at the jitter offsets (S, 2), DESIGN.md's
    camera contract, the camera node's float values."""
    eye, target, up, fov = camera
    back = normalize(sub(eye, target))
    right = normalize(cross(up, back))
    true_up = cross(back, right)
    eye, right, true_up, back = (f32(v) for v in (eye, right, true_up, back))
    tan_half = math.tan(float(f32(math.radians(fov))) / 2)
    j, i = np.mgrid[0:h, 0:w]
    x = (2 * (i[..., None] + jitter[:, 0]) / w - 1) * tan_half * (w / h)
    y = (1 - 2 * (j[..., None] + jitter[:, 1]) / h) * tan_half
    d = x[..., None] * right + y[..., None] * true_up - back
    return eye, d


def exact_view(scene, k, resolution=RESOLUTION):
    """(pixel means (H, W, 3), labels (H, W): the piece a pixel's grown footprint lies in, −1
    where it straddles, or None for views without pieces, all samples (H, W, S, 3)) of camera
    k of `scene`: DESIGN.md's pixels, q × q midpoint rule per pixel."""
    w, h = resolution
    q = QUADRATURE
    g = (np.arange(q) + 0.5) / q
    jitter = np.stack(np.meshgrid(g, g, indexing="xy"), -1).reshape(-1, 2)
    m = LABEL_MARGIN
    corners = np.array([[-m, -m], [1 + m, -m], [-m, 1 + m], [1 + m, 1 + m]])
    evaluate = scene.floor_value if k == 0 else scene.light_view_value
    eye, d = camera_rays(scene.cameras[k], w, h, np.concatenate([jitter, corners]))
    values, keys = evaluate(eye, d.reshape(-1, 3))
    values = values.reshape(h, w, -1, 3)
    mean = values[:, :, :q * q].mean(axis=2)
    if k == 1:  # piecewise constant: a label per distinct radiance (RGB folded into one number)
        folded = np.round(values.reshape(-1, 3), 9) @ np.array([1.0, math.sqrt(2.0), math.pi])
        keys = np.unique(folded, return_inverse=True)[1]
    labels = None
    if keys is not None:
        keys = np.asarray(keys).reshape(h, w, -1)
        labels = np.where(np.all(keys == keys[:, :, :1], axis=2), keys[:, :, 0], -1)
    return mean, labels, values


def view(scene, k):
    """What camera k of `scene` must see at RESOLUTION: exact pixel means, labels and probes."""
    mean, labels, values = exact_view(scene, k)
    out = {"camera": k, "resolution": list(RESOLUTION)}
    if labels is not None:
        out.update(label_map(scene, k, labels, mean, values))
    else:
        out["image_mean"] = rounded(mean.reshape(-1, 3).mean(axis=0))
    out["probes"] = probes(mean, out.get("labels"))
    if k == 0 and scene.twin:
        out["untextured_twin"] = scene.twin
    if k == 0 and scene.ratio_to_twin is not None:
        out["ratio_to_twin"] = scene.ratio_to_twin
    return out


def label_map(scene, k, labels, mean, values):
    """Rows of characters, one per pixel: the piece its whole footprint (grown by LABEL_MARGIN)
    lies in, '.' where it straddles; with the legend of what each piece means."""
    legend, chars = {}, {}
    for key in sorted(set(labels.ravel()) - {-1}):
        if k == 0:  # a floor texel: the ratio to the untextured twin
            t = scene.floor_texture
            w = t.pixels.shape[1]
            col, row = int(key) % w, int(key) // w
            ch = "0123456789abcdefghijklmnopqrstuvwxyz"[key]
            legend[ch] = {"texel": [col, row], "srgb": t.pixels[row, col, :3].tolist(),
                          "ratio": rounded(t.linear_rgb()[row, col])}
        else:  # a radiance seen directly
            ch = "ABCDEFGHIJKLMNOPQRSTUVWXYZ"[len(legend)]
            first = np.argwhere(labels == key)[0]
            legend[ch] = {"radiance": rounded(values[first[0], first[1], 0])}
        chars[key] = ch
    rows = ["".join(chars.get(v, ".") for v in row) for row in labels]
    meaning = ("ratio: pixel = ratio × the untextured twin's pixel (same camera), ratio the "
               "sRGB-decoded texel whose footprint covers the pixel (the twin has the same "
               "baseColorFactor)" if k == 0 else
               "radiance: the pixel's exact value (light seen directly, through the occluder)")
    return {"labels": rows, "legend": legend, "label_meaning": meaning,
            "labelled_pixels": int(np.sum(labels >= 0))}


def probes(mean, labels, count=16):
    """Pixels with their exact values: the most interior pixel of each label (up to `count`
    labels), or a 4×4 grid of pixels where there are no labels."""
    h, w = mean.shape[:2]
    out = []
    if labels is None:
        for j in range(h // 8, h, h // 4):
            for i in range(w // 8, w, w // 4):
                out.append({"pixel": [i, j], "value": rounded(mean[j, i])})
        return out
    grid = np.array([list(r) for r in labels])
    # distance (in pixels, chessboard) to the nearest pixel of another label, by erosion
    depth = np.zeros((h, w), int)
    inside = grid != "."
    cur = inside.copy()
    while cur.any():
        depth += cur
        shifted = np.pad(cur, 1, constant_values=False)
        same = np.pad(grid, 1, constant_values=".")
        keep = cur.copy()
        for dj in (-1, 0, 1):
            for di in (-1, 0, 1):
                nb = shifted[1 + dj:h + 1 + dj, 1 + di:w + 1 + di]
                nl = same[1 + dj:h + 1 + dj, 1 + di:w + 1 + di]
                keep &= nb & (nl == grid)
        cur = keep
    for ch in sorted(set(grid[inside].ravel()))[:count]:
        score = np.where(grid == ch, depth, -1)
        j, i = np.unravel_index(np.argmax(score), score.shape)
        out.append({"pixel": [int(i), int(j)], "label": ch, "value": rounded(mean[j, i])})
    return out


def rounded(v, digits=7):
    return [float("%.*g" % (digits, x)) for x in np.asarray(v, np.float64).ravel()]


# ----- EXPECTED.json and EXPECTED.md ----------------------------------------------------------------

FORMULAS = {
    "pixel": "pixel (i, j) = mean over a %d × %d midpoint rule of the jitter square of the radiance "
             "along the ray of DESIGN.md's camera contract (tests/support/analytic_scenes.h "
             "exact_pixel_image), at %d × %d" % (QUADRATURE, QUADRATURE, *RESOLUTION),
    "floor": "L = albedo(p)/π · Σ_pieces Le_piece · E_piece(p), albedo = baseColorFactor × "
             "sRGB-decoded texel (glTF 2.0 'Metallic-Roughness Material'), direct light only "
             "(--max-depth 1)",
    "lambert": "E(p) = 1/2 |Σ_i Θ_i (Γ_i · n)| for a convex polygon of unit radiance above p's "
               "horizon, Θ_i the angle edge i subtends at p, Γ_i the unit normal of the plane "
               "through p and edge i (Lambert 1760; Arvo 1995, 'Applications of Irradiance "
               "Tensors to the Simulation of Non-Lambertian Phenomena', SIGGRAPH, eq. 1; "
               "tests/support/analytic_scenes.h lambert_irradiance)",
    "srgb": "linear = c/12.92 for c ≤ 0.04045, else ((c + 0.055)/1.055)^2.4, c = byte/255 "
            "(IEC 61966-2-1); alpha is linear, byte/255",
    "nearest": "texel column = floor(wrap_s(u')·W), row = floor(wrap_t(v')·H), row 0 the image's "
               "top (glTF 2.0 'Images': uv (0, 0) is the upper left corner); REPEAT: frac; "
               "MIRRORED_REPEAT: frac, or 1 − frac when floor is odd; CLAMP_TO_EDGE: clamp to "
               "[0, W − 1] (glTF 2.0 'Wrapping')",
    "linear": "bilinear between texel centres: s = u'·W − 0.5, neighbours floor(s) and "
              "floor(s) + 1 wrapped at texel level, weights frac(s) (OpenGL 4.6 sec. 8.14.2), of "
              "the decoded values (glTF 2.0: decode before filtering)",
    "texture_transform": "u' = sx·cos(r)·u + sy·sin(r)·v + ox, v' = −sx·sin(r)·u + sy·cos(r)·v + "
                         "oy: T(offset)·R(rotation)·S(scale), R = [[cos, sin], [−sin, cos]] "
                         "(KHR_texture_transform; its example — offset (0, 1), rotation π/2, "
                         "scale 0.5 selects the lower left quadrant — fixes the sign)",
    "alpha": "MASK: opaque where alpha ≥ alphaCutoff (default 0.5), a hole otherwise: it neither "
             "emits nor blocks; BLEND: a ray passes with probability 1 − alpha, so a BLEND "
             "surface's expected emission and blocking are alpha × its own (glTF 2.0 'Alpha "
             "Coverage'); alpha = baseColorFactor.a × texture alpha",
    "light_view": "camera 1 sees the light's front face: L = Le × emissive texel × alpha weight "
                  "where the ray reaches it (through occluder holes), 0 elsewhere (opaque "
                  "occluder texels face away from the light: black in direct light)",
}


def expected(all_scenes):
    doc = {"generator": "scripts/scenes/make_textured_tests.py", "formulas": FORMULAS,
           "geometry": {"floor": "y = 0, [-3, 3]², baseColorFactor %s, Lambertian "
                                 "(metallic 0, KHR_materials_specular.specularFactor 0)" % (FLOOR_ALBEDO,),
                        "light": "x ∈ [%g, %g], z ∈ [%g, %g], y = %g, facing −Y, Le %s; its UVs "
                                 "u = (x − 0.8)/0.5, v = (z + 0.25)/0.5" % (*LIGHT_RECT, LIGHT_LE),
                        "triangle_light": "floor scenes only: %s, Le %s (PlaneScene's)" % TRIANGLE_LIGHT,
                        "occluder": "x ∈ [%g, %g], z ∈ [%g, %g], y = %g, doubleSided; its UVs "
                                    "u = (x − 0.75)/0.6, v = (z + 0.3)/0.6" % OCCLUDER_RECT,
                        "camera_0": "eye %s looking down −Y, image up −Z, yfov %g°" % (CAMERA_DOWN[0], CAMERA_DOWN[3]),
                        "camera_1": "eye %s looking up +Y, image up +Z, yfov %g° (light scenes)"
                                    % (CAMERA_UP[0], CAMERA_UP[3])},
           "scenes": {}}
    for s in all_scenes:
        entry = {"file": s.name + ".gltf", "purpose": s.purpose}
        if s.floor_texture is not None:
            t = s.floor_texture
            entry["floor_uv"] = "u = %g·x + %g, v = %g·z + %g (TEXCOORD_%d)" % (
                *(s.floor_uv1 or s.floor_uv), 1 if s.floor_uv1 else 0)
            entry["texture"] = {"image": t.image, "wrap": [WRAP_NAMES[m] for m in t.wrap],
                                "mag_filter": "NEAREST" if t.mag == NEAREST else "LINEAR",
                                "transform_matrix": rounded(t.matrix(), 9) if t.transform else None}
        entry["views"] = [view(s, k) for k in range(len(s.cameras))]
        if s.light is not None and (s.light.get("emissive") or s.light.get("alpha_texture")
                                    or s.light.get("mode")):
            entry["light_pieces"] = [{"x": rounded([x0, x1]), "z": rounded([z0, z1]), "radiance": rounded(le)}
                                     for x0, x1, z0, z1, _, le, _ in s.light_pieces()]
        if s.occluder is not None:
            entry["occluder_openings"] = [{"x": rounded([x0, x1]), "z": rounded([z0, z1]),
                                           "transmission": t} for x0, x1, z0, z1, t in s.occluder_holes()]
        doc["scenes"][s.name] = entry
    return doc


def markdown(doc):
    lines = ["# Textured test scenes: what a test must see", "",
             "Written by `scripts/scenes/make_textured_tests.py` with `EXPECTED.json` (the numbers); "
             "run it again to regenerate every file byte for byte. Pixels refer to %d × %d renders; "
             "values are linear radiance, direct light only (`--max-depth 1`)." % RESOLUTION, "",
             "## Formulas", ""]
    lines += ["- **%s**: %s" % (k, v) for k, v in doc["formulas"].items()]
    lines += ["", "## Geometry", ""] + ["- **%s**: %s" % (k, v) for k, v in doc["geometry"].items()]
    lines += ["", "## How a test uses a view", "",
              "- `labels`: one string per image row, one character per pixel: the piece (texel, "
              "or light radiance) the pixel's whole footprint, grown by %g pixel, lies in; `.` "
              "where it straddles. `legend` says what each character means: for the floor "
              "(camera 0) the `ratio` of the pixel to the same pixel of `untextured_twin` "
              "(rendered with the same camera, seed and estimator it is exact up to float "
              "rounding when the textured kernels draw the same random numbers; otherwise "
              "within both images' variance layers), for the light view (camera 1) the pixel's "
              "exact `radiance`." % LABEL_MARGIN,
              "- `probes`: pixels with their exact values (the pixel mean of the formulas above).",
              "- `image_mean`: the exact mean of the whole image (views without labels).",
              "- `ratio_to_twin`: every pixel is this times the twin's pixel (in expectation).",
              "", "## Scenes", "",
              "| scene | purpose | camera 0 (floor) | camera 1 (light) |", "| --- | --- | --- | --- |"]
    for name, e in doc["scenes"].items():
        cells = []
        for v in e["views"]:
            if "legend" in v:
                what = "%d labelled pixels, %d labels" % (v["labelled_pixels"], len(v["legend"]))
                if v["camera"] == 1:
                    what += ": " + ", ".join("%s %s" % (c, fmt(l["radiance"])) for c, l in v["legend"].items())
            else:
                what = "mean %s" % fmt(v["image_mean"])
            if "ratio_to_twin" in v:
                what += "; %g × %s" % (v["ratio_to_twin"], v["untextured_twin"])
            elif "untextured_twin" in v:
                what += "; ratio to %s" % v["untextured_twin"]
            cells.append(what)
        cells += [""] * (2 - len(cells))
        lines.append("| `%s` | %s | %s | %s |" % (name, e["purpose"], cells[0], cells[1]))
    return "\n".join(lines) + "\n"


def compact_json(doc, width=100):
    """JSON with every object or list that fits in `width` characters on one line."""
    def dump(x, indent):
        flat = json.dumps(x, ensure_ascii=False)
        if len(flat) + indent <= width or not isinstance(x, (dict, list)) or not x:
            return flat
        pad = " " * (indent + 1)
        if isinstance(x, dict):
            items = ["%s%s: %s" % (pad, json.dumps(k), dump(v, indent + 1)) for k, v in x.items()]
            return "{\n" + ",\n".join(items) + "\n" + " " * indent + "}"
        return "[\n" + ",\n".join(pad + dump(v, indent + 1) for v in x) + "\n" + " " * indent + "]"
    return dump(doc, 0) + "\n"


def fmt(v):
    return "(" + ", ".join("%.4g" % x for x in v) + ")"


def main():
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "tests" / "data" / "textured"
    out.mkdir(parents=True, exist_ok=True)
    for name, make in IMAGES.items():
        (out / name).write_bytes(png_bytes(make()))
    all_scenes = scenes()
    for s in all_scenes:
        s.gltf().write(out / (s.name + ".gltf"))
    doc = expected(all_scenes)
    (out / "EXPECTED.json").write_text(compact_json(doc))
    (out / "EXPECTED.md").write_text(markdown(doc))
    total = sum(p.stat().st_size for p in out.iterdir() if p.is_file())
    print("wrote %d scenes, %d images to %s (%d bytes)" % (len(all_scenes), len(IMAGES), out, total))


if __name__ == "__main__":
    main()

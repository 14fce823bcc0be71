#!/usr/bin/python3
"""An independent reference: render a glTF scene with Mitsuba 3's `direct` integrator.

Converts the scene as mcrt reads it (docs/DESIGN.md, radiometric and camera contracts) into a
Mitsuba 3 scene and renders it:

  geometry   every triangle primitive of the default scene, node transforms applied (matrix or
             TRS), written as binary PLY meshes in world space (one per material), flat shaded
             (`face_normals`), so the shading normal is the geometric one, as in mcrt;
  materials  `twosided` `diffuse` with reflectance = baseColorFactor RGB (mcrt shades both faces,
             the normal flipped toward the ray; Mitsuba's diffuse alone is one-sided): mcrt's
             `--materials lambert`, which --equal-time passes to mcrt. With --materials gltf,
             a metal (metallicFactor 1) is `twosided` `roughconductor` with material "none"
             (Fresnel 1), specular_reflectance = baseColor, distribution ggx, alpha =
             max(roughness^2, 1e-3), visible-normal sampling: glTF's metal exactly when
             baseColor is 1 (Schlick with F0 = 1 is 1), up to Smith's G (Mitsuba's is
             separable, glTF's height-correlated); a Lambertian surface (metallic 0,
             KHR_materials_specular.specularFactor 0) stays diffuse; any other material has no
             Mitsuba equivalent and is refused;
  emitters   `area` with radiance = emissiveFactor × KHR_materials_emissive_strength. Mitsuba's
             area emitters emit on the front side of the mesh normal, which for a PLY mesh is
             cross(p1 − p0, p2 − p0): glTF's counter-clockwise front, as mcrt. A `doubleSided`
             emitter gets a second, flipped copy 1e-6·diag behind it;
  camera     the first camera node (or the bench camera of DESIGN.md), `perspective` with
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
           [--materials lambert|gltf]
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


# ----- a minimal glTF reader ---------------------------------------------------------------------

class Gltf:
    """What mcrt reads of a glTF 2.0 file: triangles in world space with their material, the
    materials' baseColorFactor / emission / doubleSided, and the first camera."""

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

    def triangles(self):
        """material index (−1: the default material) → (n, 3, 3) world-space triangles."""
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
                p = self.accessor(prim["attributes"]["POSITION"]).astype(np.float64)
                p = p @ world[:3, :3].T + world[:3, 3]
                if "indices" in prim:
                    idx = self.accessor(prim["indices"]).reshape(-1).astype(np.int64)
                else:
                    idx = np.arange(len(p))
                if mode == 4:
                    tri = idx[:len(idx) // 3 * 3].reshape(-1, 3)
                elif mode == 5:  # strip: every other triangle reversed to keep the winding
                    tri = np.array([(idx[i], idx[i + 1], idx[i + 2]) if i % 2 == 0 else
                                    (idx[i + 1], idx[i], idx[i + 2]) for i in range(len(idx) - 2)])
                else:  # fan
                    tri = np.array([(idx[0], idx[i], idx[i + 1]) for i in range(1, len(idx) - 1)])
                if len(tri) == 0:
                    continue
                if np.linalg.det(world[:3, :3]) < 0:  # a mirroring transform flips the winding
                    tri = tri[:, [0, 2, 1]]
                out.setdefault(prim.get("material", -1), []).append(p[tri])
        return {m: np.concatenate(t) for m, t in out.items()}

    def material(self, index):
        """(albedo RGB, emitted radiance RGB, doubleSided) of a material; glTF's default
        material for −1."""
        m = self.doc["materials"][index] if index >= 0 else {}
        albedo = m.get("pbrMetallicRoughness", {}).get("baseColorFactor", [1, 1, 1, 1])[:3]
        strength = m.get("extensions", {}).get("KHR_materials_emissive_strength", {}) \
            .get("emissiveStrength", 1.0)
        emission = [c * strength for c in m.get("emissiveFactor", [0, 0, 0])]
        return albedo, emission, bool(m.get("doubleSided", False))

    def camera(self, bounds):
        """(eye, forward, up, yfov radians): the first camera node, else the bench camera."""
        for node, world in self.walk():
            if "camera" in node:
                cam = self.doc["cameras"][node["camera"]]
                if cam.get("type") != "perspective":
                    continue
                eye = world[:3, 3]
                forward = -world[:3, 2] / np.linalg.norm(world[:3, 2])
                up = world[:3, 1] / np.linalg.norm(world[:3, 1])
                return eye, forward, up, cam["perspective"]["yfov"]
        lo, hi = bounds
        c, diag = (lo + hi) / 2, np.linalg.norm(hi - lo)
        eye = c + diag * np.array([0.35, 0.30, 0.55])
        forward = (c - eye) / np.linalg.norm(c - eye)
        return eye, forward, np.array([0.0, 1.0, 0.0]), math.radians(45.0)


DEBIAN_LLVM19 = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"


def write_ply(path, triangles):
    """Binary PLY of unshared vertices (flat shading needs nothing more)."""
    n = len(triangles)
    header = ("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\n"
              "property float y\nproperty float z\nelement face %d\n"
              "property list uchar int vertex_indices\nend_header\n" % (3 * n, n)).encode()
    vertices = triangles.reshape(-1, 3).astype("<f4").tobytes()
    faces = np.zeros(n, dtype=[("k", "u1"), ("i", "<i4", (3,))])
    faces["k"] = 3
    faces["i"] = np.arange(3 * n, dtype=np.int64).reshape(n, 3)
    Path(path).write_bytes(header + vertices + faces.tobytes())


# ----- the Mitsuba scene -------------------------------------------------------------------------

def mitsuba_bsdf(material, albedo, materials):
    """The Mitsuba BSDF of a glTF material (see "materials" above)."""
    diffuse = {"type": "twosided", "material": {"type": "diffuse", "reflectance":
                                                {"type": "rgb", "value": list(albedo)}}}
    if materials == "lambert":
        return diffuse
    pbr = material.get("pbrMetallicRoughness", {})
    metallic = pbr.get("metallicFactor", 1.0)
    roughness = pbr.get("roughnessFactor", 1.0)
    specular = material.get("extensions", {}).get("KHR_materials_specular", {}) \
        .get("specularFactor", 1.0)
    if metallic == 0.0 and specular == 0.0:
        return diffuse
    if metallic == 1.0:
        if any(abs(c - 1.0) > 1e-6 for c in albedo):
            print("mitsuba_reference: warning: %s: a coloured metal's Schlick Fresnel rises to 1 "
                  "at grazing, Mitsuba's constant one does not: approximate"
                  % material.get("name", "material"), file=sys.stderr)
        return {"type": "twosided", "material": {
            "type": "roughconductor", "material": "none", "distribution": "ggx",
            "alpha": max(roughness * roughness, 1e-3), "sample_visible": True,
            "specular_reflectance": {"type": "rgb", "value": list(albedo)}}}
    raise mcrt_run.ScriptError(
        "%s: metallic %g with a specular layer: glTF's dielectric (a Lambertian base under a "
        "Schlick-weighted GGX layer) has no Mitsuba 3 equivalent; use --materials lambert"
        % (material.get("name", "material"), metallic))


def integrator(max_depth, rr_depth, emitter_samples=1, bsdf_samples=1):
    """Mitsuba's integrator for mcrt's --max-depth (reflections): `direct` at 1 (emitter_samples
    light and bsdf_samples BSDF samples per pixel sample; 1 and 0 is light sampling alone), else
    `path`."""
    if max_depth <= 1:
        return {"type": "direct", "hide_emitters": False, "emitter_samples": emitter_samples,
                "bsdf_samples": bsdf_samples}
    return {"type": "path", "max_depth": max_depth + 1, "rr_depth": rr_depth,
            "hide_emitters": False}


def mitsuba_scene(mi, gltf, width, height, spp, scratch, max_depth=1, rr_depth=5, sky=None,
                  materials="lambert", integrator_desc=None):
    """(scene dict, emitter count) of a glTF; PLY meshes are written to `scratch`. The
    integrator is integrator_desc when given, else integrator(max_depth, rr_depth)."""
    triangles = gltf.triangles()
    if not triangles:
        raise ValueError("the scene has no triangles")
    allp = np.concatenate([t.reshape(-1, 3) for t in triangles.values()])
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    diag = float(np.linalg.norm(hi - lo))
    eye, forward, up, yfov = gltf.camera((lo, hi))
    scene = {
        "type": "scene",
        "integrator": integrator_desc or integrator(max_depth, rr_depth),
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
    for k, (material, tri) in enumerate(sorted(triangles.items())):
        albedo, emission, double_sided = gltf.material(material)
        bsdf = mitsuba_bsdf(gltf.doc["materials"][material] if material >= 0 else {}, albedo,
                            materials)
        copies = [(tri, "")]
        if max(emission) > 0 and double_sided:
            n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
            n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
            copies.append((tri[:, [0, 2, 1]] - 1e-6 * diag * n[:, None, :], "-back"))
        for t, suffix in copies:
            ply = Path(scratch) / ("mesh%d%s.ply" % (k, suffix))
            write_ply(ply, t)
            shape = {"type": "ply", "filename": str(ply), "face_normals": True, "bsdf": bsdf}
            if max(emission) > 0:
                shape["emitter"] = {"type": "area",
                                    "radiance": {"type": "rgb", "value": list(emission)}}
                emitters += 1
            scene["shape%d%s" % (k, suffix)] = shape
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
               materials="lambert", integrator_desc=None):
    """(loaded Mitsuba scene, emitter count, seconds of mi.load_dict) of the glTF at `path`
    (mitsuba_scene's arguments)."""
    gltf = Gltf(path)
    with tempfile.TemporaryDirectory(prefix="mcrt-mitsuba-") as scratch:
        desc, emitters = mitsuba_scene(mi, gltf, width, height, spp, scratch, max_depth,
                                       rr_depth, sky, materials, integrator_desc)
        start = time.monotonic()
        scene = mi.load_dict(desc)
        return scene, emitters, time.monotonic() - start


def render(args):
    mi = import_mitsuba(args.variant)
    passes = max(1, min(args.passes, args.spp))
    spp_pass = args.spp // passes
    scene, emitters, seconds_load = load_scene(mi, args.scene, args.width, args.height, spp_pass,
                                               args.max_depth, args.rr_depth, args.sky,
                                               args.materials)
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
            "integrator": ("direct (emitter_samples=1, bsdf_samples=1, MIS)" if args.max_depth <= 1
                           else "path (max_depth=%d, rr_depth=%d)" % (args.max_depth + 1,
                                                                       args.rr_depth)),
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
                "--materials", args.materials] + shlex.split(options),
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
    p.add_argument("--materials", choices=["lambert", "gltf"], default="lambert",
                   help="how surfaces are converted (see materials above; default lambert)")
    p.add_argument("--max-depth", type=int, default=1,
                   help="reflections, as mcrt's --max-depth: 1 is `direct`, N > 1 `path` with "
                   "max_depth N + 1")
    p.add_argument("--rr-depth", type=int, default=5, help="with --max-depth > 1: `path`'s rr_depth")
    p.add_argument("--sky", type=lambda t: [float(x) for x in (t.split(",") * 3)[:3]],
                   help="R,G,B (or one value): a `constant` emitter, as mcrt's --sky light")
    p.add_argument("--compare", help="an mcrt EXR of the same size to compare with")
    p.add_argument("--diff-png", help="with --compare: write the difference image here")
    p.add_argument("--equal-time", metavar="REF.exr",
                   help="also render with mcrt for Mitsuba's time and compare both with REF.exr")
    mcrt_run.add_mcrt_option(p)
    p.add_argument("--mcrt-args", action="append",
                   help="mcrt render options for --equal-time, repeatable (default: --estimator "
                   "mis --sampler sobol --light-select power)")
    args = p.parse_args()
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

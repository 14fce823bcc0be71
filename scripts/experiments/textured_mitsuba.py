#!/usr/bin/python3
"""mcrt against Mitsuba 3 on the textured Sponza and DamagedHelmet (docs/EXPERIMENTS.md,
"Textured scenes"), both sides Lambertian (mcrt --materials lambert: every surface
baseColor/π with its textures, normal maps and alpha kept; mitsuba_reference.py --materials
lambert converts the same), under a uniform sky of radiance 1, by direct light (Mitsuba
`direct`, or `volpath` where alpha needs null surfaces) and by paths of 3 reflections
(`path`/`volpath` with max_depth 4), independent samples on both sides.

Each case is rendered twice on each side: as the file is, and from a copy without its
normalTexture (temporary folder, links to the model's files), which separates what the normal
maps do from the rest of the texture path. Mitsuba's normalmap builds its tangent frame from the
triangle's dp/du; mcrt from the TANGENT attribute, or tangents generated in the manner of
MikkTSpace where there is none (DamagedHelmet), interpolated across the triangle, as glTF asks:
the two shade a normal-mapped pixel with slightly different normals.

Per case: the image means and their relative difference with its standard error (both variance
layers: mcrt's of its samples, Mitsuba's of its 16 passes), over the whole image and over the
pixels with noise (the model; the sky seen directly is exactly 1 on both); the share of pixel
values more than 4 standard errors apart and the mean z²; and per region — blocks of 16 × 16
pixels — the number of blocks whose mean differs by more than 3 standard errors and the largest.
For DamagedHelmet it also prints the pixel
centres where the viewer is below the normal as Mitsuba's normalmap bends it (there Mitsuba's
BSDF is 0 and mcrt turns the normal back), both images' means there and their share of the
difference. Writes the difference images of mitsuba_reference.py to --out.

Usage: scripts/experiments/textured_mitsuba.py --mitsuba-python /path/to/venv/bin/python
           [--scenes DIR] [--only sponza-1,helmet-3,...] [--spp-scale 1] [--mcrt BIN] [--out DIR]
"""

import argparse
import contextlib
import math
import os
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))  # mcrt_run, mcrt_exr
import mcrt_run  # noqa: E402

mcrt_run.require("numpy", "matplotlib")
import numpy as np  # noqa: E402

import mitsuba_reference  # noqa: E402  compare(), read_hwc(): no Mitsuba needed for these
from textured_checks import Camera, Hits, Texture, edited  # noqa: E402

ROOT = mcrt_run.ROOT
DEFAULT_SCENES = ROOT.parent / "shared" / "scenes" / "textured"
DEBIAN_LLVM19 = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"

SPONZA_VIEW = ["--look-from", "9.2,1.44,-0.32", "--look-at=-11.2,1.44,0", "--fov", "55"]
HELMET_VIEW = ["--look-from", "2.0,0.6,2.2", "--look-at=0,0,0", "--fov", "38"]

# name → (scene file, view, width, height, depth, spp): spp sized to about a minute a side here.
CASES = {
    "helmet-1": ("DamagedHelmet/DamagedHelmet.gltf", HELMET_VIEW, 96, 96, 1, 1024),
    "helmet-3": ("DamagedHelmet/DamagedHelmet.gltf", HELMET_VIEW, 96, 96, 3, 512),
    "sponza-1": ("Sponza/Sponza.gltf", SPONZA_VIEW, 96, 72, 1, 1024),
    "sponza-3": ("Sponza/Sponza.gltf", SPONZA_VIEW, 96, 72, 3, 512),
}
BLOCK = 16


def without_normal_maps(doc):
    for material in doc.get("materials", []):
        material.pop("normalTexture", None)


def viewer_below_mitsuba_normal(path, view, width, height):
    """Pixel centres (of the model) where the viewer is below the normal as Mitsuba's normalmap
    bends it — the tangent-space normal in the frame (dp/du made orthogonal to the interpolated
    normal, n × that, n), green flipped where the tangent frame is mirrored, as
    mitsuba_reference.py converts it: Mitsuba's diffuse BSDF is 0 there, while mcrt turns the
    normal back toward the viewer (docs/MATERIALS.md, "Normal textures"). Returns the masks of
    those pixels and of the model's."""
    gltf = mitsuba_reference.Gltf(path)
    eye = np.array([float(v) for v in view[1].split(",")])
    target = np.array([float(v) for v in view[2].split("=")[-1].split(",")])
    cam = Camera(eye, target - eye, (0, 1, 0), math.radians(float(view[4])), width, height)
    hits = Hits(gltf, cam)
    model = hits.mat >= 0
    parts = [c for cs in gltf.primitives().values() for c in cs]
    n = hits.interpolate(np.concatenate([c.normals for c in parts]))
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    p, uv = hits.tri, hits.uv[0]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    d1, d2 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    dp_du = (d2[:, 1:2] * e1 - d1[:, 1:2] * e2) / np.where(det == 0, 1, det)[:, None]
    t = dp_du[hits._safe]
    t -= n * (t * n).sum(-1, keepdims=True)
    t /= np.maximum(np.linalg.norm(t, axis=-1, keepdims=True), 1e-12)
    hand = np.concatenate([c.handedness(0) for c in parts])[hits._safe]
    b = np.cross(n, t) * hand[..., None]
    material = gltf.doc["materials"][0]
    c = Texture(gltf, material["normalTexture"], srgb=False).sample(hits.texcoord(0))[..., :3]
    c = c * 2 - 1
    bent = c[..., 0:1] * t + c[..., 1:2] * b + c[..., 2:3] * n
    py, px = np.mgrid[0:height, 0:width] + 0.5
    wi = -cam.rays(px, py)
    ng = hits.geometric_normal()
    # Both sides shade the face toward the viewer: the frame turned to that side.
    side = np.sign((ng * wi).sum(-1)) * np.sign((bent * ng).sum(-1))
    return model & ((bent * wi).sum(-1) * side <= 0), model


def analyse(mcrt_path, mitsuba_path, png):
    """mitsuba_reference.compare's numbers, and the same over the pixels with noise and per
    block."""
    mi_rgb, mi_var = mitsuba_reference.read_hwc(mitsuba_path)
    result = mitsuba_reference.compare(mi_rgb, mi_var, mcrt_path, png)
    mc_rgb, mc_var = mitsuba_reference.read_hwc(mcrt_path)
    diff, var = mc_rgb - mi_rgb, mc_var + mi_var
    noisy = var.sum(axis=-1) > 0
    result["model_pixels"] = int(noisy.sum())
    result["model_relative_difference"] = float(diff[noisy].sum() / mi_rgb[noisy].sum())
    result["model_relative_difference_stderr"] = float(
        math.sqrt(var[noisy].sum()) / mi_rgb[noisy].sum())
    z = diff[noisy] / np.sqrt(var[noisy] + (1e-5 * mi_rgb[noisy]) ** 2)
    result["model_beyond_4_sigma"] = float(np.mean(np.abs(z) > 4))
    result["model_mean_z2"] = float(np.mean(z ** 2))
    h, w = noisy.shape
    blocks = []
    for y in range(0, h, BLOCK):
        for x in range(0, w, BLOCK):
            sel = np.zeros_like(noisy)
            sel[y:y + BLOCK, x:x + BLOCK] = True
            sel &= noisy
            if sel.sum() < BLOCK * BLOCK // 4:
                continue
            d, v, ref = diff[sel].sum(), var[sel].sum(), mi_rgb[sel].sum()
            blocks.append((d / math.sqrt(v), d / ref, x, y))
    result["blocks"] = len(blocks)
    result["blocks_beyond_3_sigma"] = sum(abs(b[0]) > 3 for b in blocks)
    result["block_largest"] = max(blocks, key=lambda b: abs(b[0])) if blocks else None
    return result


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog=__doc__.split("\n\n", 1)[1])
    p.add_argument("--scenes", default=str(DEFAULT_SCENES),
                   help="folder of the textured scenes (default ../shared/scenes/textured)")
    p.add_argument("--only", type=mcrt_run.comma_list, help="cases, of %s" % ", ".join(CASES))
    p.add_argument("--normal-maps", default="with,without",
                   help="'with', 'without' or both (default)")
    p.add_argument("--spp-scale", type=float, default=1.0, help="multiplies every case's spp")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--mitsuba-python", default=str(ROOT / ".venv-mitsuba" / "bin" / "python"),
                   help="a Python with Mitsuba 3 (default .venv-mitsuba/bin/python)")
    p.add_argument("--out", type=mcrt_run.output_directory, default=str(ROOT / "out" / "textured-mitsuba"))
    mcrt_run.add_mcrt_option(p)
    args = p.parse_args()
    scenes = Path(args.scenes)
    if not scenes.is_dir():
        print("textured_mitsuba: %s is absent: nothing to compare" % scenes)
        return 0
    if not os.access(args.mitsuba_python, os.X_OK):
        raise mcrt_run.ScriptError("%s is not a Python: pass --mitsuba-python (a venv with "
                                   "scripts/tools/requirements-mitsuba.txt)" % args.mitsuba_python)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ)
    if Path(DEBIAN_LLVM19).exists():
        env.setdefault("DRJIT_LIBLLVM_PATH", DEBIAN_LLVM19)
    print("| case | normal maps | size, spp | mcrt mean, s | Mitsuba mean, s | relative difference"
          " of image means | of the model's pixels | values beyond 4σ | mean z² | 16² blocks "
          "beyond 3σ | largest block |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for name in args.only or list(CASES):
        if name not in CASES:
            raise mcrt_run.ScriptError("no case %s (one of %s)" % (name, ", ".join(CASES)))
        scene, view, width, height, depth, spp = CASES[name]
        spp = max(16, int(round(spp * args.spp_scale / 16)) * 16)
        path = scenes / scene
        if not path.exists():
            print("textured_mitsuba: %s is absent: skipped" % path)
            continue
        for normal_maps in mcrt_run.comma_list(args.normal_maps):
            stem = out / ("%s-%s-normal-maps" % (name, normal_maps))
            with contextlib.ExitStack() as stack:
                scene_path = path if normal_maps == "with" else \
                    stack.enter_context(edited(path, without_normal_maps))
                r = mcrt_run.render(scene_path, stem, [
                    "--width", width, "--height", height, "--spp", spp, "--sky", 1,
                    "--estimator", "mis", "--max-depth", depth, "--materials", "lambert",
                    "--seed", args.seed] + view, mcrt=args.mcrt)
                command = [args.mitsuba_python, str(ROOT / "scripts/tools/mitsuba_reference.py"),
                           str(scene_path), "--variant", "llvm_ad_rgb", "--materials", "lambert",
                           "--sky", "1", "--max-depth", str(depth), "--width", str(width),
                           "--height", str(height), "--spp", str(spp), "--passes", "16",
                           "--seed", str(args.seed), "--out", str(stem) + "-mitsuba.exr"] + view
                start = time.monotonic()
                done = subprocess.run(command, env=env, capture_output=True, text=True)
                if done.returncode != 0:
                    raise mcrt_run.ScriptError("%s exited %d: %s" % (
                        " ".join(command), done.returncode, done.stderr.strip()[-500:]))
                mitsuba_seconds = time.monotonic() - start
            res = analyse(str(stem) + ".exr", str(stem) + "-mitsuba.exr",
                          str(stem) + "-diff.png")
            largest = res["block_largest"]
            print("| %s | %s | %d×%d, %d | %.6g, %.0f | %.6g, %.0f | %+.3f%% ± %.3f%% (%+.1fσ) | "
                  "%+.3f%% ± %.3f%% (%+.1fσ) | %.2f%% | %.2f | %d of %d | %+.1fσ (%+.2f%%) at "
                  "x %d, y %d |" % (
                      name, normal_maps, width, height, spp, res["mcrt_image_mean"],
                      r.wall_seconds, res["mitsuba_image_mean"], mitsuba_seconds,
                      100 * res["relative_difference_of_means"],
                      100 * res["relative_difference_of_means_stderr"],
                      res["relative_difference_of_means"]
                      / res["relative_difference_of_means_stderr"],
                      100 * res["model_relative_difference"],
                      100 * res["model_relative_difference_stderr"],
                      res["model_relative_difference"] / res["model_relative_difference_stderr"],
                      100 * res["model_beyond_4_sigma"], res["model_mean_z2"],
                      res["blocks_beyond_3_sigma"], res["blocks"], largest[0],
                      100 * largest[1], largest[2], largest[3]), flush=True)
        if name.startswith("helmet") and "with" in mcrt_run.comma_list(args.normal_maps):
            below, model = viewer_below_mitsuba_normal(path, view, width, height)
            stem = out / ("%s-with-normal-maps" % name)
            mc = mitsuba_reference.read_hwc(str(stem) + ".exr")[0]
            mi = mitsuba_reference.read_hwc(str(stem) + "-mitsuba.exr")[0]
            ys, xs = np.nonzero(below)
            keys, counts = np.unique(np.stack([xs // BLOCK * BLOCK, ys // BLOCK * BLOCK], -1),
                                     axis=0, return_counts=True)
            block = keys[np.argmax(counts)] if len(ys) else ("—", "—")
            share = (mc - mi)[below].sum() / (mc - mi)[model].sum()
            print("textured_mitsuba: %s: the viewer is below Mitsuba's bent normal at %d of the "
                  "model's %d pixel centres (%.2f%%), most in the block at x %s, y %s; mean "
                  "there mcrt %.4f, Mitsuba %.4f; %.0f%% of the model's summed difference"
                  % (name, below.sum(), model.sum(), 100 * below.sum() / model.sum(), *block,
                     mc[below].mean(), mi[below].mean(), 100 * share))
    return 0


if __name__ == "__main__":
    sys.exit(mcrt_run.script_main(main))

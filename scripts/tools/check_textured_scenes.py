#!/usr/bin/python3
"""Renders the analytic textured scenes of tests/data/textured/ with Mitsuba 3 (through
mitsuba_reference.py's conversion) and compares every pixel with its exact value: a check of
the scenes' closed forms (scripts/scenes/make_textured_tests.py) and of the conversion at once.

Per scene and camera, over the pixels EXPECTED.json labels (views with pieces) or every pixel
(smooth views): the relative difference of the pixel sums (Mitsuba / exact − 1, with its standard
error from the passes' spread), the mean z² of (Mitsuba − exact) / σ (1 when the difference is
noise), the share of pixels within 3 σ, and for each label the ratio of Mitsuba's mean to the
exact one. Pixels whose exact value is 0 must be 0 (no σ: Mitsuba's are exact there).

Usage: scripts/tools/check_textured_scenes.py [--spp N] [--passes P] [--variant V]
           [--scenes a,b] [--json OUT.json]
"""

import argparse
import json
import math
import sys
from pathlib import Path

import mcrt_run

mcrt_run.require("numpy")
import numpy as np  # noqa: E402

import mitsuba_reference as mref  # noqa: E402

sys.path.insert(0, str(mcrt_run.ROOT / "scripts" / "scenes"))
import make_textured_tests as tex  # noqa: E402

DATA = mcrt_run.ROOT / "tests" / "data" / "textured"
FLOAT_SUM_ROUNDING = 1e-5


def render(mi, path, camera, spp, passes, seed):
    """(passes, H, W, 3): `passes` Mitsuba renders at RESOLUTION, seeds seed, seed + 1, …"""
    w, h = tex.RESOLUTION
    scene, _, _ = mref.load_scene(mi, path, w, h, spp, camera=camera)
    return np.array([np.array(mi.render(scene, spp=spp, seed=seed + p), np.float64)[..., :3]
                     for p in range(passes)])


def compare(images, exact, labels):
    """The statistics of the module's docstring over the compared pixels of the passes'
    images; the sums' standard error from the spread of the passes' sums (a pixel's channels,
    and its neighbours through shared samples, are correlated)."""
    passes = len(images)
    mean, var = images.mean(axis=0), images.var(axis=0, ddof=1) / passes
    mask = np.ones(exact.shape[:2], bool) if labels is None else labels >= 0
    zero = mask & np.all(exact == 0, axis=2)
    live = mask & ~zero
    d, s2 = (mean - exact)[live], var[live]
    # Mitsuba's film adds a pixel's samples in float32: a noiseless pixel (a light seen
    # directly) is its exact value to about spp · 2^-24 relative.
    rounding = FLOAT_SUM_ROUNDING * np.abs(exact[live])
    sums = images[:, live].reshape(passes, -1).sum(axis=1)
    sum_rel = float(sums.mean() / exact[live].sum() - 1)
    sum_rel_se = float(sums.std(ddof=1) / math.sqrt(passes) / exact[live].sum())
    ok = s2 > 0
    out = {"pixels": int(live.sum()), "relative_difference_of_sums": sum_rel,
           "stderr": sum_rel_se,
           "mean_z2": float(np.mean(d[ok] ** 2 / s2[ok])) if ok.any() else None,
           "within_3_sigma": float(np.mean(np.abs(d) <= 3 * np.sqrt(s2) + rounding)),
           "zero_pixels": int(zero.sum()),
           "max_at_zero_pixels": float(np.abs(mean[zero]).max()) if zero.any() else 0.0}
    if labels is not None:
        per = {}
        for key in sorted(set(labels[live].ravel())):
            sel = live & (labels == key)
            per[int(key)] = float(mean[sel].sum() / exact[sel].sum())
        out["ratio_per_label"] = per
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog=__doc__.split("\n\n", 1)[1])
    p.add_argument("--spp", type=int, default=256, help="samples per pixel of each pass")
    p.add_argument("--passes", type=int, default=8)
    p.add_argument("--variant", default="llvm_ad_rgb")
    p.add_argument("--seed", type=int, default=0, help="the first pass's seed")
    p.add_argument("--scenes", type=mcrt_run.comma_list, help="default: all")
    p.add_argument("--json", help="write the results here")
    args = p.parse_args()
    mref.use_mitsuba_venv(__file__)
    mi = mref.import_mitsuba(args.variant)
    results = {}
    worst = 0.0
    for scene in tex.scenes():
        if args.scenes and scene.name not in args.scenes:
            continue
        for k in range(len(scene.cameras)):
            exact, labels, _ = tex.exact_view(scene, k)
            images = render(mi, DATA / (scene.name + ".gltf"), k, args.spp, args.passes,
                            args.seed + 7919 * k)
            r = compare(images, exact, labels)
            results["%s/camera%d" % (scene.name, k)] = r
            # float rounding bounds the error of a noiseless comparison
            worst = max(worst, abs(r["relative_difference_of_sums"])
                        / max(r["stderr"], FLOAT_SUM_ROUNDING))
            print("%-32s cam %d  %5d px  sum %+.5f ± %.5f  z² %s  3σ %.3f  zero px %d (max %.2g)"
                  % (scene.name, k, r["pixels"], r["relative_difference_of_sums"], r["stderr"],
                     "%.2f" % r["mean_z2"] if r["mean_z2"] is not None else "-",
                     r["within_3_sigma"], r["zero_pixels"], r["max_at_zero_pixels"]))
    print("largest |difference of sums| / stderr: %.2f" % worst)
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1) + "\n")


if __name__ == "__main__":
    sys.exit(mcrt_run.script_main(main))

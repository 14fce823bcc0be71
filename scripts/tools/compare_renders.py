#!/usr/bin/python3
"""Renders every estimator x light selection x sampler (x MIS heuristic) of the table of
variants with two mcrt binaries and compares the images bit for bit: what a refactor of the
kernels or the host must leave unchanged.

    scripts/tools/compare_renders.py --baseline OLD/mcrt [--mcrt build/mcrt] [--scene S.gltf]
        [--size 48] [--spp 32] [--seed 7] [--only mis,light-area] [--selections power]
        [--samplers independent] [--heuristics balance]
        [--options "--sky 1 --max-depth 8"] [--new-options "--materials lambert"]

The variants come from the new binary's `mcrt variants --json`, less the estimators and light
selections the old one does not have; both are given the same command-line names and
--options, the new one also --new-options. Prints one line per render and exits 1 when any image
differs; for an image that differs, also its mean's relative change and that change's standard
error (the pixels' differences are independent: each pixel has its own samples), so that a
change in what the renderer computes stands apart from the noise of moving a few samples.
"""

import argparse
import sys
import tempfile
from pathlib import Path

import mcrt_run

mcrt_run.require("numpy")
import numpy as np  # noqa: E402

from mcrt_exr import read_exr  # noqa: E402


def renders(args):
    """(label, options) of every combination."""
    table = mcrt_run.variants(args.mcrt)
    old_table = mcrt_run.variants(args.baseline)
    old = set(e["name"] for e in old_table["estimators"])
    old_names = lambda key: set(r["name"] for r in old_table.get(key, []))  # noqa: E731
    only = set(args.only.split(",")) if args.only else None
    keep = lambda given, name: not given or name in given.split(",")  # noqa: E731
    for e in table["estimators"]:
        if (only and e["name"] not in only) or e["name"] not in old:
            continue
        selections = [n for n in mcrt_run.names("light_select", mcrt=args.mcrt)
                      if n in old_names("light_select") and keep(args.selections, n)]
        heuristics = (mcrt_run.names("mis_heuristics", mcrt=args.mcrt)
                      if "mis-heuristic" in e["uses"] else ["balance"])
        for select in selections:
            for sampler in [n for n in mcrt_run.names("samplers", mcrt=args.mcrt)
                            if keep(args.samplers, n)]:
                for h in [n for n in heuristics if keep(args.heuristics, n)]:
                    yield ("%s %s %s %s" % (e["name"], select, sampler, h),
                           ["--estimator", e["name"], "--light-select", select, "--sampler",
                            sampler, "--mis-heuristic", h])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--baseline", required=True, help="the mcrt binary before the change")
    parser.add_argument("--mcrt", default=mcrt_run.default_mcrt(), help="the binary after it")
    parser.add_argument("--scene", default=str(mcrt_run.ROOT / "scenes" / "cornell" /
                                               "CornellBox-Original.gltf"))
    parser.add_argument("--size", type=int, default=48)
    parser.add_argument("--spp", type=int, default=32)
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--only", help="comma-separated estimators to compare")
    parser.add_argument("--selections", help="comma-separated light selections to compare")
    parser.add_argument("--samplers", help="comma-separated samplers to compare")
    parser.add_argument("--heuristics", help="comma-separated MIS heuristics to compare")
    parser.add_argument("--options", default="",
                        help="options given to both binaries (e.g. \"--sky 1 --max-depth 8\")")
    parser.add_argument("--new-options", default="",
                        help="options given to the new binary only (e.g. \"--materials lambert\")")
    args = parser.parse_args()
    common = ["--width", args.size, "--height", args.size, "--spp", args.spp, "--seed",
              args.seed] + args.options.split()
    differ = 0
    with tempfile.TemporaryDirectory() as scratch:
        for k, (label, options) in enumerate(renders(args)):
            images = []
            for which, binary in (("old", args.baseline), ("new", args.mcrt)):
                stem = Path(scratch) / ("%d-%s" % (k, which))
                extra = args.new_options.split() if which == "new" else []
                mcrt_run.render(args.scene, stem, options + common + extra, mcrt=binary,
                                read_image=False)
                exr = read_exr(str(stem) + ".exr")
                images.append({c: exr[c] for c in ("R", "G", "B", "variance.R", "variance.G",
                                                   "variance.B")})
            same = all(np.array_equal(images[0][c].view(np.uint32), images[1][c].view(np.uint32))
                       for c in images[0])
            if same:
                print("identical  %s" % label)
                continue
            differ += 1
            rgb = [np.stack([im[c] for c in "RGB"]).astype(np.float64) for im in images]
            ulps = np.abs(np.stack([images[0][c] for c in "RGB"]).view(np.int32).astype(np.int64)
                          - np.stack([images[1][c] for c in "RGB"]).view(np.int32).astype(np.int64))
            diff = (rgb[1] - rgb[0]).mean(axis=0).ravel()  # per pixel, channels averaged
            old_mean = rgb[0].mean()
            change = diff.mean() / old_mean if old_mean else float("nan")
            change_se = diff.std(ddof=1) / np.sqrt(diff.size) / old_mean if old_mean else float("nan")
            print("DIFFERENT  %s: %d of %d values, max |diff| %.3g (max %d ulp), means %.9g vs %.9g"
                  ", relative change %+.2e ± %.2e"
                  % (label, int((rgb[0] != rgb[1]).sum()), rgb[0].size,
                     float(np.abs(rgb[0] - rgb[1]).max()), int(ulps.max()), old_mean,
                     rgb[1].mean(), change, change_se))
    print("%s: %d render(s) differ" % ("compare_renders", differ))
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(mcrt_run.script_main(main))

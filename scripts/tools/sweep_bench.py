#!/usr/bin/python3
"""Times one sweep of variants three ways, after one untimed pass of each so that all find
PoCL's kernel cache warm: with the Python module in a new context (the scene loaded once, each
variant's program loaded once), again in a context that has rendered every variant before (a
second sweep of a session), and as a loop of `mcrt render` commands. Checks that they give the
same images, and prints the times and the ratios (docs/PYTHON.md).

    PYTHONPATH=build/python scripts/tools/sweep_bench.py [--scene S.gltf] [--mcrt build/mcrt]
        [--size 64] [--spp 4] [--estimators light-area,light-solid-angle,bsdf,mis]
        [--selections uniform,power,tree] [--repeats 3]
"""

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import mcrt

sys.path.insert(0, str(Path(__file__).resolve().parent))
from mcrt_exr import read_exr  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scene", default=str(ROOT / "scenes" / "cornell" /
                                               "CornellBox-Original.gltf"))
    parser.add_argument("--mcrt", default=str(ROOT / "build" / "mcrt"))
    parser.add_argument("--size", type=int, default=64)
    parser.add_argument("--spp", type=int, default=4)
    parser.add_argument("--estimators", default="light-area,light-solid-angle,bsdf,mis")
    parser.add_argument("--selections", default="uniform,power,tree")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    variants = [(e, s) for e in args.estimators.split(",") for s in args.selections.split(",")]
    common = dict(width=args.size, height=args.size, spp=args.spp, max_depth=2)

    def sweep(scene):
        return [scene.render(estimator=e, light_select=s, **common).image.copy()
                for e, s in variants]

    def in_process():
        with mcrt.Context() as ctx:
            return sweep(ctx.load(args.scene))

    def cli_loop(out_dir):
        images = []
        for i, (e, s) in enumerate(variants):
            out = Path(out_dir) / ("%d.exr" % i)
            subprocess.run([args.mcrt, "render", args.scene, "--out", str(out), "--quiet",
                            "--width", str(args.size), "--height", str(args.size),
                            "--spp", str(args.spp), "--max-depth", "2", "--estimator", e,
                            "--light-select", s], check=True)
            channels = read_exr(str(out))
            images.append(np.stack([channels[c] for c in ("R", "G", "B")], axis=-1))
        return images

    def timed(f, *a):
        start = time.perf_counter()
        result = f(*a)
        return time.perf_counter() - start, result

    kept = mcrt.Context()
    kept_scene = kept.load(args.scene)
    with tempfile.TemporaryDirectory() as out_dir:
        sweep(kept_scene), cli_loop(out_dir)  # untimed: PoCL's cache holds every variant
        module_times, kept_times, cli_times = [], [], []
        for _ in range(args.repeats):
            t, module_images = timed(in_process)
            module_times.append(t)
            t, kept_images = timed(sweep, kept_scene)
            kept_times.append(t)
            t, cli_images = timed(cli_loop, out_dir)
            cli_times.append(t)
    same = all(np.array_equal(a, b) and np.array_equal(a, k)
               for a, b, k in zip(module_images, cli_images, kept_images))
    m, k, c = (statistics.median(t) for t in (module_times, kept_times, cli_times))
    print("%d variants, %dx%d, %d spp, %s; median of %d" % (
        len(variants), args.size, args.size, args.spp, Path(args.scene).name, args.repeats))
    print("module, new context (load, every program, every render): %7.3f s" % m)
    print("module, the context of an earlier sweep:                 %7.3f s" % k)
    print("mcrt render loop:                                        %7.3f s" % c)
    print("ratios %.1fx and %.1fx; images %s" % (c / m, c / k, "identical" if same else "DIFFER"))
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/python3
"""Times one sweep of variants three ways, after one untimed pass so that all find PoCL's
kernel cache warm: a new Python process that imports the module, loads the scene once and
renders every variant (each variant's program loaded from PoCL's cache once); the same sweep
again in a context that has rendered every variant before (programs and uploads kept); and a
loop of `mcrt render` commands. Checks that the three give the same images, and prints the
times and the ratios (docs/PYTHON.md).

    PYTHONPATH=build/python bench/sweep_bench.py [--scene S.gltf] [--mcrt build/mcrt]
        [--size 64] [--spp 4] [--estimators light-area,light-solid-angle,bsdf,mis]
        [--selections uniform,power,tree] [--repeats 3] [--set OPTION=VALUE ...]

--set passes one more `mcrt render` option to every render of the three (e.g. --set sky=1
--set look-from=9.2,1.44,-0.32): the command gets `--OPTION VALUE`, the module the keyword
OPTION with `_` for `-` and the value as a number or a tuple of numbers.
"""

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import mcrt

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts/tools"))  # mcrt_exr
from mcrt_exr import read_exr  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def parse():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scene", default=str(ROOT / "scenes" / "cornell" /
                                               "CornellBox-Original.gltf"))
    parser.add_argument("--mcrt", default=str(ROOT / "build" / "mcrt"))
    parser.add_argument("--size", type=int, default=64)
    parser.add_argument("--spp", type=int, default=4)
    parser.add_argument("--estimators", default="light-area,light-solid-angle,bsdf,mis")
    parser.add_argument("--selections", default="uniform,power,tree")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--set", action="append", default=[], metavar="OPTION=VALUE")
    parser.add_argument("--child", help=argparse.SUPPRESS)  # the new process: its images' file
    return parser.parse_args()


def number(text):
    return int(text) if text.lstrip("-").isdigit() else float(text)


def extra_keywords(args):
    keywords = {}
    for item in args.set:
        option, value = item.split("=", 1)
        values = tuple(number(v) for v in value.split(","))
        keywords[option.replace("-", "_")] = values if len(values) > 1 else values[0]
    return keywords


def extra_options(args):
    return [part for item in args.set for part in ("--" + item.split("=", 1)[0],
                                                    item.split("=", 1)[1])]


def sweep(scene, args):
    variants = [(e, s) for e in args.estimators.split(",") for s in args.selections.split(",")]
    return [scene.render(estimator=e, light_select=s, width=args.size, height=args.size,
                         spp=args.spp, max_depth=2, **extra_keywords(args)).image.copy()
            for e, s in variants]


def main():
    args = parse()
    if args.child:
        with mcrt.Context() as ctx:
            np.save(args.child, np.stack(sweep(ctx.load(args.scene), args)))
        return 0
    variants = [(e, s) for e in args.estimators.split(",") for s in args.selections.split(",")]

    def new_process(out_dir):
        images = str(Path(out_dir) / "images.npy")
        subprocess.run([sys.executable, __file__, "--child", images] + sys.argv[1:], check=True,
                       env=dict(os.environ))
        return list(np.load(images))

    def cli_loop(out_dir):
        images = []
        for i, (e, s) in enumerate(variants):
            out = Path(out_dir) / ("%d.exr" % i)
            subprocess.run([args.mcrt, "render", args.scene, "--out", str(out), "--quiet",
                            "--width", str(args.size), "--height", str(args.size),
                            "--spp", str(args.spp), "--max-depth", "2", "--estimator", e,
                            "--light-select", s] + extra_options(args), check=True)
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
        sweep(kept_scene, args), cli_loop(out_dir)  # untimed: PoCL's cache holds every variant
        fresh_times, kept_times, cli_times = [], [], []
        for _ in range(args.repeats):
            t, fresh_images = timed(new_process, out_dir)
            fresh_times.append(t)
            t, kept_images = timed(sweep, kept_scene, args)
            kept_times.append(t)
            t, cli_images = timed(cli_loop, out_dir)
            cli_times.append(t)
    same = all(np.array_equal(a, b) and np.array_equal(a, k)
               for a, b, k in zip(fresh_images, cli_images, kept_images))
    f, k, c = (statistics.median(t) for t in (fresh_times, kept_times, cli_times))
    print("%d variants, %dx%d, %d spp, %s; median of %d" % (
        len(variants), args.size, args.size, args.spp, Path(args.scene).name, args.repeats))
    print("mcrt render loop:                                          %7.3f s" % c)
    print("module, a new process (import, load, programs, renders):   %7.3f s  %5.1fx" % (f, c / f))
    print("module, a context that rendered the variants before:       %7.3f s  %5.1fx" % (k, c / k))
    print("images %s" % ("identical" if same else "DIFFER"))
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())

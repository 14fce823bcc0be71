#!/usr/bin/python3
"""Times one sweep of variants two ways: in one process with the Python module (the scene
loaded once, each variant's program built once), and as a loop of `mcrt render` commands, after
one untimed pass of each so that both find PoCL's kernel cache warm. Checks that both give the
same images, and prints the two times and their ratio (docs/PYTHON.md, docs/BENCHMARKS.md).

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

    def in_process():
        with mcrt.Context() as ctx:
            scene = ctx.load(args.scene)
            return [scene.render(estimator=e, light_select=s, **common).image.copy()
                    for e, s in variants]

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

    with tempfile.TemporaryDirectory() as out_dir:
        in_process(), cli_loop(out_dir)  # untimed: PoCL's cache holds every variant
        module_times, cli_times = [], []
        for _ in range(args.repeats):
            t, module_images = timed(in_process)
            module_times.append(t)
            t, cli_images = timed(cli_loop, out_dir)
            cli_times.append(t)
    same = all(np.array_equal(a, b) for a, b in zip(module_images, cli_images))
    m, c = statistics.median(module_times), statistics.median(cli_times)
    print("%d variants, %dx%d, %d spp, %s" % (len(variants), args.size, args.size, args.spp,
                                              Path(args.scene).name))
    print("in-process (load, then every render): %.3f s (median of %d)" % (m, args.repeats))
    print("mcrt render loop:                     %.3f s (median of %d)" % (c, args.repeats))
    print("ratio %.1fx; images %s" % (c / m, "identical" if same else "DIFFER"))
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/python3
"""Ray-query throughput (`mcrt bench`) of two or more kernel or binary variants against each
other, in one run: what bench_ab.py is for renders, for the bench's primary, shadow and ambient
rays.

Each variant is LABEL=BINARY or LABEL=BINARY@KERNEL_DIR (the kernels read from KERNEL_DIR through
MCRT_KERNEL_DIR). For every scene and kind of ray, --rounds rounds run every variant's bench in
turn (alternating, so that a load change on the shared machine hits all variants alike). The
table gives each variant's median Mrays/s, the median of its per-round ratios to the first
variant (each round's run against the first variant's of the same round, seconds apart), the
median of its per-round ratios to Embree (measured in the same process, on the same rays), and
its hit count beside Embree's.

Usage: bench/bench_rays_ab.py --variant before=OLD/mcrt --variant after=build/mcrt [--rounds 5]
           [--size 512] SCENE...
"""

import argparse
import json
import os
import statistics
import subprocess
import sys


def variant(text):
    label, _, target = text.partition("=")
    if not label or not target:
        raise argparse.ArgumentTypeError("%s: not LABEL=BINARY[@KERNEL_DIR]" % text)
    binary, _, kernels = target.partition("@")
    return label, binary, kernels


def bench(binary, kernels, scene, rays, size):
    env = dict(os.environ)
    if kernels:
        env["MCRT_KERNEL_DIR"] = kernels
    out = subprocess.run([binary, "bench", scene, "--rays", rays, "--json", "--width", str(size),
                          "--height", str(size)], capture_output=True, text=True, check=True,
                         env=env).stdout
    return json.loads(out)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--variant", type=variant, action="append", required=True)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--size", type=int, default=512, help="rays from a SIZE x SIZE image")
    parser.add_argument("scenes", nargs="+")
    args = parser.parse_args()
    if len(args.variant) < 2:
        parser.error("give at least two --variant")
    print("| scene | rays | variant | Mrays/s median | per-round ratio to %s | ratio to Embree"
          " | hits (Embree's) |" % args.variant[0][0])
    print("|---|---|---|---|---|---|---|")
    for scene in args.scenes:
        for rays in ("primary", "shadow", "ambient"):
            runs = {label: [] for label, _, _ in args.variant}
            for _ in range(args.rounds):
                for label, binary, kernels in args.variant:
                    runs[label].append(bench(binary, kernels, scene, rays, args.size))
            first = runs[args.variant[0][0]]
            for label, _, _ in args.variant:
                r = runs[label]
                speed = statistics.median(j["mrays_per_s"] for j in r)
                paired = statistics.median(j["mrays_per_s"] / f["mrays_per_s"]
                                           for j, f in zip(r, first))
                embree = statistics.median(j["mrays_per_s"] / j["embree_mrays_per_s"] for j in r)
                print("| %s | %s | %s | %.2f | %.3f | %.2f | %d (%d) |"
                      % (os.path.basename(scene), rays, label, speed, paired, embree,
                         r[-1]["hits"], r[-1]["embree_hits"]), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())

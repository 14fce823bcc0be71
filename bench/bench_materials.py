#!/usr/bin/python3
"""What the glossy path costs: kernel time of `--materials gltf` (the microfacet build) against
`--materials lambert` (the course's build) on the same scene, estimator and spp, in alternating
rounds of one run (the machine is shared: only ratios measured together mean anything).

Usage: bench/bench_materials.py [--scene scenes/veach-mis/veach-mis.gltf] [--size 192x108]
           [--spp 64] [--rounds 5] [--estimators light-area,bsdf,mis]
Prints one Markdown row per estimator: median seconds of each build, their ratio and its range
over rounds. Only the standard library.
"""
import argparse
import statistics
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts/tools"))  # mcrt_run, mcrt_exr
import mcrt_run  # noqa: E402


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", default=str(mcrt_run.ROOT / "scenes" / "veach-mis" / "veach-mis.gltf"))
    p.add_argument("--size", type=mcrt_run.image_size, default="192x108")
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--estimators", type=mcrt_run.comma_list, default="light-area,bsdf,mis")
    mcrt_run.add_mcrt_option(p)
    args = p.parse_args()
    base = ["--width", args.size[0], "--height", args.size[1], "--spp", args.spp]
    times = {(e, m): [] for e in args.estimators for m in ("gltf", "lambert")}
    with tempfile.TemporaryDirectory() as scratch:
        for e in args.estimators:  # warm the kernel cache of both builds
            for m in ("gltf", "lambert"):
                mcrt_run.render(args.scene, Path(scratch) / "w", base + ["--estimator", e, "--materials", m],
                                mcrt=args.mcrt, read_image=False)
        for _ in range(args.rounds):
            for e in args.estimators:
                for m in ("gltf", "lambert"):
                    s = mcrt_run.render(args.scene, Path(scratch) / "r",
                                        base + ["--estimator", e, "--materials", m],
                                        mcrt=args.mcrt, read_image=False).stats
                    times[(e, m)].append(s["seconds_render"])
    print("| estimator | gltf s (median) | lambert s (median) | gltf / lambert | range over rounds |")
    print("| --- | --- | --- | --- | --- |")
    for e in args.estimators:
        g, l = times[(e, "gltf")], times[(e, "lambert")]
        ratios = [a / b for a, b in zip(g, l)]
        print("| %s | %.3f | %.3f | %.2f | %.2f–%.2f |" % (
            e, statistics.median(g), statistics.median(l), statistics.median(ratios),
            min(ratios), max(ratios)))
    return 0


if __name__ == "__main__":
    sys.exit(mcrt_run.script_main(main))

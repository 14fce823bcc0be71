#!/usr/bin/python3
"""mcrt against Embree: the table of docs/BENCHMARKS.md, from `mcrt bench --json` runs.

Usage: bench/bench_embree.py [--rounds R] [--size WxH] [--repeats K] [--scenes S ...]
                               [--mcrt BINARY] [-- EXTRA BENCH OPTIONS]
Runs build/mcrt bench on each scene R times (scenes taken in turn, round by round, so that a
change in the machine's load spreads over all of them) and prints one Markdown row per scene
and ray kind: medians over the rounds of mcrt's and Embree's Mrays/s and of the ratio measured
within each run (both tracers alternate launch by launch inside a run). Needs an mcrt built with
Embree (scripts/setup installs libembree-dev). Only the standard library.
"""
import argparse
import json
import os
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts/tools"))  # mcrt_run, mcrt_exr
import mcrt_run  # noqa: E402

SHARED = os.path.join(os.path.dirname(mcrt_run.ROOT), "shared", "scenes")
SCENES = ["sponza/crytek-sponza.gltf", "stanford/dragon_vrip_res2.glb",
          "lights/modern-hall/modern-hall.gltf"]
KINDS = ["primary", "shadow", "ambient"]


def load_average():
    with open("/proc/loadavg") as f:
        return float(f.read().split()[0])


def bench(scene, args, extra):
    """`mcrt bench SCENE --json`: ray kind → its JSON line."""
    cmd = [mcrt_run.mcrt_binary(args.mcrt), "bench", scene, "--json", "--width", args.width,
           "--height", args.height, "--repeats", args.repeats] + extra
    out = mcrt_run.run(cmd).stdout
    try:
        lines = [json.loads(line) for line in out.splitlines() if line.strip()]
    except ValueError as e:
        raise mcrt_run.ScriptError("mcrt bench %s: not JSON lines: %s" % (scene, e))
    if any("embree_mrays_per_s" not in j for j in lines):
        raise mcrt_run.ScriptError(f"{args.mcrt} was built without Embree")
    return {j["rays"]: j for j in lines}


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--size", type=mcrt_run.image_size, default="1024x1024")
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--scenes", nargs="+", default=[os.path.join(SHARED, s) for s in SCENES])
    mcrt_run.add_mcrt_option(p)
    p.add_argument("extra", nargs="*", help="further `mcrt bench` options, after --")
    args = p.parse_args()
    args.width, args.height = args.size

    runs = {s: [] for s in args.scenes}
    loads = [load_average()]
    for _ in range(args.rounds):
        for s in args.scenes:
            runs[s].append(bench(s, args, args.extra))
            loads.append(load_average())

    med = statistics.median
    print(f"{args.rounds} rounds, {args.width}x{args.height}, median of {args.repeats} per run; "
          f"1-minute load average {min(loads):.1f}-{max(loads):.1f}")
    print()
    print("| scene (triangles) | rays | count | mcrt Mrays/s | Embree Mrays/s | ratio (min-max) "
          "| hit mismatches | triangle mismatches (all / at another distance) | mcrt build (s) | Embree build (s) "
          "| SAH cost | packets | bytes/triangle |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for s in args.scenes:
        first = True
        for kind in KINDS:
            js = [r[kind] for r in runs[s]]
            ratios = [j["mrays_per_s"] / j["embree_mrays_per_s"] for j in js]
            name = f"{os.path.basename(s)} ({js[0]['triangles']:,})" if first else ""
            build = (f"{med(j['bvh_build_seconds'] for j in js):.3f} | "
                     f"{med(j['embree_build_seconds'] for j in js):.3f} | "
                     f"{js[0]['sah_cost']:.2f} | {js[0].get('bvh_packets', '-')} | "
                     f"{js[0]['bytes_per_triangle']:.1f}") if first else "| | | |"
            # Other triangles, and (after the slash) those of them at another distance: the
            # rest are ties between coplanar or edge-sharing triangles.
            tri = "%d / %d" % (max(j.get("triangle_mismatches", 0) for j in js),
                               max(j.get("triangle_mismatches_apart", 0) for j in js)) \
                if kind == "primary" else "-"
            print(f"| {name} | {kind} | {js[0]['count']:,} | "
                  f"{med(j['mrays_per_s'] for j in js):.2f} | "
                  f"{med(j['embree_mrays_per_s'] for j in js):.2f} | "
                  f"{med(ratios):.2f} ({min(ratios):.2f}-{max(ratios):.2f}) | "
                  f"{max(j['hit_mismatches'] for j in js)} | {tri} | {build} |")
            first = False


if __name__ == "__main__":
    sys.exit(mcrt_run.script_main(main))

#!/usr/bin/python3
"""mcrt against Embree: the table of docs/BENCHMARKS.md, from `mcrt bench --json` runs.

Usage: bench/bench_embree.py [--rounds R] [--size WxH] [--repeats K] [--scenes S ...]
                               [--mcrt BINARY] [-- EXTRA BENCH OPTIONS]
       bench/bench_embree.py --variant LABEL=BINARY[@KERNEL_DIR] --variant ... \
                               [--variant-options LABEL="OPTIONS"] [the options above]
Runs build/mcrt bench on each scene R times (scenes taken in turn, round by round, so that a
change in the machine's load spreads over all of them) and prints one Markdown row per scene
and ray kind: medians over the rounds of mcrt's and Embree's Mrays/s and of the ratio measured
within each run (both tracers alternate launch by launch inside a run). Needs an mcrt built with
Embree (scripts/setup installs libembree-dev). Only the standard library.

With --variant (as bench/bench_ab.py: a binary, its kernels from KERNEL_DIR through
MCRT_KERNEL_DIR if given, and options of its own), every variant runs each scene in turn within
each round, the table above is the first variant's, and a second table compares the variants'
own rates: a tree or kernel change against another in one run, where Embree's rate, which
moves between modes minutes apart, does not enter.
"""
import argparse
import json
import os
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts/tools"))  # mcrt_run, mcrt_exr
import mcrt_run  # noqa: E402
from bench_ab import parse_variant, parse_variant_options  # noqa: E402

SHARED = os.path.join(os.path.dirname(mcrt_run.ROOT), "shared", "scenes")
SCENES = ["sponza/crytek-sponza.gltf", "stanford/dragon_vrip_res2.glb",
          "lights/modern-hall/modern-hall.gltf"]
KINDS = ["primary", "shadow", "ambient"]


def load_average():
    with open("/proc/loadavg") as f:
        return float(f.read().split()[0])


def bench(scene, args, extra, binary=None, kernels=None):
    """`mcrt bench SCENE --json`: ray kind → its JSON line."""
    cmd = [mcrt_run.mcrt_binary(binary or args.mcrt), "bench", scene, "--json", "--width",
           args.width, "--height", args.height, "--repeats", args.repeats] + extra
    # kernels None: the environment's MCRT_KERNEL_DIR, if any; "": the binary's own kernels.
    env = None if kernels is None else {"MCRT_KERNEL_DIR": kernels}
    out = mcrt_run.run(cmd, env=env).stdout
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
    p.add_argument("--variant", action="append", type=parse_variant, default=[],
                   help="LABEL=BINARY[@KERNEL_DIR]; the first is the baseline")
    p.add_argument("--variant-options", action="append", type=parse_variant_options, default=[],
                   help='LABEL="OPTIONS": `mcrt bench` options of that variant alone')
    p.add_argument("extra", nargs="*", help="further `mcrt bench` options, after --")
    args = p.parse_args()
    args.width, args.height = args.size
    # A variant without KERNEL_DIR runs its binary's own kernels, whatever the environment says.
    variants = [(label, binary, kernels or "") for label, binary, kernels in args.variant] or \
        [("mcrt", args.mcrt, None)]
    labels = [v[0] for v in variants]
    own = dict(args.variant_options)
    if len(set(labels)) != len(labels):
        raise mcrt_run.ScriptError("two --variant share a label: %s" % ", ".join(labels))
    unknown = sorted(set(own) - set(labels))
    if unknown:
        raise mcrt_run.ScriptError("--variant-options names no --variant: %s" % ", ".join(unknown))

    # runs[label][scene]: that variant's JSON lines, one per round.
    runs = {label: {s: [] for s in args.scenes} for label in labels}
    loads = [load_average()]
    for _ in range(args.rounds):
        for s in args.scenes:
            for label, binary, kernels in variants:
                runs[label][s].append(
                    bench(s, args, args.extra + own.get(label, []), binary, kernels))
            loads.append(load_average())
    print_embree_table(args, runs[labels[0]], loads, labels[0])
    if len(variants) > 1:
        print()
        print_variant_table(args, runs, labels)


def print_variant_table(args, runs, labels):
    """Each variant's own Mrays/s (median and range over the rounds) and the median of its
    per-round ratios to the first variant's: a round's runs are a few seconds apart."""
    med = statistics.median
    base = labels[0]
    print("| scene | rays | " + " | ".join(f"{label} Mrays/s" for label in labels) + " | " +
          " | ".join(f"{label}/{base} (min-max)" for label in labels[1:]) + " |")
    print("|---|---|" + "---:|" * (2 * len(labels) - 1))
    for s in args.scenes:
        for kind in KINDS:
            rates = {label: [r[kind]["mrays_per_s"] for r in runs[label][s]] for label in labels}
            cells = [f"{med(rates[label]):.2f} ({min(rates[label]):.2f}-{max(rates[label]):.2f})"
                     for label in labels]
            for label in labels[1:]:
                ratios = [a / b for a, b in zip(rates[label], rates[base])]
                cells.append(f"{med(ratios):.3f} ({min(ratios):.3f}-{max(ratios):.3f})")
            print(f"| {os.path.basename(s)} | {kind} | " + " | ".join(cells) + " |")


def print_embree_table(args, runs, loads, label):
    """mcrt against Embree, one variant's runs: runs[scene] holds its JSON lines."""
    med = statistics.median
    print(f"{label} against Embree: {args.rounds} rounds, {args.width}x{args.height}, "
          f"median of {args.repeats} per run; "
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

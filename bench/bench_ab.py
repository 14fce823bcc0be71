#!/usr/bin/python3
"""Render throughput of kernel or binary variants against each other, in one run: the speed
comparisons of docs/BENCHMARKS.md ("Kernel changes measured").

Each variant is LABEL=BINARY or LABEL=BINARY@KERNEL_DIR (the kernels read from KERNEL_DIR
through MCRT_KERNEL_DIR instead of those embedded in BINARY). For every scene, each variant
renders once to warm its kernel cache, then --rounds rounds render every variant in turn
(alternating, so that a load change on the shared machine hits all variants alike). Samples per
second are those of the stats (kernel time from OpenCL profiling events) and, beside them, per
second of the process's CPU time (set-up included: a few per cent at the default size, but far
less disturbed by other jobs on a shared machine); the table gives the median and range of each
variant, its ratio of medians to the first and the median of its per-round ratios to the first
(each round's render against the first variant's of the same round, a second apart: the machine's
speed drifts by tens of per cent over minutes), and says whether its image is
bitwise that of the first variant (the pixels' float bits, not the file: the file's attributes
hold times).

A variant may also add options of its own (--variant-options LABEL="..."), so that one binary's
settings compare: --variant power=build/mcrt --variant tree=build/mcrt --variant-options
power="--light-select power" --variant-options tree="--light-select tree".

Usage: bench/bench_ab.py --variant old=build-old/mcrt --variant new=build/mcrt [--rounds 5]
           [--width 256 --height 256 --spp 64] [--options "--estimator mis"]
           [--variant-options LABEL="OPTIONS"]... SCENE...
Needs numpy (Debian's python3-numpy; /usr/bin/python3).
"""

import argparse
import json
import resource
import shlex
import statistics
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts/tools"))  # mcrt_run, mcrt_exr
import mcrt_run  # noqa: E402


def parse_variant(text):
    label, sep, rest = text.partition("=")
    if not sep or not label or not rest:
        raise argparse.ArgumentTypeError("expected LABEL=BINARY[@KERNEL_DIR], got %r" % text)
    binary, _, kernels = rest.partition("@")
    return label, binary, kernels or None


def cpu_seconds():
    """User + system CPU seconds of the finished child processes so far."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def parse_variant_options(text):
    label, sep, rest = text.partition("=")
    if not sep or not label:
        raise argparse.ArgumentTypeError("expected LABEL=OPTIONS, got %r" % text)
    return label, shlex.split(rest)


def render(variant, scene, stem, options, extra=()):
    """The Render of one variant, with .cpu_seconds: the whole process's CPU time (set-up
    included), which another job on the machine inflates far less than the kernel's wall time."""
    label, binary, kernels = variant
    env = {"MCRT_KERNEL_DIR": kernels or ""}  # empty: the binary's embedded kernels
    start = cpu_seconds()
    r = mcrt_run.render(scene, stem, list(options) + list(extra), mcrt=binary, env=env)
    r.cpu_seconds = cpu_seconds() - start
    return r


def same_bits(a, b):
    import numpy as np
    return a.shape == b.shape and bool(np.array_equal(a.view(np.uint32), b.view(np.uint32)))


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("scenes", nargs="+")
    p.add_argument("--variant", action="append", type=parse_variant, required=True,
                   help="LABEL=BINARY[@KERNEL_DIR]; the first is the baseline")
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--width", type=int, default=256)
    p.add_argument("--height", type=int, default=256)
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--options", default="--estimator mis --materials lambert",
                   help="mcrt render options for every variant")
    p.add_argument("--variant-options", action="append", type=parse_variant_options, default=[],
                   help="LABEL=OPTIONS: mcrt render options for that variant only")
    p.add_argument("--json", help="also write the raw figures here")
    args = p.parse_args()
    labels = [v[0] for v in args.variant]
    extra = {}
    for label, opts in args.variant_options:
        if label not in labels:
            p.error("--variant-options %s: no such variant" % label)
        extra[label] = extra.get(label, []) + opts
    mcrt_run.require("numpy")
    options = ["--width", args.width, "--height", args.height, "--spp", args.spp] + \
        shlex.split(args.options)
    rows = []
    with tempfile.TemporaryDirectory(prefix="mcrt-bench-ab-") as scratch:
        for scene in args.scenes:
            images = {}
            rates, cpu_rates = {v[0]: [] for v in args.variant}, {v[0]: [] for v in args.variant}
            for v in args.variant:  # warm each variant's kernel cache; keep its image
                images[v[0]] = render(v, scene, Path(scratch) / v[0], options,
                                      extra.get(v[0], ())).rgb
            for _ in range(args.rounds):
                for v in args.variant:
                    r = render(v, scene, Path(scratch) / v[0], options, extra.get(v[0], ()))
                    rates[v[0]].append(r.stats["samples_per_second"])
                    samples = args.width * args.height * args.spp
                    cpu_rates[v[0]].append(samples / r.cpu_seconds)
            base = args.variant[0][0]
            for v in args.variant:
                label = v[0]
                rows.append({"scene": Path(scene).stem, "variant": label,
                             "msamples_per_second": [x / 1e6 for x in rates[label]],
                             "median": statistics.median(rates[label]) / 1e6,
                             "ratio": statistics.median(rates[label]) /
                             statistics.median(rates[base]),
                             "cpu_msamples_per_second": [x / 1e6 for x in cpu_rates[label]],
                             "cpu_ratio": statistics.median(cpu_rates[label]) /
                             statistics.median(cpu_rates[base]),
                             # Each round's ratio to the baseline rendered just before it: the
                             # machine's speed drifts by tens of per cent over minutes, less
                             # between two renders a second apart.
                             "paired_ratios": [x / b for x, b in zip(rates[label], rates[base])],
                             "bitwise_same": same_bits(images[label], images[base])})
                print("bench_ab: %s" % json.dumps(rows[-1]), file=sys.stderr)
    print("options: %s; %d rounds, alternating" % (" ".join(str(o) for o in options), args.rounds))
    for label in labels:
        if extra.get(label):
            print("%s: %s" % (label, " ".join(extra[label])))
    print()
    print("| scene | variant | Msamples/s median (range) | ratio to %s | paired ratio median "
          "(range) | samples per CPU µs median (range) | ratio | image bitwise %s's |"
          % (args.variant[0][0], args.variant[0][0]))
    print("|---|---|---|---|---|---|---|---|")
    for row in rows:
        x, c, q = row["msamples_per_second"], row["cpu_msamples_per_second"], row["paired_ratios"]
        print("| %s | %s | %.3f (%.3f–%.3f) | %.3f | %.3f (%.3f–%.3f) | %.3f (%.3f–%.3f) | %.3f "
              "| %s |" % (
                  row["scene"], row["variant"], row["median"], min(x), max(x), row["ratio"],
                  statistics.median(q), min(q), max(q), statistics.median(c), min(c), max(c),
                  row["cpu_ratio"], "yes" if row["bitwise_same"] else "**no**"))
    if args.json:
        Path(args.json).write_text(json.dumps({"command": sys.argv, "rows": rows}, indent=1))


if __name__ == "__main__":
    sys.exit(mcrt_run.script_main(main))

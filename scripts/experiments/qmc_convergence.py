#!/usr/bin/python3
"""Variance × spp against spp, per sampler: does a sampler keep its stratification?

For each scene × estimator × sampler × spp, renders K independent seeds and measures the
variance of a pixel's value across the seeds (averaged over pixels): the error of one render,
from independent renders, whatever the sampler. Independent samples give a flat variance × spp;
a sampler whose stratification works makes it fall with spp. Prints a Markdown table, one row
per (scene, estimator, sampler), one column per spp, cells variance × spp (and the fall from
the first to the last spp).

Usage: scripts/experiments/qmc_convergence.py SCENE [SCENE ...] [--estimators light-area,...]
           [--samplers independent,sobol] [--spp 16,64,256] [--seeds 8] [--size 64]
           [--mcrt BINARY] [--label TEXT]
"""

import argparse
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))  # mcrt_run, mcrt_exr
import mcrt_run  # noqa: E402

mcrt_run.require("numpy")
import numpy as np  # noqa: E402


def pixel_variance(scene, estimator, sampler, spp, args, scratch):
    """Mean over pixels and channels of the across-seed variance of the pixel values."""
    images = []
    for seed in range(args.seeds):
        stem = Path(scratch) / ("r%d" % seed)
        r = mcrt_run.render(scene, stem, ["--width", args.size, "--height", args.size, "--spp",
                                          spp, "--sampler", sampler, "--seed", 1 + seed]
                            + mcrt_run.estimator_arguments(estimator), mcrt=args.mcrt)
        images.append(r.rgb)
    return float(np.stack(images).var(axis=0, ddof=1).mean())


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("scenes", nargs="+")
    p.add_argument("--estimators", type=mcrt_run.comma_list, default=["light-area"])
    p.add_argument("--samplers", type=mcrt_run.comma_list, default=["independent", "sobol"])
    p.add_argument("--spp", type=lambda t: [int(x) for x in mcrt_run.comma_list(t)],
                   default=[16, 64, 256])
    p.add_argument("--seeds", type=int, default=8)
    p.add_argument("--size", type=int, default=64)
    p.add_argument("--label", default="", help="a first column, e.g. the binary's name")
    mcrt_run.add_mcrt_option(p)
    args = p.parse_args()
    mcrt_run.check_estimators(args.estimators, args.mcrt)
    print("| %sscene | estimator | sampler | %s | fall %d→%d |"
          % ("binary | " if args.label else "", " | ".join("var×spp @%d" % s for s in args.spp),
             args.spp[0], args.spp[-1]))
    print("|%s---|---|---|%s---|" % ("---|" if args.label else "", "---|" * len(args.spp)))
    with tempfile.TemporaryDirectory() as scratch:
        for scene in args.scenes:
            for estimator in args.estimators:
                for sampler in args.samplers:
                    cells = [pixel_variance(scene, estimator, sampler, spp, args, scratch) * spp
                             for spp in args.spp]
                    print("| %s%s | %s | %s | %s | %.1f× |"
                          % (args.label + " | " if args.label else "", Path(scene).stem,
                             mcrt_run.estimator_label(estimator), sampler,
                             " | ".join("%.3g" % c for c in cells), cells[0] / cells[-1]))
                    sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(mcrt_run.script_main(main))

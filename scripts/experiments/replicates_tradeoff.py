#!/usr/bin/python3
"""What splitting a pixel's samples into K replicates costs and buys (the default of --replicates).

For each scene × estimator × sampler × K: R renders with independent seeds at a fixed spp. It
reports the error a render really has (the variance of a pixel across the seeds, averaged over
pixels and channels), its ratio to K = 1's (the QMC efficiency that splitting loses: K
replicates of spp/K samples are K shorter sequences), and what the variance layer says against
it (the image-wide ratio, which should be 1 for K ≥ 2; for K = 1 it is the per-sample estimate,
an overstatement for correlated samples). A pixel's own error bar from K replicates has a
relative standard deviation of √(2/(K−1)) (χ² with K − 1 degrees of freedom).

Usage: scripts/experiments/replicates_tradeoff.py SCENE [--estimators light-area,...] [--samplers sobol,...]
           [--replicates 1,2,4,8,16] [--spp 64] [--seeds 12] [--size 32] [--mcrt BINARY]
"""

import argparse
import math
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))  # mcrt_run, mcrt_exr
import mcrt_run  # noqa: E402

mcrt_run.require("numpy")
import numpy as np  # noqa: E402


def measure(scene, estimator, sampler, k, args, scratch):
    rgb, layer = [], []
    for seed in range(args.seeds):
        r = mcrt_run.render(scene, Path(scratch) / ("r%d" % seed),
                            ["--width", args.size, "--height", args.size, "--spp", args.spp,
                             "--sampler", sampler, "--replicates", k, "--seed", 1 + seed]
                            + mcrt_run.estimator_arguments(estimator), mcrt=args.mcrt)
        rgb.append(r.rgb)
        layer.append(r.variance)
    observed = float(np.stack(rgb).var(axis=0, ddof=1).mean())
    return observed, float(np.stack(layer).mean())


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("scene")
    p.add_argument("--estimators", type=mcrt_run.comma_list, default=["light-area"])
    p.add_argument("--samplers", type=mcrt_run.comma_list, default=["sobol", "stratified"])
    p.add_argument("--replicates", type=lambda t: [int(x) for x in mcrt_run.comma_list(t)],
                   default=[1, 2, 4, 8, 16])
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--seeds", type=int, default=12)
    p.add_argument("--size", type=int, default=32)
    mcrt_run.add_mcrt_option(p)
    args = p.parse_args()
    mcrt_run.check_estimators(args.estimators, args.mcrt)
    print("%s, %d spp, %d×%d, %d seeds\n" % (Path(args.scene).stem, args.spp, args.size,
                                              args.size, args.seeds))
    print("| estimator | sampler | K | observed var | × K = 1's | layer / observed | "
          "a pixel's error bar ± |")
    print("|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as scratch:
        for estimator in args.estimators:
            for sampler in args.samplers:
                base = None
                for k in args.replicates:
                    observed, layer = measure(args.scene, estimator, sampler, k, args, scratch)
                    base = base or observed
                    spread = "%.0f%%" % (100 * math.sqrt(2 / (k - 1))) if k > 1 else "—"
                    print("| %s | %s | %d | %.3g | %.2f | %.2f | %s |"
                          % (mcrt_run.estimator_label(estimator), sampler, k, observed,
                             observed / base, layer / observed, spread))
                    sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(mcrt_run.script_main(main))

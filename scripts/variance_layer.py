#!/usr/bin/python3
"""How well the EXR's variance layer predicts the error of the image, per sampler.

For each (estimator, sampler): K renders with independent seeds; the observed variance of the
image mean across seeds is compared with the one the variance layer predicts,
mean(variance layer) / pixels (pixels are independent). A ratio above 1 means the layer
overstates the error. Prints a Markdown table. The samplers are those of `mcrt variants`; the
estimators built-in names or estimator files FILE.cl. Only the standard library: the figures
are those of the stats JSON.

Usage: scripts/variance_layer.py [--scene S] [--size WxH] [--spp N] [--renders K]
                                 [--estimators a,b,...] [--mcrt BINARY]
"""
import argparse
import statistics
import sys
import tempfile
from pathlib import Path

import mcrt_run


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", default=str(mcrt_run.ROOT / "scenes/cornell/CornellBox-Original.gltf"))
    p.add_argument("--size", type=mcrt_run.image_size, default="64x64")
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--renders", type=int, default=16)
    p.add_argument("--estimators", default="light-area,hemisphere-cosine,ambient-cosine,ambient-fibonacci")
    mcrt_run.add_mcrt_option(p)
    args = p.parse_args()
    width, height = args.size
    pixels = width * height
    estimators = mcrt_run.comma_list(args.estimators)
    mcrt_run.check_estimators(estimators, args.mcrt)
    print("| estimator | sampler | observed var of image mean | layer's prediction | "
          "layer / observed |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as out:
        for estimator in estimators:
            for sampler in mcrt_run.names("samplers", mcrt=args.mcrt):
                means, predicted = [], []
                for seed in range(args.renders):
                    s = mcrt_run.render(args.scene, Path(out) / "i", mcrt_run.estimator_arguments(
                        estimator) + ["--width", width, "--height", height, "--spp", args.spp,
                                      "--seed", seed, "--sampler", sampler],
                        mcrt=args.mcrt, read_image=False).stats
                    means.append(sum(s["image_mean"]) / 3)
                    predicted.append(sum(s["image_mean_variance"]) / 3 / pixels)
                observed = statistics.variance(means)
                layer = statistics.mean(predicted)
                print(f"| {mcrt_run.estimator_label(estimator)} | {sampler} | {observed:.3e} | "
                      f"{layer:.3e} | {layer / observed:.2f} |", flush=True)


if __name__ == "__main__":
    sys.exit(mcrt_run.script_main(main))

#!/usr/bin/python3
"""How well the EXR's variance layer predicts the error of the image, per sampler.

For each (estimator, sampler): K renders with independent seeds; the observed variance of the
image mean across seeds is compared with the one the variance layer predicts,
mean(variance layer) / pixels (pixels are independent). A ratio above 1 means the layer
overstates the error. Prints a Markdown table. The samplers are those of `mcrt variants`; the
estimators built-in names or estimator files FILE.cl. Two comparisons: per pixel (the variance
of each pixel across the K renders against the layer, both averaged over pixels: precise, as
pixels are independent) and on the image mean (one number per render: noisier).

Usage: scripts/experiments/variance_layer.py [--scene S] [--size WxH] [--spp N] [--renders K]
                                 [--estimators a,b,...] [--mcrt BINARY]
"""
import argparse
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))  # mcrt_run, mcrt_exr
import mcrt_run  # noqa: E402

mcrt_run.require("numpy")
import numpy as np  # noqa: E402


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
    print("| estimator | sampler | replicates | per pixel: observed var | layer | layer / observed "
          "| image mean: observed var | layer's prediction | layer / observed |")
    print("|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as out:
        for estimator in estimators:
            for sampler in mcrt_run.names("samplers", mcrt=args.mcrt):
                rgb, layer, replicates = [], [], set()
                for seed in range(args.renders):
                    r = mcrt_run.render(args.scene, Path(out) / "i", mcrt_run.estimator_arguments(
                        estimator) + ["--width", width, "--height", height, "--spp", args.spp,
                                      "--seed", seed, "--sampler", sampler], mcrt=args.mcrt)
                    rgb.append(r.rgb)
                    layer.append(r.variance)
                    replicates.add(r.stats.get("replicates", 1))
                rgb, layer = np.stack(rgb), np.stack(layer)
                # Per pixel: the variance of each pixel across the renders, averaged over pixels
                # and channels, against the layer averaged the same way (pixels are independent,
                # so this is the precise comparison).
                px_observed = float(rgb.var(axis=0, ddof=1).mean())
                px_layer = float(layer.mean())
                # Image mean: its variance across renders, against mean(layer) / pixels (noisier:
                # one number per render, and heavy tails weigh on it).
                observed = float(rgb.mean(axis=(2, 3)).var(axis=0, ddof=1).mean())
                predicted = float(layer.mean(axis=(0, 2, 3)).mean()) / pixels
                print(f"| {mcrt_run.estimator_label(estimator)} | {sampler} | "
                      f"{'/'.join(map(str, sorted(replicates)))} | {px_observed:.3e} | "
                      f"{px_layer:.3e} | {px_layer / px_observed:.2f} | {observed:.3e} | "
                      f"{predicted:.3e} | {predicted / observed:.2f} |", flush=True)


if __name__ == "__main__":
    sys.exit(mcrt_run.script_main(main))

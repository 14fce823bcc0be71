#!/usr/bin/python3
"""How well the EXR's variance layer predicts the error of the image, per sampler.

For each (estimator, sampler): K renders with independent seeds; the observed variance of the
image mean across seeds is compared with the one the variance layer predicts,
mean(variance layer) / pixels (pixels are independent). A ratio above 1 means the layer
overstates the error. Prints a Markdown table.

Usage: scripts/variance_layer.py [--scene S] [--size WxH] [--spp N] [--renders K]
"""
import argparse
import json
import os
import statistics
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", default=os.path.join(ROOT, "scenes/cornell/CornellBox-Original.gltf"))
    p.add_argument("--size", default="64x64")
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--renders", type=int, default=16)
    p.add_argument("--estimators", default="light-area,hemisphere-cosine,ambient-cosine,ambient-fibonacci")
    args = p.parse_args()
    width, height = (int(v) for v in args.size.split("x"))
    pixels = width * height
    print("| estimator | sampler | observed var of image mean | layer's prediction | "
          "layer / observed |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as out:
        for estimator in args.estimators.split(","):
            for sampler in ["independent", "stratified", "sobol"]:
                means, predicted = [], []
                for seed in range(args.renders):
                    stats = os.path.join(out, "s.json")
                    subprocess.run([os.path.join(ROOT, "build", "mcrt"), "render", args.scene,
                                    "--out", os.path.join(out, "i.exr"), "--stats", stats,
                                    "--width", str(width), "--height", str(height),
                                    "--spp", str(args.spp), "--seed", str(seed),
                                    "--estimator", estimator, "--sampler", sampler, "--quiet"],
                                   check=True)
                    with open(stats) as f:
                        s = json.load(f)
                    means.append(sum(s["image_mean"]) / 3)
                    predicted.append(sum(s["image_mean_variance"]) / 3 / pixels)
                observed = statistics.variance(means)
                layer = statistics.mean(predicted)
                print(f"| {estimator} | {sampler} | {observed:.3e} | {layer:.3e} | "
                      f"{layer / observed:.2f} |", flush=True)


if __name__ == "__main__":
    main()

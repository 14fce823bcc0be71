#!/usr/bin/python3
"""Per-pixel maps of one estimator configuration: where the noise is, and how fast it falls.

  variance.exr / .png     the variance layer of the render at the largest spp (the variance of
                          each pixel mean, mean of R, G, B; also per channel in the EXR):
                          honest for every sampler, from independent replicates with stratified
                          and Sobol samples, so it maps where the error really is;
                          false colour of log10;
  convergence.exr / .png  per pixel, the slope of log MSE against log spp, fitted over renders
                          at every --spp level (MSE: squared error against the reference, mean
                          over R, G, B and --repeats seeds). Plain Monte Carlo gives −1; a
                          stratified or Sobol sampler on a smooth integrand steeper; 0 where the
                          error stops falling (a bias, or the reference's own noise reached).
                          Pixels exact at every level (e.g. black background) are NaN in the
                          EXR and grey in the PNG. The EXR's channels: `slope`, and `mse` at
                          the largest spp.

The reference is the one scripts/experiments/experiment.py uses (--reference auto, same cache) or a file.
--estimator is a built-in name (`mcrt variants`) or an estimator file FILE.cl.

Usage: scripts/experiments/pixel_maps.py SCENE [--estimator E] [--light-select S] [--sampler G]
           [--spp 4,16,64,256] [--repeats 4] [--width W --height H] [--reference auto|FILE]
           --out DIR
"""

import argparse
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))  # mcrt_run, mcrt_exr
import mcrt_run  # noqa: E402

mcrt_run.require("numpy", "matplotlib")
import numpy as np  # noqa: E402

import experiment  # noqa: E402  (its reference, renders and list parsing)
from mcrt_exr import write_exr  # noqa: E402


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog=__doc__.split("\n\n", 1)[1])
    p.add_argument("scene")
    p.add_argument("--estimator", default="light-area")
    p.add_argument("--light-select", default="power")
    p.add_argument("--sampler", default="independent")
    p.add_argument("--mis-heuristic", help="for the estimators that use one")
    p.add_argument("--spp", type=lambda t: experiment.number_list(t, int), default=[4, 16, 64, 256])
    p.add_argument("--repeats", type=int, default=4)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--width", type=int, default=128)
    p.add_argument("--height", type=int, default=128)
    p.add_argument("--reference", default="auto")
    p.add_argument("--reference-spp", type=int, default=4096)
    p.add_argument("--reference-cache")
    mcrt_run.add_mcrt_option(p)
    p.add_argument("--out", type=mcrt_run.output_directory, required=True)
    args = p.parse_args()
    if len(args.spp) < 2:
        raise mcrt_run.ScriptError("--spp needs at least two levels for a slope")
    # the scene, the binary and the variants, before any render
    experiment.check_variants(args, [args.estimator], [args.light_select], [args.sampler])
    plt = mcrt_run.pyplot()

    out = Path(args.out)
    scratch = out / "renders"
    scratch.mkdir(parents=True, exist_ok=True)
    if args.reference == "auto":
        reference, _, _ = experiment.auto_reference(args, Path(args.scene), scratch)
    else:
        reference, _ = experiment.file_reference(args.reference)

    levels = sorted(args.spp)
    log_mse = []
    variance = None
    for spp in levels:
        sq = np.zeros(reference.shape[1:])
        for r in range(args.repeats):
            stem = str(scratch / ("r-%d-%d" % (spp, r)))
            render = experiment.run_mcrt(args, args.scene, stem, args.estimator,
                                         args.light_select, args.sampler, args.seed + r, spp=spp)
            sq += ((render.rgb - reference) ** 2).mean(axis=0) / args.repeats
            if spp == levels[-1] and r == 0:
                variance = render.variance
            mcrt_run.remove_outputs(stem)
        log_mse.append(sq)
        print("pixel_maps: %d spp: RMSE %.4g" % (spp, math.sqrt(sq.mean())), file=sys.stderr)

    # Least-squares slope of log MSE against log spp, per pixel.
    x = np.log(np.array(levels, np.float64))
    y = np.stack(log_mse)
    valid = np.all(y > 0, axis=0)
    y = np.log(np.where(y > 0, y, 1.0))
    xc = x - x.mean()
    slope = np.tensordot(xc, y - y.mean(axis=0), axes=1) / (xc ** 2).sum()
    slope = np.where(valid, slope, np.nan)

    write_exr(out / "variance.exr", {"R": variance[0], "G": variance[1], "B": variance[2],
                                     "Y": variance.mean(axis=0)},
              float_attributes={"spp": levels[-1]})
    write_exr(out / "convergence.exr", {"slope": slope, "mse": log_mse[-1]})

    title = "%s, %s / %s / %s" % (Path(args.scene).name, mcrt_run.estimator_label(args.estimator),
                                  args.light_select, args.sampler)
    h, w = slope.shape
    size = (4.2, 3.6 * h / w + 0.5)
    fig, ax = plt.subplots(figsize=size, dpi=100)
    v = variance.mean(axis=0)
    positive = v[v > 0]
    lo = np.log10(np.percentile(positive, 1)) if positive.size else -8
    im = ax.imshow(np.log10(np.maximum(v, 1e-30)), cmap="viridis", vmin=lo,
                   vmax=np.log10(v.max()) if v.max() > 0 else 0, interpolation="nearest")
    fig.colorbar(im, ax=ax, fraction=0.046, pad=0.02, label="log10 variance of the pixel mean")
    ax.set_title("%s\nvariance layer, %d spp" % (title, levels[-1]), fontsize=7)
    ax.set_xticks([])
    ax.set_yticks([])
    fig.tight_layout()
    mcrt_run.save_png(fig, out / "variance.png")
    plt.close(fig)

    fig, ax = plt.subplots(figsize=size, dpi=100)
    cmap = plt.get_cmap("RdBu_r").copy()
    cmap.set_bad("0.6")
    im = ax.imshow(np.ma.masked_invalid(slope), cmap=cmap, vmin=-2, vmax=0,
                   interpolation="nearest")
    fig.colorbar(im, ax=ax, fraction=0.046, pad=0.02, label="d log MSE / d log spp")
    ax.set_title("%s\nconvergence rate, spp %s (median %.2f)" % (
        title, ",".join(map(str, levels)), float(np.nanmedian(slope))), fontsize=7)
    ax.set_xticks([])
    ax.set_yticks([])
    fig.tight_layout()
    mcrt_run.save_png(fig, out / "convergence.png")
    plt.close(fig)
    print("pixel_maps: wrote %s (variance.exr/.png, convergence.exr/.png); median slope %.3f"
          % (out, float(np.nanmedian(slope))), file=sys.stderr)


if __name__ == "__main__":
    sys.exit(mcrt_run.script_main(main))

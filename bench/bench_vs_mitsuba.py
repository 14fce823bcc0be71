#!/usr/bin/python3
"""mcrt against Mitsuba 3's llvm_ad_rgb variant, estimator for estimator: the same scene, image
size, spp and estimator, in alternating rounds on the same machine (docs/BENCHMARKS.md, "Against Mitsuba 3's LLVM variant").

Pairs (--pairs; mcrt always with --materials lambert --light-select power --sampler
independent, as Mitsuba's scene is mitsuba_reference.py's diffuse conversion):
  mis         mcrt --estimator mis --mis-heuristic power ↔ `direct`, emitter_samples 1,
              bsdf_samples 1 (Mitsuba's MIS weights are the power heuristic's)
  light-area  mcrt --estimator light-area ↔ `direct`, emitter_samples 1, bsdf_samples 0
  path        mcrt --estimator mis --mis-heuristic power --max-depth D --rr-depth 5 (D: --depth)
              ↔ `path`, max_depth D + 1, rr_depth 5 (mitsuba_reference.py's mapping)
SCENE:sky renders a scene without emitters under --sky 1 in both (a `constant` emitter).
--device SPEC renders mcrt's side on that device (mcrt render --device: an index, `pocl`,
`intel`, ...; default mcrt's first device); Intel's OpenCL runtime is visible when the script
runs under scripts/with-intel (Mitsuba uses no OpenCL).
The light strategies still differ where the scene's lights do: Mitsuba picks an emitter (one
mesh per emissive material) uniformly, then a point by area, mcrt a triangle by power (the same
with one emissive material); Mitsuba samples the sky uniformly on the sphere, mcrt cosine-
weighted about the normal.

Mitsuba runs in this process, so Dr.Jit's compilation is paid once per scene and pair: the
script runs under the Mitsuba venv's Python (it re-runs itself with .venv-mitsuba/bin/python
when mitsuba is not importable). Per scene and pair: one untimed warm-up render each (mcrt: the
PoCL kernel cache; Mitsuba: its JIT), then --rounds rounds of one `mcrt render` (its time: the
stats' seconds_render_wall, the render's wall clock from the first launch, after the kernel build
and upload; the kernels' own time and the process's wall time recorded too) and one
mi.render(scene, spp=N, seed=S) timed with time.monotonic up to the numpy copy that forces
its evaluation; S, also mcrt's --seed, is the round plus R times the pair's index, so that no two
pairs share random numbers. Samples per second = width·height·spp / seconds: median and range over the
rounds, and the ratio of the medians.

Error: each side's last image against one reference per scene and pair, an mcrt render of the
same setup at --reference-spp (cached in --out, reused by reruns). The RMSE is over the pixels
that see no emitter and have no neighbour that does (none in an mcrt --max-depth 0 render, cached
too, dilated by a pixel): at a light's edges the pixel jitter's noise, the same for any
estimator, is nearly all the error; the JSON has the RMSE over every pixel too. RMSE² has the reference's own noise (the mean of its variance layer)
subtracted; mcrt's RMSE at Mitsuba's time is RMSE·√(t_mcrt / t_Mitsuba) with the median times
(RMSE² ∝ 1/time for an unbiased estimator). Image means, over the same pixels (every pixel's
in the JSON): both sides' means over the rounds and their relative difference, ± its standard error from the per-pixel spread of the rounds: a
check that both render the same thing.

Writes DIR/bench_vs_mitsuba.md (the table, also printed) and DIR/bench_vs_mitsuba.json (every
round's figures, machine, command, mcrt binary and commit, Mitsuba version).

Usage: bench/bench_vs_mitsuba.py [--width 256 --height 256] [--spp 64] [--rounds 5] [--depth 8]
           [--pairs mis,light-area,path] [--reference-spp 1024] [--mcrt BINARY] [--device SPEC]
           --out DIR SCENE[:sky] ...
"""

import argparse
import json
import math
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts/tools"))  # mcrt_run, mcrt_exr
import mcrt_run  # noqa: E402
import mitsuba_reference as mref  # checks for numpy first (mcrt_run.require)
import numpy as np  # noqa: E402

PAIRS = ("mis", "light-area", "path")
RR_DEPTH = 5
WARMUP_SEED, REFERENCE_SEED = 1000, 1000003  # apart from the rounds' seeds 0 .. 3R−1 (R < 333)


def mcrt_options(pair, depth, sky, device=None):
    """`mcrt render` options of a pair (without size, spp, seed) on `device` (None: mcrt's
    default)."""
    options = {"mis": ["--estimator", "mis", "--mis-heuristic", "power"],
               "light-area": ["--estimator", "light-area"],
               "path": ["--estimator", "mis", "--mis-heuristic", "power",
                        "--max-depth", depth, "--rr-depth", RR_DEPTH]}[pair]
    return options + ["--materials", "lambert", "--light-select", "power",
                      "--sampler", "independent"] + (["--sky", "1"] if sky else []) + \
        (["--device", device] if device else [])


def mitsuba_integrator(pair, depth):
    """Mitsuba's integrator dict of a pair."""
    if pair == "path":
        return mref.integrator(depth, RR_DEPTH)
    return mref.integrator(1, RR_DEPTH, emitter_samples=1,
                           bsdf_samples=1 if pair == "mis" else 0)


def spread(values):
    """(median, min, max)."""
    return float(np.median(values)), min(values), max(values)


def cached_render(args, scene, name, options):
    """(rgb, variance, path) of an mcrt render at --reference-spp, (H, W, 3): rendered once
    into --out as NAME-WxH-Nspp.exr, read from there by later runs."""
    stem = Path(args.out) / ("%s-%dx%d-%dspp" % (name, args.width, args.height,
                                                 args.reference_spp))
    if not (Path(str(stem) + ".exr").exists() and Path(str(stem) + ".json").exists()):
        print("bench_vs_mitsuba: rendering %s" % stem, file=sys.stderr)
        mcrt_run.render(scene, stem, options + [
            "--width", args.width, "--height", args.height, "--spp", args.reference_spp,
            "--seed", REFERENCE_SEED], mcrt=args.mcrt, read_image=False)
    rgb, variance = mcrt_run.read_image_file(str(stem) + ".exr")
    if rgb.shape != (3, args.height, args.width):
        raise mcrt_run.ScriptError("%s.exr is not %dx%d: remove it" % (stem, args.width,
                                                                       args.height))
    return np.moveaxis(rgb, 0, -1), np.moveaxis(variance, 0, -1), str(stem) + ".exr"


def dilate(mask):
    """A (H, W) bool mask grown by one pixel in each of the 8 directions."""
    padded = np.pad(mask, 1)
    h, w = mask.shape
    return np.logical_or.reduce([padded[1 + dy:1 + dy + h, 1 + dx:1 + dx + w]
                                 for dy in (-1, 0, 1) for dx in (-1, 0, 1)])


def rmse(image, ref, ref_variance, keep):
    """RMSE against the reference over the pixels `keep` ((H, W) bool), the reference's own
    noise there (the mean of its variance layer) subtracted; nan when no pixel is kept."""
    if not keep.any():
        return float("nan")
    mse = float(np.mean((image - ref)[keep] ** 2) - np.mean(ref_variance[keep]))
    return math.sqrt(max(mse, 0.0))


def mean_difference(a, b, keep):
    """(mean of a, mean of b, relative difference of the means, its standard error) of two
    Accumulators over the pixels `keep`; the error None with one round; nan where no pixel is
    kept (a scene whose every surface emits) or b's mean is 0."""
    if not keep.any():
        return float("nan"), float("nan"), float("nan"), None
    mean_a, mean_b = float(a.mean()[keep].mean()), float(b.mean()[keep].mean())
    variance = (a.variance_of_mean() + b.variance_of_mean())[keep]
    if mean_b == 0.0:
        return mean_a, mean_b, float("nan"), None
    stderr = math.sqrt(float(variance.sum())) / variance.size / mean_b if a.n > 1 else None
    return mean_a, mean_b, (mean_a - mean_b) / mean_b, stderr


class Accumulator:
    """Sums of a side's round images: their mean and the variance of that mean per pixel."""

    def __init__(self):
        self.n, self.sum1, self.sum2 = 0, 0.0, 0.0

    def add(self, image):
        self.n += 1
        self.sum1 = self.sum1 + image
        self.sum2 = self.sum2 + image * image

    def mean(self):
        return self.sum1 / self.n

    def variance_of_mean(self):  # sample variance over the rounds / rounds
        return np.maximum(self.sum2 / self.n - self.mean() ** 2, 0) / max(self.n - 1, 1)


def bench(args, mi, item, pair, scratch):
    """One scene and pair: warm-ups, rounds, errors; the row of the JSON."""
    scene, _, tag = item.partition(":")
    sky = tag == "sky"
    label = Path(scene).stem + ("-sky" if sky else "")
    pixels_spp = args.width * args.height * args.spp
    options = mcrt_options(pair, args.depth, sky, args.device) + [
        "--width", args.width, "--height", args.height, "--spp", args.spp]
    integrator = mitsuba_integrator(pair, args.depth)
    try:
        m_scene, emitters, _ = mref.load_scene(mi, scene, args.width, args.height, args.spp,
                                               sky=[1.0, 1.0, 1.0] if sky else None,
                                               materials="lambert", integrator_desc=integrator)
    except (OSError, ValueError) as e:  # an unreadable scene, an unsupported accessor
        raise mcrt_run.ScriptError("%s: %s" % (scene, e))
    if emitters == 0:
        raise mcrt_run.ScriptError("%s has no emitters: give it as %s:sky" % (scene, scene))
    depth = "-d%d" % args.depth if pair == "path" else ""
    ref, ref_variance, ref_path = cached_render(args, scene, "reference-%s-%s%s" % (
        label, pair, depth), mcrt_options(pair, args.depth, sky, args.device))
    # The pixels that see an emitter (the sky) directly: their pixel-jitter noise at a light's
    # edges, the same for every estimator, is nearly all of the squared error (99.7% on the
    # Cornell box at 64x64), so the RMSE of the table is that of the other pixels.
    emitted = cached_render(args, scene, "emitted-%s" % label,
                            ["--max-depth", 0, "--materials", "lambert"] +
                            (["--sky", 1] if sky else []) +
                            (["--device", args.device] if args.device else []))[0]
    # Dilated by a pixel: an edge pixel that the light covers a thousandth of is often missed
    # by the emitted render's 512 samples but hit by some 64-sample round (one such pixel of
    # veach-mis's radiance-3040 light made mcrt's RMSE 0.43 against its 0.05 elsewhere).
    surfaces = ~dilate(emitted.max(axis=-1) > 0)

    # Warm-ups, untimed: PoCL's kernel cache, Dr.Jit's compilation of this scene's kernels.
    stem = Path(scratch) / "m"
    warm = mcrt_run.render(scene, stem, options + ["--seed", WARMUP_SEED], mcrt=args.mcrt,
                           read_image=False)
    start = time.monotonic()
    np.array(mi.render(m_scene, spp=args.spp, seed=WARMUP_SEED))
    warmup = {"mcrt_wall_seconds": warm.wall_seconds, "mitsuba_seconds": time.monotonic() - start}

    rounds, mcrt_images, mitsuba_images = [], Accumulator(), Accumulator()
    # Each pair its own seeds: with the same seeds 0 .. R−1 everywhere, the pairs of a scene
    # drew the same random numbers (common random numbers), and their image means' differences
    # were one draw shown six times (docs/BENCHMARKS.md, "Against Mitsuba 3's LLVM variant").
    first_seed = PAIRS.index(pair) * args.rounds
    for r in range(args.rounds):
        seed = first_seed + r
        m = mcrt_run.render(scene, stem, options + ["--seed", seed], mcrt=args.mcrt)
        start = time.monotonic()
        image = np.array(mi.render(m_scene, spp=args.spp, seed=seed), dtype=np.float64)[..., :3]
        seconds = time.monotonic() - start
        mcrt_image = np.moveaxis(m.rgb, 0, -1)
        mcrt_images.add(mcrt_image)
        mitsuba_images.add(image)
        # The render's wall clock (launch gaps and host work included, as Mitsuba's time
        # includes its own), from its first launch, after the kernel build and upload.
        wall = m.stats.get("seconds_render_wall", m.stats["seconds_render"])
        rounds.append({"mcrt_seconds_render": wall,
                       "mcrt_seconds_kernels": m.stats["seconds_render"],
                       "mcrt_wall_seconds": m.wall_seconds,
                       "mcrt_stats_samples_per_second": m.stats["samples_per_second"],
                       "mcrt_samples_per_second": pixels_spp / wall,
                       "mitsuba_seconds": seconds,
                       "mitsuba_samples_per_second": pixels_spp / seconds})
        print("bench_vs_mitsuba: %s %s round %d: mcrt %.3f s, Mitsuba %.3f s"
              % (label, pair, r + 1, wall, seconds), file=sys.stderr)

    t_mcrt = spread([x["mcrt_seconds_render"] for x in rounds])[0]
    t_mitsuba = spread([x["mitsuba_seconds"] for x in rounds])[0]
    every = np.ones_like(surfaces)
    rmse_mcrt, rmse_mitsuba = (rmse(x, ref, ref_variance, surfaces) for x in (mcrt_image, image))
    means = mean_difference(mcrt_images, mitsuba_images, every)
    means_surfaces = mean_difference(mcrt_images, mitsuba_images, surfaces)
    return {
        "scene": scene, "label": label, "sky": sky, "pair": pair, "spp": args.spp,
        "mcrt_options": [str(o) for o in options], "mitsuba_integrator": integrator,
        "mitsuba_emitters": emitters, "mcrt_device": m.stats["devices"][0]["name"],
        "warmup": warmup, "rounds": rounds,
        "mcrt_samples_per_second": spread([x["mcrt_samples_per_second"] for x in rounds]),
        "mitsuba_samples_per_second": spread([x["mitsuba_samples_per_second"] for x in rounds]),
        "mcrt_seconds_median": t_mcrt, "mitsuba_seconds_median": t_mitsuba,
        "reference": ref_path, "reference_rmse_floor": math.sqrt(float(np.mean(ref_variance))),
        "emitter_pixels": int((~surfaces).sum()),
        # RMSEs over the pixels that see no emitter (the table's), and over every pixel
        "rmse_mcrt": rmse_mcrt, "rmse_mitsuba": rmse_mitsuba,
        "rmse_mcrt_at_mitsuba_time": rmse_mcrt * math.sqrt(t_mcrt / t_mitsuba),
        "rmse_mcrt_all_pixels": rmse(mcrt_image, ref, ref_variance, every),
        "rmse_mitsuba_all_pixels": rmse(image, ref, ref_variance, every),
        # image means over every pixel, and over those that see no emitter (the table's)
        **dict(zip(("mcrt_image_mean", "mitsuba_image_mean", "relative_difference_of_means",
                    "relative_difference_of_means_stderr"), means)),
        **dict(zip(("mcrt_surfaces_mean", "mitsuba_surfaces_mean",
                    "relative_difference_of_surfaces_means",
                    "relative_difference_of_surfaces_means_stderr"), means_surfaces)),
    }


def table(rows, args, variant):
    """The markdown table of the rows, with a line on how to read it."""
    def rate(s):  # (median, min, max) samples/s → "M (min–max)" in Msamples/s
        return "%.3g (%.3g–%.3g)" % tuple(v / 1e6 for v in s)

    lines = ["| scene | pair | spp | mcrt Msamples/s median (range) | Mitsuba %s Msamples/s "
             "median (range) | mcrt/Mitsuba | RMSE mcrt, Mitsuba (mcrt at Mitsuba's time) | "
             "image means mcrt, Mitsuba (difference) |" % variant,
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        difference = "%+.2f%%" % (100 * r["relative_difference_of_surfaces_means"])
        if r["relative_difference_of_surfaces_means_stderr"] is not None:
            difference += " ± %.2f%%" % (100 * r["relative_difference_of_surfaces_means_stderr"])
        lines.append("| %s | %s | %d | %s | %s | %.2f | %.4g, %.4g (%.4g) | %.5g, %.5g (%s) |" % (
            r["label"], r["pair"], r["spp"], rate(r["mcrt_samples_per_second"]),
            rate(r["mitsuba_samples_per_second"]),
            r["mcrt_samples_per_second"][0] / r["mitsuba_samples_per_second"][0],
            r["rmse_mcrt"], r["rmse_mitsuba"], r["rmse_mcrt_at_mitsuba_time"],
            r["mcrt_surfaces_mean"], r["mitsuba_surfaces_mean"], difference))
    lines.append("")
    devices = sorted({r["mcrt_device"] for r in rows})
    lines.append("mcrt on --device %s (%s); %dx%d, %d rounds; mcrt's time: seconds_render_wall "
                 "of its stats. RMSE against a %d spp mcrt reference, its noise subtracted, over "
                 "the pixels that see no emitter (nor one next to such a pixel); (…) mcrt's "
                 "RMSE·√(t_mcrt/t_Mitsuba). Image means over the same pixels, ± the standard "
                 "error from the rounds." % (
                     args.device or "default", ", ".join(devices), args.width, args.height,
                     args.rounds, args.reference_spp))
    return "\n".join(lines) + "\n"


def git_revision():
    try:
        return subprocess.run(["git", "-C", str(mcrt_run.ROOT), "rev-parse", "--short", "HEAD"],
                              capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog=__doc__.split("\n\n", 1)[1])
    p.add_argument("scenes", nargs="+", metavar="SCENE[:sky]",
                   help="glTF files; SCENE:sky renders under --sky 1 (no emitters)")
    p.add_argument("--width", type=int, default=256)
    p.add_argument("--height", type=int, default=256)
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--depth", type=int, default=8, help="reflections of the path pair")
    p.add_argument("--pairs", type=mcrt_run.comma_list, default=list(PAIRS),
                   help="of %s (default all)" % ",".join(PAIRS))
    p.add_argument("--reference-spp", type=int, default=1024)
    p.add_argument("--variant", default="llvm_ad_rgb", help="Mitsuba variant")
    p.add_argument("--out", type=mcrt_run.output_directory, required=True, help="directory for the table, JSON, references")
    p.add_argument("--device", help="mcrt's device (mcrt render --device SPEC; default its first)")
    mcrt_run.add_mcrt_option(p)
    args = p.parse_args()
    for name, value in (("--width", args.width), ("--height", args.height), ("--spp", args.spp),
                        ("--rounds", args.rounds), ("--depth", args.depth),
                        ("--reference-spp", args.reference_spp)):
        if value < 1:
            raise mcrt_run.ScriptError("%s must be at least 1, not %d" % (name, value))
    if 3 * args.rounds > WARMUP_SEED:
        raise mcrt_run.ScriptError("--rounds must be at most %d" % (WARMUP_SEED // 3))
    for pair in args.pairs:
        if pair not in PAIRS:
            raise mcrt_run.ScriptError("unknown pair %s (one of %s)" % (pair, ", ".join(PAIRS)))
    for item in args.scenes:
        scene, _, tag = item.partition(":")
        if tag not in ("", "sky"):
            raise mcrt_run.ScriptError("%s: the only suffix is :sky" % item)
        if not Path(scene).is_file():
            raise mcrt_run.ScriptError("%s does not exist" % scene)
    mcrt = mcrt_run.mcrt_binary(args.mcrt)
    mref.use_mitsuba_venv(__file__)
    mi = mref.import_mitsuba(args.variant)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    with tempfile.TemporaryDirectory(prefix="mcrt-bench-vs-mitsuba-") as scratch:
        for item in args.scenes:
            for pair in args.pairs:
                rows.append(bench(args, mi, item, pair, scratch))
    text = table(rows, args, args.variant)
    (out / "bench_vs_mitsuba.md").write_text(text)
    (out / "bench_vs_mitsuba.json").write_text(json.dumps({
        "machine": platform.node(), "cpus": os.cpu_count(), "command": sys.argv,
        "python": sys.executable, "mcrt": os.path.abspath(mcrt), "mcrt_commit": git_revision(),
        "mitsuba_version": mi.__version__, "mitsuba_variant": args.variant,
        "width": args.width, "height": args.height, "spp": args.spp, "rounds": args.rounds,
        "depth": args.depth, "device": args.device, "reference_spp": args.reference_spp,
        "rows": rows},
        indent=1) + "\n")
    print(text)


if __name__ == "__main__":
    sys.exit(mcrt_run.script_main(main))

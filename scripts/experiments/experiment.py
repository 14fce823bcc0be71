#!/usr/bin/python3
"""Speed against accuracy: error against time for every estimator configuration of a scene.

Renders SCENE (through the Python module when it is built beside --mcrt, the scene loaded
once; with --cli, or without the module, with one `mcrt render` each: the same images) for
every estimator × light selection × sampler × level (an spp
count, or a time budget given to mcrt's --time-limit) × repeat, compares each image with a
reference and writes DIR/results.csv and charts:

  rmse       √MSE, MSE = mean over pixels and R, G, B of (x − ref)²;
  relmse     mean over pixels and channels of (x − ref)² / (ref² + ε), ε = 1e-2 (the relative
             MSE of the denoising literature; ε keeps black pixels from dominating);
  efficiency 1 / (MSE × seconds), seconds = `seconds_render` of the stats JSON: the time of the
             render kernels from OpenCL profiling events, without start-up and kernel build
             (PBRT 3rd ed. 13.1.2's efficiency); `wall_seconds` is the whole process (through the
             module: the call, with the EXR's writing).

The MSE against a noisy reference is the render's MSE plus the reference's own (they are
independent), so errors cannot be measured below the reference's noise: its RMSE is written in
every row (`reference_rmse_floor`) and drawn as a floor on the charts.

Reference (--reference auto): the lowest-variance estimator mcrt has for direct light, `mis`
with `power` light selection and the `sobol` sampler, at --reference-spp (default 4096) spp, as
two half renders with different seeds averaged. Its noise floor is its variance layer, honest
for Sobol samples since it comes from independent replicates (docs/EXPERIMENTS.md, "The variance layer"; the two halves'
E[(a − b)²]/4 is kept beside it as a cross-check). Every row's `layer_rmse` is the render's own
error bar the same way (√ of its variance layer's mean, bias excluded): error bars for every
sampler, from one render. It is cached in
$XDG_CACHE_HOME/mcrt/references/ (else ~/.cache/mcrt/references/), keyed by a hash of the
scene file (and its .bin buffers), the image size and the settings, with a provenance JSON.
--reference FILE.exr uses that image (its variance layer gives the floor).

Charts (PNG, matplotlib Agg): error_vs_time.png (log-log, one line per configuration, −1/2
slope guide, reference floor), error_vs_spp.png, efficiency.png (bars, at the largest level),
equal_time.png (a strip of image crops at equal render time with their error maps: one more
render of each configuration under --time-limit, listed in equal_time.csv).

Estimators are built-in names (`mcrt variants`) or a user's estimator files (FILE.cl, rendered
with --estimator-file, labelled by the file's stem), e.g. --estimators light-area,my_idea.cl: a
user's estimator is charted against the built-in ones in one command.

Usage: scripts/experiments/experiment.py SCENE --estimators a,b,... [--light-select power,...]
           [--samplers independent,...] (--spp 1,4,16,... | --seconds 0.5,1,2,...)
           [--materials gltf|lambert] [--render-options "--env FILE ..."]
           [--width W --height H] [--reference auto|FILE.exr] [--repeats K] --out DIR [--quick]
           [--mcrt build/mcrt] [--cli]
"""

import argparse
import csv
import datetime
import hashlib
import json
import math
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))  # mcrt_run, mcrt_exr
import mcrt_run  # noqa: E402

mcrt_run.require("numpy", "matplotlib")
import numpy as np  # noqa: E402

from mcrt_exr import read_exr_float_attribute, write_exr  # noqa: E402

ROOT = mcrt_run.ROOT
RELMSE_EPSILON = 1e-2
REFERENCE_SEEDS = (1000003, 2000003)  # far from the seeds of the measured renders
CSV_COLUMNS = ["scene", "estimator", "light_select", "sampler", "level", "spp", "repeat", "seed",
               "seconds", "wall_seconds", "rmse", "layer_rmse", "replicates", "relmse", "mse",
               "efficiency",
               "rel_efficiency", "reference_rmse_floor", "reference_relrmse_floor", "image_mean", "nan_samples"]


# ----- running mcrt ----------------------------------------------------------------------------

def run_mcrt(args, scene, out_stem, estimator, light_select, sampler, seed, spp=None,
             seconds=None):
    """One `mcrt render` of `estimator` (a built-in name or a .cl file); returns a
    mcrt_run.Render (rgb and variance as (3, H, W) float64, stats, wall seconds, command)."""
    options = mcrt_run.estimator_arguments(estimator) + [
        "--light-select", light_select, "--sampler", sampler, "--seed", seed,
        "--width", args.width, "--height", args.height, "--materials", args.materials]
    if args.mis_heuristic and "mis-heuristic" in mcrt_run.estimator_uses(estimator, args.mcrt):
        options += ["--mis-heuristic", args.mis_heuristic]
    if args.max_depth != 1:  # paths: the reference and every render at the same depth
        options += ["--max-depth", args.max_depth, "--rr-depth", args.rr_depth]
    if seconds is not None:
        # mcrt stops after the time limit at a whole 16-sample chunk; the spp cap is never hit.
        options += ["--spp", "16777216", "--time-limit", repr(seconds)]
    else:
        options += ["--spp", spp]
    options += args.render_options  # e.g. --env FILE: every render and the reference
    return mcrt_run.render(scene, out_stem, options, mcrt=args.mcrt)


def git_commit():
    try:
        done = subprocess.run(["git", "-C", str(ROOT), "describe", "--always", "--dirty"],
                              capture_output=True, text=True, timeout=10)
        return done.stdout.strip() or "unknown"
    except (OSError, subprocess.SubprocessError):
        return "unknown"


# ----- reference ------------------------------------------------------------------------------

def scene_hash(scene):
    """SHA-256 of the glTF file and of the buffers it names (a .gltf's .bin)."""
    h = hashlib.sha256()
    data = Path(scene).read_bytes()
    h.update(data)
    if str(scene).endswith(".gltf"):
        try:
            for buffer in json.loads(data).get("buffers", []):
                uri = buffer.get("uri", "")
                if uri and not uri.startswith("data:"):
                    h.update((Path(scene).parent / uri).read_bytes())
        except (ValueError, OSError):
            pass
    return h.hexdigest()


def option_file_hashes(options):
    """SHA-256 of every --render-options word that names a file (an --env map), by word."""
    return {o: hashlib.sha256(Path(o).read_bytes()).hexdigest() for o in options
            if Path(o).is_file()}


def reference_cache_dir():
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "mcrt" / "references"


def auto_reference(args, scene, scratch):
    """Renders (or finds in the cache) the reference; returns (rgb, info dict)."""
    settings = {"estimator": "mis", "light_select": "power", "sampler": "sobol",
                "mis_heuristic": args.mis_heuristic or "balance", "spp": args.reference_spp,
                "materials": args.materials,
                "width": args.width, "height": args.height, "seeds": list(REFERENCE_SEEDS)}
    if args.max_depth != 1:  # direct lighting keeps the keys of the references it had
        settings.update(max_depth=args.max_depth, rr_depth=args.rr_depth)
    if args.render_options:  # likewise; the files they name (a map) by their contents
        settings.update(render_options=args.render_options,
                        render_option_files=option_file_hashes(args.render_options))
    key = hashlib.sha256((scene_hash(scene) + json.dumps(settings, sort_keys=True))
                         .encode()).hexdigest()[:20]
    cache = Path(args.reference_cache) if args.reference_cache else reference_cache_dir()
    stem = cache / ("%s-%dx%d-%dspp-%s" % (Path(scene).stem, args.width, args.height,
                                            args.reference_spp, key))
    exr_path, json_path = Path(str(stem) + ".exr"), Path(str(stem) + ".json")
    if exr_path.exists() and json_path.exists():
        info = json.loads(json_path.read_text())
        rgb, _ = mcrt_run.read_image_file(exr_path)
        print("experiment: reference from the cache: %s" % exr_path, file=sys.stderr)
        return rgb, info, exr_path

    half = max(1, args.reference_spp // 2)
    print("experiment: rendering the reference (mis, power, sobol, 2 × %d spp, %d×%d)…"
          % (half, args.width, args.height), file=sys.stderr)
    halves, commands, seconds, wall = [], [], 0.0, 0.0
    for i, seed in enumerate(REFERENCE_SEEDS):
        r = run_mcrt(args, scene, str(scratch / ("reference-%d" % i)), "mis", "power", "sobol",
                     seed, spp=half)
        halves.append((r.rgb, r.variance))
        commands.append(shlex.join(r.command))
        seconds += r.stats["seconds_render"]
        wall += r.wall_seconds
    (a, va), (b, vb) = halves
    rgb = (a + b) / 2
    variance = (va + vb) / 4
    split_mse = float(np.mean((a - b) ** 2) / 4)       # MSE of the mean of the two halves
    layer_mse = float(np.mean(variance))               # what the variance layers say
    layer_relmse = float(np.mean(variance / (rgb ** 2 + RELMSE_EPSILON)))
    info = {
        "scene": str(scene), "scene_sha256": scene_hash(scene), "settings": settings,
        "commands": commands, "mcrt_commit": git_commit(),
        "date": datetime.datetime.now().astimezone().isoformat(timespec="seconds"),
        "spp": 2 * half, "seconds_render": seconds, "wall_seconds": wall,
        "image_mean": float(rgb.mean()),
        # sqrt of the variance layer per pixel, averaged: the per-pixel standard error
        "standard_error_layer": float(np.mean(np.sqrt(variance))),
        # the floor used: the reference's RMSE from its variance layers, honest for Sobol
        # samples since they come from replicates
        "rmse_floor_layer": math.sqrt(layer_mse),
        "rmse_floor": math.sqrt(layer_mse),
        "relrmse_floor": math.sqrt(layer_relmse),
        # the same measured from the two independent halves, a cross-check of the layer
        "rmse_floor_halves": math.sqrt(split_mse),
        "note": "reference = mean of two half renders with different seeds; rmse_floor = "
                "sqrt(mean of the variance layers / 4) (replicate-based for Sobol); "
                "rmse_floor_halves = sqrt(mean((a-b)^2)/4)",
    }
    cache.mkdir(parents=True, exist_ok=True)
    write_exr(exr_path, {"R": rgb[0], "G": rgb[1], "B": rgb[2], "variance.R": variance[0],
                         "variance.G": variance[1], "variance.B": variance[2]},
              float_attributes={"spp": 2 * half})
    json_path.write_text(json.dumps(info, indent=1) + "\n")
    return rgb, info, exr_path


def file_reference(path):
    rgb, variance = mcrt_run.read_image_file(path)
    info = {"file": str(path), "spp": read_exr_float_attribute(path, "spp")}
    if variance is not None:
        info["standard_error_layer"] = float(np.mean(np.sqrt(variance)))
        info["rmse_floor_layer"] = info["rmse_floor"] = math.sqrt(float(np.mean(variance)))
        info["relrmse_floor"] = math.sqrt(float(np.mean(variance / (rgb ** 2 + RELMSE_EPSILON))))
    else:
        info["rmse_floor"] = info["relrmse_floor"] = 0.0
    return rgb, info


# ----- metrics ---------------------------------------------------------------------------------

def errors(rgb, reference):
    d2 = (rgb - reference) ** 2
    mse = float(d2.mean())
    relmse = float((d2 / (reference ** 2 + RELMSE_EPSILON)).mean())
    return mse, relmse


def config_label(row):
    return "%s / %s / %s" % (row["estimator"], row["light_select"], row["sampler"])


def tonemap(rgb, scale):
    """(3, H, W) linear → (H, W, 3) sRGB in [0, 1] after multiplying by `scale`."""
    x = np.clip(np.moveaxis(rgb, 0, -1) * scale, 0, 1)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


# ----- charts ----------------------------------------------------------------------------------

save_png = mcrt_run.save_png  # pixel_maps.py and mitsuba_reference.py use it here


def grouped(rows):
    """configuration label → its levels in increasing spp, each a dict of the means over the
    repeats: spp, seconds, rmse and relrmse (from the mean MSE), efficiency, rel_efficiency."""
    configs = {}
    for r in rows:
        configs.setdefault(config_label(r), {}).setdefault(r["level"], []).append(r)
    out = {}
    for label, levels in configs.items():
        points = []
        for level, rs in levels.items():
            mse = np.mean([r["mse"] for r in rs])
            relmse = np.mean([r["relmse"] for r in rs])
            seconds = np.mean([r["seconds"] for r in rs])
            points.append({"level": level, "spp": np.mean([r["spp"] for r in rs]),
                           "seconds": seconds, "rmse": math.sqrt(mse),
                           "relrmse": math.sqrt(relmse),
                           "efficiency": 1 / (mse * seconds) if mse * seconds > 0 else math.inf,
                           "rel_efficiency": 1 / (relmse * seconds) if relmse * seconds > 0
                           else math.inf})
        out[label] = sorted(points, key=lambda p: p["spp"])
    return out


def error_chart(plt, rows, floors, x_key, x_label, title, path):
    """Two panels, RMSE and relative RMSE (√relMSE) against `x_key`, log-log."""
    fig, axes = plt.subplots(1, 2, figsize=(9.6, 4.0), dpi=100)
    groups = grouped(rows)
    for ax, y_key, y_label, floor in (
            (axes[0], "rmse", "RMSE against the reference", floors[0]),
            (axes[1], "relrmse", "relative RMSE √relMSE (ε = 1e-2)", floors[1])):
        xs_all, ys_all = [], []
        for k, (label, points) in enumerate(groups.items()):
            xs = [p[x_key] for p in points]
            ys = [p[y_key] for p in points]
            ax.plot(xs, ys, "o-", ms=3.5, lw=1.2, color="C%d" % (k % 10), label=label)
            xs_all += xs
            ys_all += ys
        if xs_all:
            # a −1/2 slope through the geometric middle of the data, drawn above it
            x0, x1 = min(xs_all), max(xs_all)
            xm = math.sqrt(x0 * x1)
            ym = math.exp(np.mean(np.log(np.maximum(ys_all, 1e-30)))) * 1.8
            gx = np.array([x0, x1])
            ax.plot(gx, ym * (gx / xm) ** -0.5, "k:", lw=1, label="slope −1/2")
        if floor > 0:
            ax.axhline(floor, color="0.4", ls="--", lw=1, label="reference's own error")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(x_label)
        ax.set_ylabel(y_label)
        ax.grid(True, which="both", alpha=0.25)
    axes[0].legend(fontsize=7, loc="lower left")
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    save_png(fig, path)
    plt.close(fig)


def efficiency_chart(plt, rows, title, path):
    """Bars of efficiency (MSE and relMSE) at each configuration's largest level."""
    groups = grouped(rows)
    labels = list(groups)
    fig, axes = plt.subplots(1, 2, figsize=(9.6, 0.42 * len(labels) + 1.4), dpi=100)
    for ax, key, x_label in ((axes[0], "efficiency", "1 / (MSE × kernel seconds)"),
                             (axes[1], "rel_efficiency", "1 / (relMSE × kernel seconds)")):
        values = [groups[l][-1][key] for l in labels]
        finite = [v for v in values if math.isfinite(v) and v > 0]
        if not finite:  # zero error everywhere (a black scene against its black reference)
            ax.text(0.5, 0.5, "no error to chart: every image equals the reference",
                    transform=ax.transAxes, ha="center", va="center", fontsize=8)
            ax.set_xticks([])
            ax.set_yticks([])
            continue
        # An exact configuration (zero error: infinite efficiency) is drawn past the best.
        best = max(finite)
        shown = [v if v in finite else best * 10 for v in values]
        order = np.argsort(shown)[::-1]
        y = np.arange(len(labels))
        ax.barh(y, [shown[i] for i in order], color="C0" if key == "efficiency" else "C1")
        ax.set_yticks(y)
        ax.set_yticklabels([labels[i] for i in order], fontsize=7)
        ax.invert_yaxis()
        ax.set_xscale("log")
        for k, i in enumerate(order):
            text = (" %.3g (×%.2g)" % (values[i], values[i] / best) if values[i] in finite
                    else " exact (zero error)")
            ax.text(shown[i], k, text, va="center", fontsize=7)
        ax.set_xlim(min(finite) / 3, best * 400)
        ax.set_xlabel(x_label + ", largest level", fontsize=8)
    fig.suptitle(title + ": efficiency (higher is better; × = relative to the best)", fontsize=9)
    fig.tight_layout()
    save_png(fig, path)
    plt.close(fig)


def equal_time_strip(plt, images, reference, title, path, crop):
    """images: list of (label, rgb, seconds, rmse). Top row the crops, bottom row |error|."""
    _, h, w = reference.shape
    ch, cw = min(crop, h), min(crop, w)
    y0, x0 = (h - ch) // 2, (w - cw) // 2
    window = (slice(None), slice(y0, y0 + ch), slice(x0, x0 + cw))
    lum = reference.mean(axis=0)
    scale = 1.0 / max(np.percentile(lum, 99), 1e-6)
    n = len(images) + 1
    fig, axes = plt.subplots(2, n, figsize=(max(1.25 * n, 4.8), 3.1), dpi=100, squeeze=False)
    fig.subplots_adjust(left=0.01, right=0.95, top=0.8, bottom=0.02, wspace=0.05, hspace=0.3)
    err_maps = [np.abs(im[1] - reference).mean(axis=0)[window[1:]] for im in images]
    vmax = max([np.percentile(e, 99) for e in err_maps] + [1e-9])
    axes[0][0].imshow(tonemap(reference[window], scale), interpolation="nearest")
    axes[0][0].set_title("reference", fontsize=7)
    axes[1][0].axis("off")
    for k, (label, rgb, seconds, rmse, spp) in enumerate(images):
        axes[0][k + 1].imshow(tonemap(rgb[window], scale), interpolation="nearest")
        axes[0][k + 1].set_title(label.replace(" / ", "\n", 1), fontsize=6)
        im = axes[1][k + 1].imshow(err_maps[k], cmap="inferno", vmin=0, vmax=vmax,
                                   interpolation="nearest")
        axes[1][k + 1].set_title("%.2f s, %d spp\nRMSE %.2g" % (seconds, spp, rmse), fontsize=6)
    for ax in axes.flat:
        ax.set_xticks([])
        ax.set_yticks([])
    cax = fig.add_axes([0.96, 0.05, 0.01, 0.3])
    fig.colorbar(im, cax=cax).ax.tick_params(labelsize=6)
    fig.suptitle(title + "\ntop: images; bottom: |x − ref| (mean of R, G, B)", fontsize=7)
    save_png(fig, path)
    plt.close(fig)


# ----- main ------------------------------------------------------------------------------------

ScriptError = mcrt_run.ScriptError


def scratch_stem(scratch, *parts):
    """A render's file stem in the scratch directory: the parts joined by '-', made safe."""
    return str(scratch / re.sub(r"[^\w.-]", "_", "-".join(str(p) for p in parts)))


def number_list(text, kind):
    try:
        values = [kind(v) for v in text.split(",") if v]
    except ValueError:
        raise argparse.ArgumentTypeError("expected a comma-separated list of numbers: %r" % text)
    if not values or any(v <= 0 for v in values):
        raise argparse.ArgumentTypeError("expected positive numbers: %r" % text)
    return values


def parse_args(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog=__doc__.split("\n\n", 1)[1])
    p.add_argument("scene")
    p.add_argument("--estimators", required=True,
                   help="comma-separated built-in estimators and/or estimator files FILE.cl")
    p.add_argument("--light-select", default="power", help="comma-separated (default power)")
    p.add_argument("--samplers", default="independent", help="comma-separated (default independent)")
    p.add_argument("--mis-heuristic", help="for the estimators that use one (mcrt variants)")
    p.add_argument("--materials", default="gltf", choices=["gltf", "lambert"],
                   help="how mcrt reads the surfaces (default gltf; lambert: the course's model)")
    levels = p.add_mutually_exclusive_group()
    levels.add_argument("--spp", type=lambda t: number_list(t, int), help="e.g. 1,4,16,64")
    levels.add_argument("--seconds", type=lambda t: number_list(t, float),
                        help="time budgets for mcrt --time-limit, e.g. 0.5,1,2")
    p.add_argument("--width", type=int, help="default 128 (32 with --quick)")
    p.add_argument("--height", type=int, help="default 128 (32 with --quick)")
    p.add_argument("--reference", default="auto", help="auto or an EXR file")
    p.add_argument("--reference-spp", type=int, help="spp of the auto reference (default 4096, "
                   "512 with --quick)")
    p.add_argument("--reference-cache", help="directory for auto references (default "
                   "$XDG_CACHE_HOME/mcrt/references)")
    p.add_argument("--repeats", type=int, help="renders per level with different seeds (default 1)")
    p.add_argument("--seed", type=int, default=1, help="seed of repeat 0 (repeat r: seed + r)")
    p.add_argument("--crop", type=int, default=96, help="crop size of the equal-time strip")
    p.add_argument("--max-depth", type=int, default=1,
                   help="mcrt --max-depth of every render and of the auto reference (paths)")
    p.add_argument("--rr-depth", type=int, default=5, help="mcrt --rr-depth with --max-depth")
    p.add_argument("--render-options", type=shlex.split, default=[],
                   help="more `mcrt render` options for every render and the auto reference, "
                        "one string, e.g. \"--env sky.hdr --env-rotate 30\" (in the "
                        "reference's settings and cache key, reference.json and the titles); a single word starting with - as "
                        "--render-options=--env-rotate=30")
    p.add_argument("--out", type=mcrt_run.output_directory, required=True, help="output directory")
    p.add_argument("--quick", action="store_true",
                   help="32×32 image, spp 1,4,16 unless given, 1 repeat, 512 spp reference")
    mcrt_run.add_mcrt_option(p)
    mcrt_run.add_cli_option(p)
    p.add_argument("--keep-images", action="store_true", help="keep every render's EXR and JSON")
    args = p.parse_args(argv)
    quick = args.quick
    args.width = args.width or (32 if quick else 128)
    args.height = args.height or (32 if quick else 128)
    args.reference_spp = args.reference_spp or (512 if quick else 4096)
    args.repeats = args.repeats or 1
    if quick:
        args.repeats = 1
    if not args.spp and not args.seconds:
        args.spp = [1, 4, 16] if quick else [1, 4, 16, 64, 256]
    return args


def check_variants(args, estimators, selects, samplers):
    """ScriptError for a missing scene or binary, or an unknown variant, before any render."""
    if not Path(args.scene).exists():
        raise ScriptError("no scene %s" % args.scene)
    mcrt_run.mcrt_binary(args.mcrt)
    if not estimators:
        raise ScriptError("--estimators: no estimator given")
    mcrt_run.check_estimators(estimators, args.mcrt)
    mcrt_run.check_choices("light selection", selects, "light_select", args.mcrt)
    mcrt_run.check_choices("sampler", samplers, "samplers", args.mcrt)
    if args.mis_heuristic:
        mcrt_run.check_choices("MIS heuristic", [args.mis_heuristic], "mis_heuristics",
                               args.mcrt)


def main(argv=None):
    args = parse_args(argv)
    estimators = mcrt_run.comma_list(args.estimators)
    selects = mcrt_run.comma_list(args.light_select)
    samplers = mcrt_run.comma_list(args.samplers)
    check_variants(args, estimators, selects, samplers)
    mcrt_run.use_module(args.mcrt, args.cli)
    plt = mcrt_run.pyplot()

    scene = Path(args.scene)
    out = Path(args.out)
    scratch = out / "renders"
    scratch.mkdir(parents=True, exist_ok=True)

    if args.reference == "auto":
        reference, ref_info, ref_path = auto_reference(args, scene, scratch)
    else:
        reference, ref_info = file_reference(args.reference)
        ref_path = Path(args.reference)
        if reference.shape[1:] != (args.height, args.width):
            raise ScriptError("reference %s is %d×%d, the renders %d×%d"
                              % (args.reference, reference.shape[2], reference.shape[1], args.width,
                        args.height))
    floor = ref_info.get("rmse_floor", 0.0)
    rel_floor = ref_info.get("relrmse_floor", 0.0)
    recorded = dict(ref_info, path=str(ref_path))
    if args.render_options:  # the options of this run's renders, whatever the reference's
        recorded["render_options"] = args.render_options
    (out / "reference.json").write_text(json.dumps(recorded, indent=1) + "\n")
    print("experiment: reference %s: %s spp, RMSE floor %.3g from its variance layer (its two "
          "halves say %.3g)" % (ref_path, ref_info.get("spp"), floor,
                                ref_info.get("rmse_floor_halves", float("nan"))), file=sys.stderr)

    levels = args.spp if args.spp else args.seconds
    rows, images, configs = [], {}, []
    for estimator in estimators:
        name = mcrt_run.estimator_label(estimator)  # a file's stem in the CSV and charts
        # selection only matters to the estimators that sample lights
        for select in (selects if mcrt_run.uses_light_select(estimator, args.mcrt)
                       else selects[:1]):
            for sampler in samplers:
                configs.append((estimator, select, sampler))
                for level in levels:
                    for repeat in range(args.repeats):
                        seed = args.seed + repeat
                        stem = scratch_stem(scratch, name, select, sampler, level, repeat)
                        kw = {"spp": level} if args.spp else {"seconds": level}
                        r = run_mcrt(args, scene, stem, estimator, select, sampler, seed, **kw)
                        rgb, stats, wall = r.rgb, r.stats, r.wall_seconds
                        mse, relmse = errors(rgb, reference)
                        seconds = stats["seconds_render"]
                        row = {"scene": scene.name, "estimator": name, "light_select": select,
                               "sampler": sampler, "level": level, "spp": stats["spp"],
                               "repeat": repeat, "seed": seed, "seconds": seconds,
                               "wall_seconds": wall, "rmse": math.sqrt(mse),
                               # the render's own error bar: √ of its variance layer's mean,
                               # honest for every sampler (replicates), bias excluded
                               "layer_rmse": math.sqrt(float(np.mean(r.variance))),
                               "replicates": stats.get("replicates", 1), "relmse": relmse,
                               "mse": mse,
                               "efficiency": 1.0 / (mse * seconds) if mse > 0 and seconds > 0
                               else float("inf"),
                               "rel_efficiency": 1.0 / (relmse * seconds)
                               if relmse > 0 and seconds > 0 else float("inf"),
                               "reference_rmse_floor": floor,
                               "reference_relrmse_floor": rel_floor, "image_mean": float(rgb.mean()),
                               "nan_samples": stats.get("nan_samples", 0)}
                        rows.append(row)
                        if repeat == 0:
                            images[(config_label(row), level)] = (rgb, seconds, math.sqrt(mse),
                                                                  stats["spp"])
                        if not args.keep_images:
                            mcrt_run.remove_outputs(stem)
                        print("experiment: %s, %s %s: %.3f s, RMSE %.4g" % (
                            config_label(row), level, "spp" if args.spp else "s", seconds,
                            row["rmse"]), file=sys.stderr)

    with open(out / "results.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=CSV_COLUMNS, extrasaction="ignore")
        writer.writeheader()
        for r in rows:
            writer.writerow({k: ("%.6g" % v if isinstance(v, float) else v) for k, v in r.items()})

    title = "%s, %d×%d" % (scene.name, args.width, args.height)
    if args.render_options:
        title += ", " + shlex.join(Path(o).name if Path(o).is_file() else o
                                   for o in args.render_options)
    error_chart(plt, rows, (floor, rel_floor), "seconds", "kernel seconds (seconds_render)",
                title, out / "error_vs_time.png")
    error_chart(plt, rows, (floor, rel_floor), "spp", "samples per pixel", title,
                out / "error_vs_spp.png")
    efficiency_chart(plt, rows, title, out / "efficiency.png")

    # Equal time: one more render of every configuration under --time-limit T, T the least
    # over the configurations of their second-largest level's time (a quarter of the sweep's
    # cost more); with --seconds, the largest level, already rendered at equal time.
    groups = grouped(rows)
    strip = []
    if args.seconds:
        target = max(args.seconds)
        for label in groups:
            rgb, seconds, rmse, spp = images[(label, target)]
            strip.append((label, rgb, seconds, rmse, spp))
    else:
        target = min(points[max(len(points) - 2, 0)]["seconds"] for points in groups.values())
        target = max(target, 0.05)
        for (estimator, select, sampler) in configs:
            name = mcrt_run.estimator_label(estimator)
            stem = scratch_stem(scratch, "equal-time", name, select, sampler)
            r = run_mcrt(args, scene, stem, estimator, select, sampler, args.seed + 7919,
                         seconds=target)
            mse, _ = errors(r.rgb, reference)
            label = "%s / %s / %s" % (name, select, sampler)
            strip.append((label, r.rgb, r.stats["seconds_render"], math.sqrt(mse),
                          r.stats["spp"]))
            if not args.keep_images:
                mcrt_run.remove_outputs(stem)
    strip.sort(key=lambda s: s[3])
    (out / "equal_time.csv").write_text(
        "estimator,light_select,sampler,seconds,spp,rmse\n" + "".join(
            "%s,%.6g,%d,%.6g\n" % (s[0].replace(" / ", ","), s[2], s[4], s[3]) for s in strip))
    equal_time_strip(plt, strip, reference, title + ", equal time ≈%.2g s" % target,
                     out / "equal_time.png", args.crop)
    print("experiment: wrote %s (results.csv, error_vs_time.png, error_vs_spp.png, "
          "efficiency.png, equal_time.png, equal_time.csv)" % out, file=sys.stderr)


if __name__ == "__main__":
    sys.exit(mcrt_run.script_main(main))

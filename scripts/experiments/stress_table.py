#!/usr/bin/python3
"""Stability where methods fail: the error of each direct estimator on each stress scene.

For every scene of scenes/stress × direct estimator (× light selection: `power`, or all three on
the scenes about selection), renders K independent seeds with the mcrt executable at a fixed spp
and measures, from the K EXRs and stats JSONs:

  m_k      image mean of render k: the mean over all pixels and the R, G, B channels;
  RSE      relative standard error at equal samples: std(m_1..m_K, ddof=1) / mean(m_1..m_K),
           the relative error of one render's image mean;
  RSE_t    the same at equal time: RSE × √(t / t_ref), t the least seconds_render (device time,
           without kernel build) of the row's K renders (the one least disturbed by other load),
           t_ref the median of t over the scene's rows. Error falls as 1/√time, so this is the RSE the estimator would reach in the
           time t_ref: the efficiency 1/(σ²·t) (PBRT 3rd ed. 13.7) as a relative error;
  px RSE   relative per-pixel error from the EXRs' variance layer: √(mean of the variance of
           the pixel means over pixels, channels and renders) / (mean of the pixel means);
  NaN      total nan_samples of the K stats JSONs (non-finite samples the renderer dropped).

An RSE of "∞" means every render's image mean was 0 (no sample found light). Prints Markdown
tables: RSE and RSE_t as an estimator × scene matrix, then every measurement.

The estimators are the direct-light ones of `mcrt variants` (those that use lights), the
MIS ones once per heuristic, those that sample a light first; the selections are all of the
table's. The EXRs are read with scripts/tools/mcrt_exr.py (zlib and numpy: Debian 12 has no Python
OpenEXR binding).

Usage: scripts/experiments/stress_table.py [--mcrt build/mcrt] [--seeds 8] [--spp 64] [--size 128]
                               [--scenes NAME ...] [--keep DIR]
"""

import argparse
import math
import statistics
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))  # mcrt_run, mcrt_exr
import mcrt_run  # noqa: E402

mcrt_run.require("numpy")

ROOT = mcrt_run.ROOT
SCENES = ["tiny-bright-light", "near-light", "grazing-light", "light-facing-away", "many-lights",
          "degenerate-emitters", "reflecting-emitters"]
# Scenes about light selection: every selection; the others use power.
SELECTION_SCENES = {"light-facing-away", "many-lights"}


def estimators(mcrt, chosen=None):
    """(label, estimator, extra arguments, samples a light) of each direct-light estimator of
    the table of variants (DESIGN.md), or of `chosen` (names or users' .cl files): those that
    sample a light first, an MIS one once per heuristic, labelled "mis (balance)"."""
    rows = []
    for name in chosen or mcrt_run.names("estimators", uses="lights", mcrt=mcrt):
        samples_light = mcrt_run.uses_light_select(name, mcrt)
        if mcrt_run.is_estimator_file(name):  # the user's file says which heuristic, if any
            rows.append((mcrt_run.estimator_label(name), name, [], samples_light))
        elif "mis-heuristic" in mcrt_run.estimator_uses(name, mcrt):
            rows += [("%s (%s)" % (name, h), name, ["--mis-heuristic", h], samples_light)
                     for h in mcrt_run.names("mis_heuristics", mcrt=mcrt)]
        else:
            rows.append((name, name, [], samples_light))
    return sorted(rows, key=lambda row: not row[3])  # stable: the table's order otherwise


# ----- measurements ----------------------------------------------------------------------------

def render(mcrt, scene, estimator, extra, select, seed, args, scratch):
    stem = scratch / ("%s-%s%s-%s-%d" % (scene, mcrt_run.estimator_label(estimator),
                                         "".join(extra[1:]), select, seed))
    r = mcrt_run.render(ROOT / "scenes" / "stress" / (scene + ".gltf"), stem,
                        ["--width", args.size, "--height", args.size, "--spp", args.spp,
                         "--light-select", select, "--seed", seed]
                        + mcrt_run.estimator_arguments(estimator) + extra, mcrt=mcrt)
    return r.rgb, r.variance, r.stats


def measure(mcrt, scene, estimator, extra, select, args, scratch):
    means, seconds, nan, pixel_mean, pixel_var = [], [], 0, 0.0, 0.0
    for k in range(args.seeds):
        rgb, variance, stats = render(mcrt, scene, estimator, extra, select, 1 + k, args, scratch)
        means.append(rgb.mean())
        seconds.append(stats["seconds_render"])
        nan += stats["nan_samples"]
        pixel_mean += rgb.mean() / args.seeds
        pixel_var += variance.mean() / args.seeds
    mean = statistics.fmean(means)
    rse = statistics.stdev(means) / mean if mean > 0 else math.inf
    px_rse = math.sqrt(pixel_var) / pixel_mean if pixel_mean > 0 else math.inf
    return {"mean": mean, "rse": rse, "px_rse": px_rse, "seconds": min(seconds),
            "nan": nan}


def percent(x):
    if math.isinf(x):
        return "∞"
    return "%.3g%%" % (100 * x)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    mcrt_run.add_mcrt_option(parser)
    parser.add_argument("--seeds", type=int, default=8, help="independent renders K")
    parser.add_argument("--spp", type=int, default=64, help="samples per pixel")
    parser.add_argument("--size", type=int, default=128, help="image width and height")
    parser.add_argument("--scenes", nargs="+", default=SCENES, choices=SCENES)
    parser.add_argument("--keep", help="keep the EXRs and JSONs in this directory")
    parser.add_argument("--estimators", type=mcrt_run.comma_list,
                        help="comma-separated names or users' .cl files (default: every direct "
                             "estimator of `mcrt variants`)")
    args = parser.parse_args()
    if args.estimators:
        mcrt_run.check_estimators(args.estimators, args.mcrt)
    table = estimators(args.mcrt, args.estimators)
    selections = mcrt_run.names("light_select", mcrt=args.mcrt)
    order = ["power"] + [s for s in selections if s != "power"]  # the default first

    with tempfile.TemporaryDirectory(prefix="mcrt-stress-") as temporary:
        scratch = Path(args.keep) if args.keep else Path(temporary)
        scratch.mkdir(parents=True, exist_ok=True)
        rows = []  # (scene, label, select, measurement)
        for scene in args.scenes:
            scene_rows = []
            for label, estimator, extra, samples_light in table:
                selects = ["power"]
                if scene in SELECTION_SCENES and samples_light:
                    selects = selections
                for select in selects:
                    m = measure(args.mcrt, scene, estimator, extra, select, args, scratch)
                    scene_rows.append((scene, label, select, m))
                    print("%s / %s / %s: RSE %s, %.3f s" % (scene, label, select,
                                                            percent(m["rse"]), m["seconds"]),
                          file=sys.stderr)
            t_ref = statistics.median(m["seconds"] for *_, m in scene_rows)
            for *_, m in scene_rows:
                m["rse_t"] = m["rse"] * math.sqrt(m["seconds"] / t_ref)
            rows += scene_rows

    print("%d×%d pixels, %d spp, K = %d seeds; cell: RSE at equal spp · RSE at equal time\n"
          % (args.size, args.size, args.spp, args.seeds))
    keys = []
    for _, label, select, _ in rows:
        if (label, select) not in keys:
            keys.append((label, select))
    keys.sort(key=lambda k: ([e[0] for e in table].index(k[0]), order.index(k[1])))
    cells = {(s, l, sel): m for s, l, sel, m in rows}
    print("| estimator | " + " | ".join(args.scenes) + " |")
    print("|---|" + "---|" * len(args.scenes))
    for label, select in keys:
        name = label if select == "power" else "%s, %s" % (label, select)
        line = []
        for scene in args.scenes:
            m = cells.get((scene, label, select))
            if m is None:
                line.append("")
            else:
                nan = " (NaN: %d)" % m["nan"] if m["nan"] else ""
                line.append("%s · %s%s" % (percent(m["rse"]), percent(m["rse_t"]), nan))
        print("| %s | %s |" % (name, " | ".join(line)))

    print("\n| scene | estimator | selection | image mean | RSE | RSE_t | px RSE | s/render | NaN |")
    print("|---|---|---|---|---|---|---|---|---|")
    for scene, label, select, m in rows:
        print("| %s | %s | %s | %.5g | %s | %s | %s | %.3f | %d |" % (
            scene, label, select, m["mean"], percent(m["rse"]), percent(m["rse_t"]),
            percent(m["px_rse"]), m["seconds"], m["nan"]))
    if any(m["nan"] for *_, m in rows):
        raise mcrt_run.ScriptError("non-finite samples: see the NaN column")


if __name__ == "__main__":
    sys.exit(mcrt_run.script_main(main))

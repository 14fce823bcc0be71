#!/usr/bin/python3
"""Light selection at equal time: the efficiency of uniform, power, alias and tree selection.

For every scene × selection, renders K seeds with one direct estimator (default light-area) at a
fixed spp and measures, from the EXRs' variance layers and the stats JSONs:

  var      variance of the pixel means (the variance layer), averaged over pixels, channels and
           the K renders: all pixels, and the lit-surface pixels only — those through which no
           camera ray sees an emitter (where the estimator does the work; pixels on a visible
           light vary by where the jitter lands on its edge, the same for every selection).
           The mask: one `ambient-uniform --sky 0,0,0` render, which is L_e at the first hit.
  t        the least seconds_render (device time, no start-up or kernel build) of the K
           renders, the one least disturbed by other load;
  eff      1 / (var × t) (PBRT 3rd ed. 13.1.2): independent of spp, so renders at equal spp
           compare as at equal time; printed relative to `power`'s.

Then renders each selection once more with the spp that power's time buys it (equal time) and
writes DIR/NAME-ESTIMATOR-equal-time.png: one crop per selection (sRGB, one exposure) with its
lit-pixel RMSE against a reference: the selection of least variance at 8× the spp.

Prints a Markdown table per estimator, one row per scene, and writes DIR/results.json.

Usage: scripts/experiments/light_select_table.py [SCENE ...] [--selections uniform,power,alias,tree]
           [--estimators light-area] [--spp 64] [--size 128] [--seeds 3] [--crop X,Y,W]
           --out DIR [--mcrt build/mcrt] [--cli]

Renders through the Python module built beside --mcrt when there is one (each scene loaded
once), else, or with --cli, with one `mcrt render` each: the same images.
"""

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))  # mcrt_run, mcrt_exr
import mcrt_run  # noqa: E402

mcrt_run.require("numpy", "matplotlib")
import numpy as np  # noqa: E402

ROOT = mcrt_run.ROOT
SHARED = ROOT.parent / "shared" / "scenes"
DEFAULT_SCENES = [
    ROOT / "scenes" / "stress" / "light-facing-away.gltf",
    ROOT / "scenes" / "stress" / "many-lights.gltf",
    ROOT / "out" / "many-lights" / "lamp-field.gltf",
    ROOT / "out" / "many-lights" / "lamp-grid.gltf",
    ROOT / "out" / "many-lights" / "emissive-bunny.gltf",
    SHARED / "cornell" / "mcguire_CornellBox-Original" / "CornellBox-Original.gltf",
    SHARED / "lights" / "modern-hall" / "modern-hall.gltf",
]


def scene_name(path):
    return Path(path).stem


def lit_mask(scene, size, out, mcrt):
    """True where no camera ray of the pixel sees an emitter."""
    r = mcrt_run.render(scene, out / ("%s-mask" % scene_name(scene)),
                        ["--estimator", "ambient-uniform", "--sky", "0,0,0", "--width", size,
                         "--height", size, "--spp", 16], mcrt=mcrt)
    return np.all(r.rgb == 0.0, axis=0)


def measure(scene, estimator, selection, size, spp, seeds, out, mcrt, mask):
    variances, lit, times = [], [], []
    for seed in range(seeds):
        stem = out / ("%s-%s-%s-%d" % (scene_name(scene), estimator, selection, seed))
        r = mcrt_run.render(scene, stem, ["--estimator", estimator, "--light-select", selection,
                                          "--width", size, "--height", size, "--spp", spp,
                                          "--seed", seed], mcrt=mcrt)
        variances.append(r.variance.mean())
        lit.append(r.variance[:, mask].mean() if mask.any() else float("nan"))
        times.append(r.stats["seconds_render"])
        if r.stats["nan_samples"]:
            print("warning: %s %s %s: %d NaN samples" % (scene_name(scene), estimator, selection,
                                                         r.stats["nan_samples"]), file=sys.stderr)
        mcrt_run.remove_outputs(stem)
    t = min(times)
    var, var_lit = float(np.mean(variances)), float(np.mean(lit))
    return {"var": var, "var_lit": var_lit, "seconds": t,
            "eff": 1.0 / (var * t) if var > 0 else float("inf"),
            "eff_lit": 1.0 / (var_lit * t) if var_lit > 0 else float("inf")}


def srgb(x, exposure):
    x = np.clip(x * exposure, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def equal_time_strip(scene, estimator, selections, rows, size, spp, out, mcrt, mask, crop):
    """One render per selection with the spp that power's (else the first's) time buys it; a PNG
    strip of crops with each one's lit-pixel RMSE against a reference (the least-variance
    selection at 8× spp)."""
    base = rows.get("power") or rows[selections[0]]
    budget = base["seconds"] * spp  # spp × seconds: s gets spp × t_power / t_s
    best = min(selections, key=lambda s: rows[s]["var_lit"] if mask.any() else rows[s]["var"])
    ref = mcrt_run.render(scene, out / ("%s-%s-reference" % (scene_name(scene), estimator)),
                          ["--estimator", estimator, "--light-select", best, "--width", size,
                           "--height", size, "--spp", 8 * spp, "--seed", 1000], mcrt=mcrt)
    images = []
    for s in selections:
        s_spp = max(1, int(round(budget / rows[s]["seconds"])))
        r = mcrt_run.render(scene, out / ("%s-%s-%s-equal" % (scene_name(scene), estimator, s)),
                            ["--estimator", estimator, "--light-select", s, "--width", size,
                             "--height", size, "--spp", s_spp, "--seed", 500], mcrt=mcrt)
        m = mask if mask.any() else np.ones_like(mask)
        rmse = float(np.sqrt(np.mean((r.rgb[:, m] - ref.rgb[:, m]) ** 2)))
        images.append((s, s_spp, rmse, r.rgb))
    x, y, w = crop if crop else (size // 4, size // 4, size // 2)
    lit_mean = float(ref.rgb[:, mask].mean()) if mask.any() else float(ref.rgb.mean())
    exposure = 0.5 / max(lit_mean, 1e-8)
    plt = mcrt_run.pyplot()
    fig, axes = plt.subplots(1, len(images), figsize=(2.2 * len(images), 2.5))
    for ax, (s, s_spp, rmse, rgb) in zip(np.atleast_1d(axes), images):
        ax.imshow(srgb(np.transpose(rgb[:, y:y + w, x:x + w], (1, 2, 0)), exposure),
                  interpolation="nearest")
        ax.set_title("%s, %d spp\nRMSE %.3g" % (s, s_spp, rmse), fontsize=8)
        ax.axis("off")
    fig.suptitle("%s, %s, equal time" % (scene_name(scene), estimator), fontsize=9)
    path = out / ("%s-%s-equal-time.png" % (scene_name(scene), estimator))
    mcrt_run.save_png(fig, path)
    plt.close(fig)
    return {s: {"spp": s_spp, "rmse_lit": rmse} for s, s_spp, rmse, _ in images}, str(path)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("scenes", nargs="*", default=[str(s) for s in DEFAULT_SCENES])
    p.add_argument("--selections", type=mcrt_run.comma_list, default=["uniform", "power", "alias", "tree"])
    p.add_argument("--estimators", type=mcrt_run.comma_list, default=["light-area"])
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--size", type=int, default=128)
    p.add_argument("--seeds", type=int, default=3)
    p.add_argument("--crop", type=lambda t: tuple(int(v) for v in t.split(",")),
                   help="X,Y,W of the equal-time crops (default the central half)")
    p.add_argument("--no-strips", action="store_true", help="skip the equal-time crops")
    p.add_argument("--out", type=mcrt_run.output_directory, required=True)
    mcrt_run.add_mcrt_option(p)
    mcrt_run.add_cli_option(p)
    a = p.parse_args()
    mcrt_run.check_choices("light selection", a.selections, "light_select", mcrt=a.mcrt)
    mcrt_run.use_module(a.mcrt, a.cli)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    results = {}
    for estimator in a.estimators:
        print("\n%s, %d×%d, %d spp, %d seeds; efficiency 1/(var × t) relative to power's "
              "(lit-surface pixels; all pixels in brackets)\n" % (estimator, a.size, a.size, a.spp, a.seeds))
        print("| scene | " + " | ".join(a.selections) + " | tree's t / power's |")
        print("|---|" + "---|" * (len(a.selections) + 1))
        for scene in a.scenes:
            if not Path(scene).exists():
                print("warning: %s is missing (scripts/scenes/make_many_light_scenes.py writes "
                      "out/many-lights)" % scene, file=sys.stderr)
                continue
            mask = lit_mask(scene, a.size, out, a.mcrt)
            rows = {s: measure(scene, estimator, s, a.size, a.spp, a.seeds, out, a.mcrt, mask)
                    for s in a.selections}
            base = rows.get("power") or rows[a.selections[0]]
            cells = ["%.3g (%.3g)" % (rows[s]["eff_lit"] / base["eff_lit"], rows[s]["eff"] / base["eff"])
                     for s in a.selections]
            ratio = (rows["tree"]["seconds"] / base["seconds"]) if "tree" in rows else float("nan")
            print("| %s | %s | %.2f |" % (scene_name(scene), " | ".join(cells), ratio), flush=True)
            entry = {"rows": rows, "lit_fraction": float(mask.mean())}
            if not a.no_strips:
                entry["equal_time"], entry["strip"] = equal_time_strip(
                    scene, estimator, a.selections, rows, a.size, a.spp, out, a.mcrt, mask, a.crop)
            results.setdefault(estimator, {})[scene_name(scene)] = entry
    (out / "results.json").write_text(json.dumps(results, indent=1))
    print("\nwrote %s" % (out / "results.json"))


if __name__ == "__main__":
    sys.exit(mcrt_run.script_main(main))

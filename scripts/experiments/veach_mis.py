#!/usr/bin/python3
"""Veach's MIS experiment (Veach 1997, fig. 9.2) with glossy plates: light sampling, BSDF
sampling and MIS (balance and power heuristics) on the four plates of scenes/veach-mis, whose
roughness grows from the top plate down while the three lights span 400x in size.

For each estimator it renders at every time budget of --seconds (mcrt's --time-limit; the time
reported is the stats' seconds_render, kernel time without start-up), measures the relative MSE
(mean of (x - ref)^2 / (ref^2 + 1e-2)) of the whole image and of each plate's pixels against a
reference (mis, power heuristic, Sobol, --reference-spp), and writes:

  DIR/results.csv      one row per render: estimator, seconds, spp, relMSE overall and per plate
  DIR/plates.png       equal-time crops, one row per plate, one column per estimator + reference
  DIR/error_vs_time.png  relMSE of each plate against time, one line per estimator

The plates' pixels are found by projecting each plate's box through the scene's camera.

Usage: scripts/experiments/veach_mis.py [--scene scenes/veach-mis/veach-mis.gltf] [--size 384x216]
           [--seconds 0.5,1,2,4] [--reference-spp 4096] --out DIR [--mcrt build/mcrt] [--cli]

Renders through the Python module built beside --mcrt when there is one (the scene loaded once,
each estimator's kernels built once), else, or with --cli, with one `mcrt render` each.
"""

import argparse
import csv
import json
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))  # mcrt_run, mcrt_exr
import mcrt_run  # noqa: E402

mcrt_run.require("numpy", "matplotlib")
import numpy as np  # noqa: E402

RELMSE_EPSILON = 1e-2
CONFIGS = [  # (label, options)
    ("light-area", ["--estimator", "light-area"]),
    ("bsdf", ["--estimator", "bsdf"]),
    ("mis (balance)", ["--estimator", "mis", "--mis-heuristic", "balance"]),
    ("mis (power)", ["--estimator", "mis", "--mis-heuristic", "power"]),
]
PLATES = ["cube_0", "cube_1", "cube_2", "cube_8"]  # top to bottom: Mitsuba alpha .01 .05 .1 .25


def node_matrix(node):
    m = node.get("matrix")
    if m is None:
        return np.eye(4)  # the converter writes matrices only
    return np.array(m, dtype=np.float64).reshape(4, 4).T


def plate_boxes(scene, width, height):
    """name -> (x0, x1, y0, y1) pixel box of each plate: its accessor's bounds through the
    camera (DESIGN.md's camera: local -Z forward, +Y up, aspect width/height)."""
    g = json.loads(Path(scene).read_text())
    camera_node = next(n for n in g["nodes"] if "camera" in n)
    yfov = g["cameras"][camera_node["camera"]]["perspective"]["yfov"]
    to_camera = np.linalg.inv(node_matrix(camera_node))
    tan_half = math.tan(yfov / 2)
    aspect = width / height
    boxes = {}
    for node in g["nodes"]:
        if node.get("name") not in PLATES:
            continue
        accessor = g["accessors"][g["meshes"][node["mesh"]]["primitives"][0]["attributes"]["POSITION"]]
        lo, hi = accessor["min"], accessor["max"]
        xs, ys = [], []
        for corner in range(8):
            p = np.array([hi[k] if corner >> k & 1 else lo[k] for k in range(3)] + [1.0])
            c = to_camera @ (node_matrix(node) @ p)
            x = c[0] / (-c[2]) / (tan_half * aspect)
            y = c[1] / (-c[2]) / tan_half
            xs.append((x + 1) / 2 * width)
            ys.append((1 - y) / 2 * height)
        boxes[node["name"]] = (max(0, int(min(xs))), min(width, int(math.ceil(max(xs)))),
                               max(0, int(min(ys))), min(height, int(math.ceil(max(ys)))))
    return [boxes[name] for name in PLATES]


def relmse(rgb, ref):
    return float(((rgb - ref) ** 2 / (ref ** 2 + RELMSE_EPSILON)).mean())


def tonemap(rgb):
    x = np.clip(np.moveaxis(rgb, 0, -1), 0, 1)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--scene", default=str(mcrt_run.ROOT / "scenes" / "veach-mis" / "veach-mis.gltf"))
    p.add_argument("--size", type=mcrt_run.image_size, default=(384, 216))
    p.add_argument("--seconds", type=lambda t: [float(v) for v in mcrt_run.comma_list(t)],
                   default=[0.5, 1, 2, 4])
    p.add_argument("--reference-spp", type=int, default=4096)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--out", type=mcrt_run.output_directory, required=True)
    mcrt_run.add_mcrt_option(p)
    mcrt_run.add_cli_option(p)
    args = p.parse_args()
    mcrt_run.use_module(args.mcrt, args.cli)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    width, height = args.size
    size = ["--width", width, "--height", height]

    # The reference, kept in DIR with its settings so that a rerun reuses it.
    ref_options = size + ["--estimator", "mis", "--mis-heuristic", "power", "--sampler", "sobol",
                          "--spp", args.reference_spp, "--seed", 12345]
    ref_stem = out / "reference"
    key = json.dumps([str(o) for o in ref_options] + [args.scene])
    key_file = out / "reference.key"
    if not (key_file.exists() and key_file.read_text() == key and Path(str(ref_stem) + ".exr").exists()):
        print("reference: %d spp" % args.reference_spp, flush=True)
        mcrt_run.render(args.scene, ref_stem, ref_options, mcrt=args.mcrt, read_image=False)
        key_file.write_text(key)
    ref, _ = mcrt_run.read_image_file(str(ref_stem) + ".exr")
    boxes = plate_boxes(args.scene, width, height)

    rows, last = [], {}
    for label, options in CONFIGS:
        for seconds in args.seconds:
            stem = out / ("%s-%g" % (label.replace(" ", "").replace("(", "-").replace(")", ""), seconds))
            r = mcrt_run.render(args.scene, stem, size + options + ["--spp", 1 << 20, "--time-limit",
                                                                     seconds, "--seed", args.seed],
                                mcrt=args.mcrt)
            row = {"estimator": label, "time_limit": seconds,
                   "seconds": r.stats["seconds_render"], "spp": r.stats["spp"],
                   "relmse": relmse(r.rgb, ref)}
            for k, (x0, x1, y0, y1) in enumerate(boxes):
                row["relmse_plate%d" % (k + 1)] = relmse(r.rgb[:, y0:y1, x0:x1], ref[:, y0:y1, x0:x1])
            rows.append(row)
            last[label] = r.rgb
            print("%-14s %5.2f s  %6d spp  relMSE %.4g  plates %s" % (
                label, row["seconds"], row["spp"], row["relmse"],
                " ".join("%.3g" % row["relmse_plate%d" % (k + 1)] for k in range(4))), flush=True)

    with open(out / "results.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)

    plt = mcrt_run.pyplot()
    # Equal-time crops at the largest budget: rows plates (top = smoothest), columns estimators.
    columns = [label for label, _ in CONFIGS] + ["reference"]
    fig, axes = plt.subplots(len(boxes), len(columns), figsize=(2.4 * len(columns), 1.3 * len(boxes) + 0.6))
    for j, label in enumerate(columns):
        image = ref if label == "reference" else last[label]
        for i, (x0, x1, y0, y1) in enumerate(boxes):
            ax = axes[i][j]
            ax.imshow(tonemap(image[:, y0:y1, x0:x1]), interpolation="nearest")
            ax.set_xticks([])
            ax.set_yticks([])
            if i == 0:
                ax.set_title(label, fontsize=9)
            if label != "reference":
                row = next(r for r in rows if r["estimator"] == label and r["time_limit"] == args.seconds[-1])
                ax.set_xlabel("relMSE %.3g" % row["relmse_plate%d" % (i + 1)], fontsize=7)
            if j == 0:
                ax.set_ylabel("plate %d" % (i + 1), fontsize=8)
    fig.suptitle("veach-mis, equal time (%g s each); plates 1-4: roughness 0.1, 0.22, 0.32, 0.5"
                 % args.seconds[-1], fontsize=9)
    fig.tight_layout()
    mcrt_run.save_png(fig, out / "plates.png")

    fig, axes = plt.subplots(1, 5, figsize=(16, 3.4))
    for k, key in enumerate(["relmse"] + ["relmse_plate%d" % (i + 1) for i in range(4)]):
        ax = axes[k]
        for label, _ in CONFIGS:
            pts = [(r["seconds"], r[key]) for r in rows if r["estimator"] == label]
            ax.loglog([a for a, _ in pts], [b for _, b in pts], "o-", label=label, ms=3)
        ax.set_title("whole image" if k == 0 else "plate %d" % k, fontsize=9)
        ax.set_xlabel("kernel seconds", fontsize=8)
        if k == 0:
            ax.set_ylabel("relMSE", fontsize=8)
            ax.legend(fontsize=7)
    fig.tight_layout()
    mcrt_run.save_png(fig, out / "error_vs_time.png")
    print("wrote %s, %s, %s" % (out / "results.csv", out / "plates.png", out / "error_vs_time.png"))
    return 0


if __name__ == "__main__":
    sys.exit(mcrt_run.script_main(main))

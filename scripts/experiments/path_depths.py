#!/usr/bin/python3
"""Light that bounces: error against time of every direct estimator used as next-event
estimation inside the path tracer, at several depths (docs/EXPERIMENTS.md, "Paths: every direct estimator as next-event estimation").

For each scene and each depth (`N` or `N:K` for --max-depth N --rr-depth K), runs
scripts/experiments/experiment.py (its auto reference at that depth: mis, power, sobol), then prints one
markdown table: per depth and estimator the RMSE, the relative RMSE (√ of experiment.py's relMSE,
which weighs a pixel by 1/(reference² + 0.01), so that the jitter noise of the lights seen
directly, common to every estimator, does not drown the rest) and render seconds at the largest
spp, the efficiency 1/(relMSE·t) relative to the depth's best estimator, and what the indirect
light costs —
the reference's image mean against depth 1 and seconds per sample against depth 1.

Usage: scripts/experiments/path_depths.py SCENE [SCENE ...] --depths 1,2,3,8,8:1 --estimators mis,light-area,...
           [--spp 4,16,64] [--width 64 --height 64] [--reference-spp 2048] --out DIR
"""

import argparse
import csv
import json
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))  # mcrt_run, mcrt_exr
import mcrt_run  # noqa: E402

ROOT = mcrt_run.ROOT


def parse_depth(text):
    depth, _, rr = text.partition(":")
    return int(depth), int(rr) if rr else 1024  # no roulette unless asked for


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("scenes", nargs="+")
    p.add_argument("--depths", default="1,2,3,8,8:1")
    p.add_argument("--estimators", default="mis,light-area,light-solid-angle,bsdf,hemisphere-cosine")
    p.add_argument("--spp", default="4,16,64")
    p.add_argument("--width", type=int, default=64)
    p.add_argument("--height", type=int, default=64)
    p.add_argument("--reference-spp", type=int, default=2048)
    p.add_argument("--reference-cache", help="experiment.py's --reference-cache")
    p.add_argument("--reuse", action="store_true",
                   help="summarise the results.csv already in --out instead of rendering again")
    p.add_argument("--materials", default="gltf", choices=["gltf", "lambert"],
                   help="how mcrt reads the surfaces (experiment.py --materials)")
    p.add_argument("--out", type=mcrt_run.output_directory, required=True)
    mcrt_run.add_mcrt_option(p)
    args = p.parse_args()
    out = Path(args.out)
    lines = ["| scene | depth | estimator | spp | seconds | RMSE | relative RMSE | "
             "efficiency / best | reference mean / depth 1 | seconds per sample / depth 1 |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for scene in args.scenes:
        base = {}  # depth 1's reference mean and seconds per sample, per estimator
        for depth_text in args.depths.split(","):
            depth, rr = parse_depth(depth_text)
            run_dir = out / ("%s-depth%d-rr%d" % (Path(scene).stem, depth, rr))
            command = [sys.executable, str(ROOT / "scripts" / "experiments" / "experiment.py"), scene,
                       "--estimators", args.estimators, "--spp", args.spp,
                       "--width", str(args.width), "--height", str(args.height),
                       "--reference-spp", str(args.reference_spp), "--max-depth", str(depth),
                       "--rr-depth", str(rr), "--materials", args.materials,
                       "--out", str(run_dir)]
            if args.mcrt:
                command += ["--mcrt", args.mcrt]
            if args.reference_cache:
                command += ["--reference-cache", args.reference_cache]
            if not (args.reuse and (run_dir / "results.csv").exists()):
                print("path_depths: " + " ".join(command), file=sys.stderr)
                subprocess.run(command, check=True)
            reference = json.loads((run_dir / "reference.json").read_text())
            with open(run_dir / "results.csv") as f:
                rows = list(csv.DictReader(f))
            top = max(int(r["level"]) for r in rows)
            rows = [r for r in rows if int(r["level"]) == top]
            efficiency = {r["estimator"]: 1.0 / (float(r["relmse"]) * float(r["seconds"]))
                          for r in rows}
            best = max(efficiency.values())
            for r in rows:
                sps = float(r["seconds"]) / (float(r["spp"]) * args.width * args.height)
                if depth == 1:
                    base[r["estimator"]] = (reference["image_mean"], sps)
                mean1, sps1 = base.get(r["estimator"], (float("nan"), float("nan")))
                lines.append("| %s | %s | %s | %s | %.3f | %.4g | %.4g | %.2f | %.3f | %.2f |" % (
                    Path(scene).stem, depth if rr >= depth else "%d, roulette from %d" % (depth, rr),
                    r["estimator"], r["spp"], float(r["seconds"]), float(r["rmse"]),
                    float(r["relmse"]) ** 0.5, efficiency[r["estimator"]] / best,
                    reference["image_mean"] / mean1, sps / sps1))
    table = "\n".join(lines) + "\n"
    (out / "path_depths.md").write_text(table)
    print(table)


if __name__ == "__main__":
    sys.exit(mcrt_run.script_main(main))

#!/usr/bin/python3
"""Path-tracing throughput: mcrt against Mitsuba 3's `path` integrator at the same depth, in one
run on the same machine (docs/BENCHMARKS.md, "Path tracing against Mitsuba 3's path integrator").

For each scene: `mcrt render --max-depth N` (mis, power, independent) — samples and rays per
second of kernel time from its stats — and scripts/tools/mitsuba_reference.py --max-depth N (Mitsuba's
`path`, max_depth N + 1, the same image size and spp) — samples per second of its steady passes
(the first, which includes Dr.Jit's kernel compilation, left out). Scenes without emitters get
`--sky 1` in both. Prints a markdown table and writes it, with the raw numbers, to --out.

Usage: bench/bench_paths.py [--depth 8] [--width 128 --height 128] [--spp 64] [--variant llvm_ad_rgb]
           --out DIR SCENE[:sky] ...
"""

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts/tools"))  # mcrt_run, mcrt_exr
import mcrt_run  # noqa: E402

ROOT = mcrt_run.ROOT


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("scenes", nargs="+", help="glTF files; SCENE:sky renders under --sky 1")
    p.add_argument("--depth", type=int, default=8)
    p.add_argument("--width", type=int, default=128)
    p.add_argument("--height", type=int, default=128)
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--passes", type=int, default=4, help="Mitsuba passes (the first not timed)")
    p.add_argument("--variant", default="llvm_ad_rgb")
    p.add_argument("--out", type=mcrt_run.output_directory, required=True)
    mcrt_run.add_mcrt_option(p)
    args = p.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for item in args.scenes:
        scene, _, tag = item.partition(":")
        sky = ["--sky", "1"] if tag == "sky" else []
        with tempfile.TemporaryDirectory(prefix="mcrt-bench-paths-") as scratch:
            r = mcrt_run.render(scene, Path(scratch) / "m", [
                "--width", args.width, "--height", args.height, "--spp", args.spp,
                "--max-depth", args.depth, "--estimator", "mis",
                # Mitsuba's MIS weights are the power heuristic's; mcrt's default is balance.
                "--mis-heuristic", "power",
                # Mitsuba's conversion is diffuse (mitsuba_reference.py --materials lambert).
                "--materials", "lambert"] + sky, mcrt=args.mcrt,
                read_image=False)
            exr = Path(scratch) / "mitsuba.exr"
            subprocess.run([sys.executable, str(ROOT / "scripts" / "tools" / "mitsuba_reference.py"), scene,
                            "--spp", str(args.spp * args.passes), "--passes", str(args.passes),
                            "--width", str(args.width), "--height", str(args.height),
                            "--variant", args.variant, "--max-depth", str(args.depth),
                            "--out", str(exr)] + sky, check=True)
            m = json.loads(Path(str(exr) + ".json").read_text())
        pixels = args.width * args.height
        steady = m["seconds_render"] - m["seconds_first_pass"]
        row = {"scene": Path(scene).stem, "sky": bool(sky), "depth": args.depth,
               "mcrt_samples_per_second": r.stats["samples_per_second"],
               "mcrt_rays_per_second": r.stats["rays_per_second"],
               "mcrt_rays_per_sample": r.stats["rays_per_sample"],
               "mcrt_mean_path_length": r.stats["mean_path_length"],
               "mcrt_roulette_share": r.stats["roulette_share"],
               "mcrt_image_mean": sum(r.stats["image_mean"]) / 3,
               "mcrt_device": r.stats["devices"][0]["name"],
               "mitsuba_samples_per_second": pixels * args.spp * (args.passes - 1) / steady,
               "mitsuba_first_pass_seconds": m["seconds_first_pass"],
               "mitsuba_image_mean": m["image_mean"], "mitsuba_variant": args.variant}
        rows.append(row)
        print("bench_paths: %s" % json.dumps(row), file=sys.stderr)
    lines = ["| scene | depth | mcrt samples/s | mcrt rays/s | rays per sample | mean path length "
             "| roulette share | Mitsuba %s samples/s | mcrt / Mitsuba | image means (mcrt, "
             "Mitsuba) |" % args.variant, "|---|---|---|---|---|---|---|---|---|---|"]
    for row in rows:
        lines.append("| %s%s | %d | %.3g | %.3g | %.2f | %.2f | %.1f%% | %.3g | %.2f | %.4g, %.4g |" % (
            row["scene"], " (sky)" if row["sky"] else "", row["depth"],
            row["mcrt_samples_per_second"], row["mcrt_rays_per_second"],
            row["mcrt_rays_per_sample"], row["mcrt_mean_path_length"],
            100 * row["mcrt_roulette_share"], row["mitsuba_samples_per_second"],
            row["mcrt_samples_per_second"] / row["mitsuba_samples_per_second"],
            row["mcrt_image_mean"], row["mitsuba_image_mean"]))
    table = "\n".join(lines) + "\n"
    (out / "bench_paths.md").write_text(table)
    (out / "bench_paths.json").write_text(json.dumps(
        {"machine": platform.node(), "cpus": os.cpu_count(), "command": sys.argv, "rows": rows},
        indent=1) + "\n")
    print(table)


if __name__ == "__main__":
    sys.exit(mcrt_run.script_main(main))

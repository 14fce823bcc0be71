#!/usr/bin/python3
"""MPI figures: one render on 1, 2 and 3 ranks of this machine (the same cores: what MPI costs),
with the items, bytes and message overhead per work item from the stats' `ranks`.

Usage: bench/bench_mpi.py [--scene S] [--size WxH] [--spp N] [--ranks 1,2,3] [--mcrt BINARY]
Prints a Markdown table (docs/BENCHMARKS.md "Several processes (MPI)"). Rank counts run through
`mpirun --bind-to none --oversubscribe -n K`; "1 (no mpirun)" is a plain render. Only the standard library.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts/tools"))  # mcrt_run, mcrt_exr
import mcrt_run  # noqa: E402


def render(args, ranks, out_dir):
    out = Path(out_dir)
    cmd = [args.mcrt, "render", args.scene, "--width", str(args.size[0]), "--height", str(args.size[1]),
           "--spp", str(args.spp), "--quiet", "--out", str(out / "image.exr"),
           "--stats", str(out / "stats.json")]
    if ranks > 0:
        cmd = ["mpirun", "--bind-to", "none", "--oversubscribe", "-n", str(ranks)] + cmd
    # Shared memory with CMA single copy (OpenMPI's default; a container may need
    # OMPI_MCA_btl_vader_single_copy_mechanism=none, which makes large results slower).
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    subprocess.run(cmd, check=True, env=env)
    return json.loads((out / "stats.json").read_text())


def row(label, s, image_bytes, reference):
    wall = s["seconds_total"]
    samples = sum(d["samples"] for d in s["devices"])
    ranks = s.get("ranks", [])
    items = sum(d["batches"] for d in s["devices"])
    remote_items = sum(r["items"] for r in ranks if r["rank"] > 0)
    remote_bytes = sum(r["message_bytes"] for r in ranks if r["rank"] > 0)
    overhead = sum(r["seconds_message_overhead"] for r in ranks if r["rank"] > 0)
    shares = " ".join(f"r{r['rank']}:{100.0 * r['samples'] / samples:.0f}%" for r in ranks) or "-"
    per_item = (f"{remote_bytes / remote_items / 1024:.0f} KiB, {1e3 * overhead / remote_items:.2f} ms"
                if remote_items else "-")
    same = "yes" if image_bytes == reference else "NO"
    return (f"| {label} | {wall:.2f} | {samples / wall / 1e6:.2f} | {items} | {items / wall:.1f} | "
            f"{shares} | {per_item} | {same} |")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", default=str(mcrt_run.ROOT / "scenes/cornell/CornellBox-Original.gltf"))
    p.add_argument("--size", type=mcrt_run.image_size, default="512x512")
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--ranks", default="1,2,3")
    mcrt_run.add_mcrt_option(p)
    args = p.parse_args()
    args.mcrt = str(args.mcrt)
    with tempfile.TemporaryDirectory() as out:
        render(args, 0, out)  # warm the kernel cache
        s = render(args, 0, out)
        reference = (Path(out) / "image.exr").read_bytes()
        print("| processes | wall (s) | Msamples/s (wall) | items | items/s | share per rank "
              "| per remote item: bytes, message overhead | image = 1 process |")
        print("|---|---|---|---|---|---|---|---|")
        print(row("1 (no mpirun)", s, reference, reference), flush=True)
        for k in [int(x) for x in args.ranks.split(",")]:
            s = render(args, k, out)
            print(row(f"{k} (mpirun -n {k})", s, (Path(out) / "image.exr").read_bytes(), reference),
                  flush=True)


if __name__ == "__main__":
    main()

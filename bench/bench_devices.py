#!/usr/bin/python3
"""Multi-device scheduling figures: throughput with each device alone and with all together,
each device's share of the samples against its measured speed, and a simulated slow device.

Usage: bench/bench_devices.py [--scene S] [--size WxH] [--spp N] [--mcrt BINARY]
Runs build/mcrt with POCL_DEVICES="pthread basic" (two PoCL devices on the same cores) and
prints Markdown tables. MCRT_SLOW_DEVICE=D:F makes device D sleep (F-1)x its kernel time after
each launch, i.e. behave F times slower. Only the standard library.
"""
import argparse
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts/tools"))  # mcrt_run, mcrt_exr
import mcrt_run  # noqa: E402


def render(args, devices, env_extra, out_dir):
    """The stats JSON of one render on `devices` (indices for --device)."""
    options = ["--spp", args.spp, "--width", args.size[0], "--height", args.size[1]]
    for d in devices:
        options += ["--device", d]
    return mcrt_run.render(args.scene, Path(out_dir) / "image", options, mcrt=args.mcrt,
                           env=dict(POCL_DEVICES="pthread basic", **env_extra),
                           read_image=False).stats


def row(label, s):
    total = sum(d["samples"] for d in s["devices"])
    parts = []
    for d in s["devices"]:
        rate = d["samples"] / d["seconds_busy"] / 1e6 if d["seconds_busy"] > 0 else 0.0
        parts.append(f"d{d['index']}: {100.0 * d['samples'] / total:.0f}% of samples, "
                     f"{d['batches']} launches, {rate:.2f} Msamples/s busy")
    wall = s["seconds_total"]
    return (f"| {label} | {wall:.2f} | {total / wall / 1e6:.2f} | " + "; ".join(parts) + " |")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", default=str(mcrt_run.ROOT / "scenes/cornell/CornellBox-Original.gltf"))
    p.add_argument("--size", type=mcrt_run.image_size, default="512x512")
    p.add_argument("--spp", type=int, default=64)
    mcrt_run.add_mcrt_option(p)
    args = p.parse_args()
    with tempfile.TemporaryDirectory() as out:
        render(args, ["0"], {}, out)  # warm the kernel caches
        render(args, ["1"], {}, out)
        print("| devices | wall (s) | Msamples/s (wall) | per device |")
        print("|---|---|---|---|")
        for label, devices, env in [
                ("basic alone (d0)", ["0"], {}),
                ("pthread alone (d1)", ["1"], {}),
                ("both (all)", ["all"], {}),
                ("basic simulated 10x slower, alone", ["0"], {"MCRT_SLOW_DEVICE": "0:10"}),
                ("both, basic simulated 10x slower", ["all"], {"MCRT_SLOW_DEVICE": "0:10"})]:
            print(row(label, render(args, devices, env, out)), flush=True)


if __name__ == "__main__":
    sys.exit(mcrt_run.script_main(main))

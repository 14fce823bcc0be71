#!/usr/bin/python3
"""Multi-device scheduling figures: throughput with each device alone and with all together,
each device's share of the samples against its measured speed, and a simulated slow device.

Usage: scripts/bench_devices.py [--scene S] [--size WxH] [--spp N]
Runs build/mcrt with POCL_DEVICES="pthread basic" (two PoCL devices on the same cores) and
prints Markdown tables. MCRT_SLOW_DEVICE=D:F makes device D sleep (F-1)x its kernel time after
each launch, i.e. behave F times slower.
"""
import argparse
import json
import os
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def render(args, devices, env_extra, out_dir):
    stats = os.path.join(out_dir, "stats.json")
    cmd = [os.path.join(ROOT, "build", "mcrt"), "render", args.scene, "--out",
           os.path.join(out_dir, "image.exr"), "--stats", stats, "--spp", str(args.spp),
           "--width", str(args.width), "--height", str(args.height), "--quiet"]
    for d in devices:
        cmd += ["--device", d]
    env = dict(os.environ, POCL_DEVICES="pthread basic", **env_extra)
    subprocess.run(cmd, check=True, env=env)
    with open(stats) as f:
        return json.load(f)


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
    p.add_argument("--scene", default=os.path.join(ROOT, "scenes/cornell/CornellBox-Original.gltf"))
    p.add_argument("--size", default="512x512")
    p.add_argument("--spp", type=int, default=64)
    args = p.parse_args()
    args.width, args.height = (int(v) for v in args.size.split("x"))
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
    main()

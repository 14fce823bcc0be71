#!/usr/bin/python3
"""Render throughput of `mcrt render` on a set of scenes, as a Markdown table.

Usage: scripts/bench_render.py [--spp N] [--size WxH] SCENE...
Each scene is rendered once to warm the kernel cache, then once more for the figures; the
figures are those of the stats JSON (kernel time from OpenCL profiling events).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def render(scene, spp, width, height, out_dir):
    stats = os.path.join(out_dir, "stats.json")
    cmd = [os.path.join(ROOT, "build", "mcrt"), "render", scene, "--out",
           os.path.join(out_dir, "image.exr"), "--stats", stats, "--spp", str(spp),
           "--width", str(width), "--height", str(height), "--quiet"]
    subprocess.run(cmd, check=True)
    with open(stats) as f:
        return json.load(f)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenes", nargs="+")
    parser.add_argument("--spp", type=int, default=16)
    parser.add_argument("--size", default="512x512")
    args = parser.parse_args()
    width, height = (int(v) for v in args.size.split("x"))
    print("| scene | triangles | lights | BVH build (s) | SAH cost | kernel build (s) | "
          "render (s) | Msamples/s | Mrays/s |")
    print("|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as out_dir:
        for scene in args.scenes:
            render(scene, args.spp, width, height, out_dir)  # warm the kernel cache
            s = render(scene, args.spp, width, height, out_dir)
            print(f"| {os.path.relpath(scene, ROOT)} | {s['triangles']} | {s['lights']} | "
                  f"{s['seconds_bvh_build']:.3f} | {s['bvh']['sah_cost']:.1f} | "
                  f"{s['seconds_kernel_build']:.3f} | {s['seconds_render']:.3f} | "
                  f"{s['samples_per_second'] / 1e6:.2f} | {s['rays_per_second'] / 1e6:.2f} |")
            sys.stdout.flush()


if __name__ == "__main__":
    main()

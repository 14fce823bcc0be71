#!/usr/bin/python3
"""Render throughput of `mcrt render` on a set of scenes, as a Markdown table.

Usage: bench/bench_render.py [--spp N] [--size WxH] [--mcrt BINARY] SCENE...
Each scene is rendered once to warm the kernel cache, then once more for the figures; the
figures are those of the stats JSON (kernel time from OpenCL profiling events). Only the
standard library.
"""
import argparse
import os
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts/tools"))  # mcrt_run, mcrt_exr
import mcrt_run  # noqa: E402


def render(args, scene, out_dir):
    """The stats JSON of one render of `scene`."""
    return mcrt_run.render(scene, Path(out_dir) / "image",
                           ["--spp", args.spp, "--width", args.size[0], "--height", args.size[1]],
                           mcrt=args.mcrt, read_image=False).stats


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenes", nargs="+")
    parser.add_argument("--spp", type=int, default=16)
    parser.add_argument("--size", type=mcrt_run.image_size, default="512x512")
    mcrt_run.add_mcrt_option(parser)
    args = parser.parse_args()
    print("| scene | triangles | lights | BVH build (s) | SAH cost | kernel build (s) | "
          "render (s) | Msamples/s | Mrays/s |")
    print("|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as out_dir:
        for scene in args.scenes:
            render(args, scene, out_dir)  # warm the kernel cache
            s = render(args, scene, out_dir)
            print(f"| {os.path.relpath(scene, mcrt_run.ROOT)} | {s['triangles']} | {s['lights']} | "
                  f"{s['seconds_bvh_build']:.3f} | {s['bvh']['sah_cost']:.1f} | "
                  f"{s['seconds_kernel_build']:.3f} | {s['seconds_render']:.3f} | "
                  f"{s['samples_per_second'] / 1e6:.2f} | {s['rays_per_second'] / 1e6:.2f} |")
            sys.stdout.flush()


if __name__ == "__main__":
    sys.exit(mcrt_run.script_main(main))

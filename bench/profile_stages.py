#!/usr/bin/python3
"""Where a sample's time goes: the render kernel with one stage left out at a time, against the
whole, in alternating rounds (docs/BENCHMARKS.md, "Where a sample's time goes").

Each stage is a textual change of a copy of kernels/ (read through MCRT_KERNEL_DIR), checked to
apply exactly once, so that a kernel edit which moves a stage's code fails loudly here instead of
measuring nothing. A stage's cost is the whole sample's kernel time per sample minus that of the
variant without it. Leaving a stage out changes the image (that is the point) but not the work
around it: the shadow ray's answer is replaced by `true`, the BSDF ray by a miss, the camera
ray's estimate by its normal, the store by a store nobody takes, the sample hash by a cheaper one.
The stages assume the `mis` estimator with a Lambertian scene (--materials lambert), direct
lighting, independent sampler: what `bench/bench_vs_mitsuba.py`'s mis pair renders.

Usage: bench/profile_stages.py [--rounds 5] [--width 256 --height 256 --spp 64] [--mcrt BINARY]
           [--device SPEC] SCENE...
(--device: mcrt render's; Intel's OpenCL runtime under scripts/with-intel.)
Needs numpy (Debian's python3-numpy; /usr/bin/python3).
"""

import argparse
import shutil
import statistics
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts/tools"))  # mcrt_run, mcrt_exr
import bench_ab  # noqa: E402
import mcrt_run  # noqa: E402

# (stage, file, text, replacement): the variant without the stage.
STAGES = [
    ("shadow ray (any hit)", "estimators/estimators.cl",
     "        if (light_sample_visible(scene, sp, &ls)) {\n            float pdf_light = "
     "light_sample_pdf_w(&ls);",
     "        if (true) {\n            float pdf_light = light_sample_pdf_w(&ls);"),
    ("BSDF ray (closest hit and its surface point)", "estimators/estimators.cl",
     "        if (trace_bsdf_sample(scene, sp, &bs, rays, &seen)) {\n            float3 Le = "
     "emitted_radiance(&seen);",
     "        if (as_uint(bs.wi.x) == 0x12345u && trace_bsdf_sample(scene, sp, &bs, rays, "
     "&seen)) {\n            float3 Le = emitted_radiance(&seen);"),
    ("the estimator (light and BSDF sampling, both rays, MIS)", "estimators/path.cl",
     "        L += beta * MCRT_ESTIMATE(scene, &sp, stream, &record->rays);",
     "        L += beta * sp.n;"),
    ("the sample's store", "render/render.cl",
     "    samples[g] = (uint4)(as_uint3(L), pack_path_record(&record));",
     "    if (as_uint(L.x) == 0x12345u) samples[g] = (uint4)(as_uint3(L), "
     "pack_path_record(&record));"),
    ("pcg4d's second round (half the sample hashing)", "sampling/rng.cl",
     "    v ^= v >> 16u;\n    v.x += v.y * v.w;\n    v.y += v.z * v.x;\n    v.z += v.x * v.y;\n"
     "    v.w += v.y * v.z;\n    return v;",
     "    v ^= v >> 16u;\n    return v;"),
]


def variant_dir(root, stage):
    """A copy of kernels/ in root/NAME without the stage; its path."""
    name, file, text, replacement = stage
    out = Path(root) / ("v%d" % STAGES.index(stage))
    shutil.copytree(mcrt_run.ROOT / "kernels", out)
    path = out / file
    source = path.read_text()
    if source.count(text) != 1:
        raise mcrt_run.ScriptError("stage '%s': its code is not in kernels/%s exactly once; "
                                   "update STAGES to the kernels" % (name, file))
    path.write_text(source.replace(text, replacement))
    return str(out)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("scenes", nargs="+")
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--width", type=int, default=256)
    p.add_argument("--height", type=int, default=256)
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--device", help="mcrt render --device SPEC (default mcrt's first device)")
    mcrt_run.add_mcrt_option(p)
    args = p.parse_args()
    mcrt_run.require("numpy")
    binary = mcrt_run.mcrt_binary(args.mcrt)
    options = ["--width", args.width, "--height", args.height, "--spp", args.spp,
               "--estimator", "mis", "--materials", "lambert"] + \
        (["--device", args.device] if args.device else [])
    samples = args.width * args.height * args.spp
    print("| scene | stage left out | ns per sample without it, median (range) | the stage's "
          "cost, ns per sample | share of the sample |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory(prefix="mcrt-profile-stages-") as scratch:
        variants = [("whole sample", binary, str(mcrt_run.ROOT / "kernels"))] + [
            (s[0], binary, variant_dir(scratch, s)) for s in STAGES]
        for scene in args.scenes:
            ns = {v[0]: [] for v in variants}
            for v in variants:  # warm each variant's kernel caches
                bench_ab.render(v, scene, Path(scratch) / "warm", options)
            for _ in range(args.rounds):
                for v in variants:
                    r = bench_ab.render(v, scene, Path(scratch) / "r", options)
                    ns[v[0]].append(1e9 * r.stats["seconds_render"] / samples)
            whole = statistics.median(ns["whole sample"])
            for v in variants:
                x = ns[v[0]]
                cost = whole - statistics.median(x)
                print("| %s | %s | %.1f (%.1f–%.1f) | %s | %s |" % (
                    Path(scene).stem, v[0], statistics.median(x), min(x), max(x),
                    "—" if v[0] == "whole sample" else "%.1f" % cost,
                    "100%" if v[0] == "whole sample" else "%.0f%%" % (100 * cost / whole)))
    print()
    print("%dx%d, %d spp, mis, --materials lambert, --device %s; %d rounds alternating; kernel "
          "time per sample (the stats' seconds_render)." % (
              args.width, args.height, args.spp, args.device or "default", args.rounds))


if __name__ == "__main__":
    sys.exit(mcrt_run.script_main(main))

#!/usr/bin/python3
"""The gate for shading eight (or sixteen) samples wide: how much faster the shading of a sample
runs on Intel's OpenCL CPU runtime when its vectoriser spreads work-items across SIMD lanes than
when each work-item runs as scalar code (docs/BENCHMARKS.md, "Intel's OpenCL CPU runtime beside
PoCL").

For each scene it writes six copies of kernels/ under --out/SCENE (the shipped kernels stay as
they are) and times them with bench/bench_ab.py, alternating:

  real/          the kernels as shipped (scalar on Intel: intel_vec_len_hint(1))
  real-vec/      the same with MCRT_INTEL_VECTORIZE defined (vectorised across work-items)
  fixed/         bvh_closest_hit and bvh_any_hit replaced by a fixed answer: no traversal
  fixed-vec/     the fixed answer, vectorised
  coherent/      a fixed answer that rays of nearly the same origin and direction share
  coherent-vec/  that answer, vectorised
  fixed-vec8/, coherent-vec8/  vectorised eight work-items wide (intel_vec_len_hint(8))

The fixed answer is a hash of the ray's origin and direction bits: the closest hit misses for
1 ray in 8, else hits a triangle chosen by the hash among the scene's packets (an unused packet
lane falls back to the packet's lane 0; the triangle the ray leaves counts as a miss) at
barycentrics uniform over it; any-hit reports 1 ray in 4 blocked. The coherent answer hashes
the bits down to the fourth of the mantissa (1/16 relative), so that a pixel's camera rays (its
samples are adjacent work-items, so one SIMD vector) mostly hit one triangle, as real camera
rays do; the rays leaving a surface still scatter. Everything else of a sample (camera ray,
sampler, light selection and sampling, BSDF evaluation and sampling, MIS, accumulation) runs as
shipped, on surfaces with the scene's materials. The packet count comes from a tiny render's
stats (`bvh.packets`).

Variants per scene: pocl-real and pocl-fixed on PoCL, intel-real, intel-real-vec, intel-fixed,
intel-fixed-vec, intel-fixed-vec8, intel-coherent, intel-coherent-vec and intel-coherent-vec8
on Intel's runtime; the figures are
bench_ab's (kernel-time samples per second) and the gate's ratio is intel-fixed-vec /
intel-fixed (and intel-coherent-vec / intel-coherent), each round's pair, median over rounds.

Usage: scripts/with-intel bench/shading_gate.py [--mcrt build/mcrt] [--out /tmp/shading-gate]
           [--rounds 3] [--width 128 --height 128 --spp 32]
           [--estimators mis,light-area] [--materials gltf,lambert] [--write-only] SCENE...
Needs Intel's runtime laid out (scripts/setup-intel-opencl) and numpy (/usr/bin/python3).
"""

import argparse
import json
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

# lowbias32 (C. Wellons, "Prospecting for hash functions", 2018) over the ray's float bits.
FIXED_PRELUDE = """
inline uint gate_hash(uint x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

inline uint gate_ray_hash(const Ray* r) {
    uint3 o = as_uint3(r->org) & MCRT_GATE_MASK, d = as_uint3(r->dir) & MCRT_GATE_MASK;
    return gate_hash(o.x ^ gate_hash(o.y ^ gate_hash(o.z ^ gate_hash(d.x ^ gate_hash(d.y ^
           gate_hash(d.z))))));
}
"""

FIXED_CLOSEST = """inline Hit bvh_closest_hit(global const Bvh4Node* nodes,
                           global const TrianglePacket* packets, const Ray* r, float t_max,
                           uint skip, const AlphaTest* alpha) {
    /* The gate's fixed answer (bench/shading_gate.py): no traversal. */
    uint h = gate_ray_hash(r), h2 = gate_hash(h), h3 = gate_hash(h2);
    Hit hit;
    hit.t = 1.0f;
    float u1 = (float)(h2 >> 8) * 0x1.0p-24f, u2 = (float)(h3 >> 8) * 0x1.0p-24f;
    bool fold = u1 + u2 > 1.0f;
    hit.b1 = fold ? 1.0f - u1 : u1;
    hit.b2 = fold ? 1.0f - u2 : u2;
    uint packet = (h >> 3) % (uint)MCRT_GATE_PACKETS, lane = h2 & 3u;
    lane = packets[packet].index[lane] == MCRT_NO_HIT ? 0u : lane;
    hit.lane = packet * MCRT_PACKET_WIDTH + lane;
    hit.lane = (h & 7u) == 0u || hit.lane == skip ? MCRT_NO_HIT : hit.lane;
    return hit;
}
"""

FIXED_ANY = """inline bool bvh_any_hit(global const Bvh4Node* nodes,
                        global const TrianglePacket* packets, const Ray* r, float t_max,
                        uint skip, const AlphaTest* alpha) {
    /* The gate's fixed answer (bench/shading_gate.py): no traversal. */
    return (gate_ray_hash(r) & 3u) == 0u;
}
"""


def replace_function(text, head, body):
    """text with the function starting at `head` (up to its closing brace at column 0) replaced
    by body."""
    start = text.index(head)
    end = text.index("\n}\n", start) + 3
    return text[:start] + body + text[end:]


def write_variants(out, packets):
    """The four kernel directories under out (real, real-vec, fixed, fixed-vec)."""
    out = Path(out)
    names = ("real", "real-vec", "fixed", "fixed-vec", "fixed-vec8", "coherent", "coherent-vec",
             "coherent-vec8")
    for name in names:
        d = out / name
        if d.exists():
            shutil.rmtree(d)
        shutil.copytree(ROOT / "kernels", d)
        if "-vec" in name:
            f = d / "core/shared_types.h"
            text = f.read_text()
            anchor = "#if defined(MCRT_INTEL_CPU) && defined(MCRT_INTEL_VECTORIZE)"
            assert anchor in text
            text = text.replace(anchor, "#define MCRT_INTEL_VECTORIZE\n" + anchor, 1)
            if name.endswith("-vec8"):
                # Eight work-items per vector (AVX2 width) instead of the runtime's choice
                # (sixteen with AVX-512); CL_CONFIG_CPU_VECTORIZER_MODE would also reach the
                # scalar variants, whose intel_vec_len_hint(1) it conflicts with.
                anchor = "#define inline inline __attribute__((always_inline))\n"
                assert anchor in text
                text = text.replace(anchor, anchor + "#define kernel __kernel "
                                    "__attribute__((intel_vec_len_hint(8)))\n", 1)
            f.write_text(text)
        if not name.startswith("real"):
            f = d / "traversal/bvh_traverse.cl"
            text = f.read_text()
            text = replace_function(text, "inline Hit bvh_closest_hit(global", FIXED_CLOSEST)
            text = replace_function(text, "inline bool bvh_any_hit(global", FIXED_ANY)
            anchor = "typedef struct {\n    float t;\n"
            assert anchor in text
            # coherent: the hash of the rays' bits down to 4 of the mantissa's, so that rays
            # of nearly the same origin and direction (a pixel's camera rays) get one answer.
            mask = 0xfff80000 if name.startswith("coherent") else 0xffffffff
            text = text.replace(anchor, "#define MCRT_GATE_PACKETS %du\n#define MCRT_GATE_MASK "
                                "0x%08xu\n%s" % (packets, mask, anchor), 1)
            # The hash after Hit's declaration (it needs Ray, from geometry.cl, already included).
            anchor = "} Hit;\n"
            text = text.replace(anchor, anchor + FIXED_PRELUDE, 1)
            f.write_text(text)
    return {name: out / name for name in names}


def scene_packets(mcrt, scene):
    with tempfile.TemporaryDirectory(prefix="mcrt-gate-") as tmp:
        stats = Path(tmp) / "stats.json"
        subprocess.run([mcrt, "render", scene, "--width", "8", "--height", "8", "--spp", "1",
                        "--device", "pocl", "--quiet", "--out", str(Path(tmp) / "x.exr"), "--stats",
                        str(stats)], check=True, stdout=subprocess.DEVNULL)
        s = json.loads(stats.read_text())
    return int(s["bvh"]["packets"])


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("scenes", nargs="+")
    p.add_argument("--mcrt", default=str(ROOT / "build/mcrt"))
    p.add_argument("--out", default="/tmp/shading-gate")
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--width", type=int, default=128)
    p.add_argument("--height", type=int, default=128)
    p.add_argument("--spp", type=int, default=32)
    p.add_argument("--estimators", default="mis,light-area")
    p.add_argument("--materials", default="gltf,lambert")
    p.add_argument("--write-only", action="store_true",
                   help="write the kernel directories and stop")
    args = p.parse_args()
    summary = []
    for scene in args.scenes:
        stem = re.sub(r"[^A-Za-z0-9_-]", "_", Path(scene).stem)
        packets = scene_packets(args.mcrt, scene)
        dirs = write_variants(Path(args.out) / stem, packets)
        print("%s: %d packets, kernels in %s" % (scene, packets, Path(args.out) / stem),
              flush=True)
        if args.write_only:
            continue
        m = args.mcrt
        variants = [("intel-fixed", m, dirs["fixed"], "intel"),
                    ("intel-fixed-vec", m, dirs["fixed-vec"], "intel"),
                    ("intel-fixed-vec8", m, dirs["fixed-vec8"], "intel"),
                    ("intel-coherent", m, dirs["coherent"], "intel"),
                    ("intel-coherent-vec", m, dirs["coherent-vec"], "intel"),
                    ("intel-coherent-vec8", m, dirs["coherent-vec8"], "intel"),
                    ("intel-real", m, dirs["real"], "intel"),
                    ("intel-real-vec", m, dirs["real-vec"], "intel"),
                    ("pocl-fixed", m, dirs["fixed"], "pocl"),
                    ("pocl-real", m, dirs["real"], "pocl")]
        for estimator in args.estimators.split(","):
            for materials in args.materials.split(","):
                js = Path(args.out) / ("%s-%s-%s.json" % (stem, estimator, materials))
                cmd = [sys.executable, str(ROOT / "bench/bench_ab.py"), "--rounds",
                       str(args.rounds), "--width", str(args.width), "--height",
                       str(args.height), "--spp", str(args.spp), "--options",
                       "--estimator %s --materials %s" % (estimator, materials), "--json",
                       str(js)]
                for label, binary, kernels, device in variants:
                    cmd += ["--variant", "%s=%s@%s" % (label, binary, kernels),
                            "--variant-options", "%s=--device %s" % (label, device)]
                cmd.append(scene)
                print("$ " + " ".join(cmd), flush=True)
                if subprocess.run(cmd).returncode != 0:
                    print("gate: %s %s %s: bench_ab failed" % (stem, estimator, materials),
                          flush=True)
                    continue
                rows = {r["variant"]: r for r in json.loads(js.read_text())["rows"]}

                def paired(a, b):
                    return [x / y for x, y in zip(rows[a]["msamples_per_second"],
                                                  rows[b]["msamples_per_second"])]
                for name, a, b in (("shading vec/scalar", "intel-fixed-vec", "intel-fixed"),
                                   ("shading vec8/scalar", "intel-fixed-vec8", "intel-fixed"),
                                   ("coherent shading vec/scalar", "intel-coherent-vec",
                                    "intel-coherent"),
                                   ("coherent shading vec8/scalar", "intel-coherent-vec8",
                                    "intel-coherent"),
                                   ("real vec/scalar", "intel-real-vec", "intel-real"),
                                   ("intel-fixed/pocl-fixed", "intel-fixed", "pocl-fixed"),
                                   ("intel-fixed-vec/pocl-fixed", "intel-fixed-vec",
                                    "pocl-fixed")):
                    q = paired(a, b)
                    summary.append((stem, estimator, materials, name, statistics.median(q),
                                    min(q), max(q)))
                    print("gate: %s %s %s %s: %.3f (%.3f-%.3f)" % summary[-1], flush=True)
    if summary:
        print()
        print("| scene | estimator | materials | ratio | paired median (range) |")
        print("|---|---|---|---|---|")
        for s in summary:
            print("| %s | %s | %s | %s | %.2f (%.2f–%.2f) |" % s)


if __name__ == "__main__":
    sys.exit(main())

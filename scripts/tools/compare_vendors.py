#!/usr/bin/python3
"""Renders every kernel configuration on the first device of each OpenCL platform present and
compares the EXRs byte for byte: every estimator with every light selection, every sampler,
both material models, paths, the sky light and the example estimator files. Run it with two
implementations visible (docs/ROBUSTNESS.md, "Every OpenCL implementation"):

    scripts/with-intel scripts/tools/compare_vendors.py [--mcrt build/mcrt] [--size 32] [--spp 32]

Prints one line per configuration and a summary; exits 1 when any configuration differs or fails.
"""

import argparse
import itertools
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
CORNELL = ROOT / "scenes/cornell/CornellBox-Original.gltf"
GLOSSY = ROOT / "scenes/glossy/cornell-metal-block.gltf"
TEXTURED = ROOT / "tests/data/textured"

DIRECT = ["hemisphere-uniform", "hemisphere-cosine", "bsdf", "light-area", "light-solid-angle", "mis"]
AMBIENT = ["ambient-uniform", "ambient-cosine", "ambient-fibonacci"]
SELECTIONS = ["uniform", "power", "alias", "tree"]
SAMPLERS = ["independent", "stratified", "sobol"]


def configurations():
    """(name, scene, options) for each configuration compared."""
    for estimator, selection in itertools.product(DIRECT, SELECTIONS):
        yield ("%s %s" % (estimator, selection), CORNELL,
               ["--estimator", estimator, "--light-select", selection])
    for estimator, sampler in itertools.product(["light-area", "mis", "bsdf"], SAMPLERS):
        yield ("%s %s, glossy" % (estimator, sampler), GLOSSY,
               ["--estimator", estimator, "--sampler", sampler])
    yield ("mis power heuristic, glossy", GLOSSY,
           ["--estimator", "mis", "--mis-heuristic", "power"])
    for shared in ["sponza/crytek-sponza.gltf", "lights/modern-hall/modern-hall.gltf"]:
        path = ROOT.parent / "shared/scenes" / shared
        if path.exists():  # the larger third-party scenes, where present
            yield ("mis depth 3, %s" % path.stem, path, ["--estimator", "mis", "--max-depth", "3"])
    for scene in ["checker_linear", "wrap_clamp_mirror", "emissive_light", "mask_occluder",
                  "blend_texture_light"]:
        yield ("mis depth 3, textured %s" % scene, TEXTURED / (scene + ".gltf"),
               ["--estimator", "mis", "--max-depth", "3"])
    for shared in ["textured/DamagedHelmet/DamagedHelmet.gltf",
                   "textured/AlphaBlendModeTest/AlphaBlendModeTest.gltf",
                   "textured/NormalTangentTest/NormalTangentTest.gltf"]:
        path = ROOT.parent / "shared/scenes" / shared
        if path.exists():
            yield ("mis depth 3 under the sky, %s" % path.stem, path,
                   ["--estimator", "mis", "--max-depth", "3", "--sky", "1"])
    for materials in ["gltf", "lambert"]:
        yield ("mis depth 8, %s" % materials, GLOSSY,
               ["--estimator", "mis", "--max-depth", "8", "--materials", materials])
    for estimator in ["mis", "light-solid-angle", "hemisphere-cosine"]:
        yield ("%s depth 3 under a sky light" % estimator, CORNELL,
               ["--estimator", estimator, "--max-depth", "3", "--sky", "0.4"])
    for estimator, sampler in itertools.product(AMBIENT, SAMPLERS):
        yield ("%s %s" % (estimator, sampler), CORNELL,
               ["--estimator", estimator, "--sampler", sampler, "--sky", "1"])
    for path in sorted((ROOT / "examples/estimators").glob("*.cl")):
        yield ("estimator file %s, depth 2" % path.name, CORNELL,
               ["--estimator-file", str(path), "--max-depth", "2"])


def platforms(mcrt):
    """{platform name: index of its first device} from `mcrt devices`."""
    out = subprocess.run([mcrt, "devices"], capture_output=True, text=True, check=True).stdout
    first = {}
    for line in out.splitlines():
        m = re.match(r"(\d+): .* — (.*?) \(", line)
        if m:
            first.setdefault(m.group(2), int(m.group(1)))
    return first


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--mcrt", default=str(ROOT / "build/mcrt"))
    parser.add_argument("--size", type=int, default=32)
    parser.add_argument("--spp", type=int, default=32)
    args = parser.parse_args()

    found = platforms(args.mcrt)
    if len(found) < 2:
        print("compare_vendors: %d OpenCL platform(s) present; run under scripts/with-intel"
              % len(found), file=sys.stderr)
        return 1
    print("platforms: " + ", ".join("%s (device %d)" % kv for kv in found.items()))
    bad = 0
    total = 0
    with tempfile.TemporaryDirectory() as tmp:
        for name, scene, options in configurations():
            total += 1
            images = {}
            for platform, index in found.items():
                out = Path(tmp) / ("%d.exr" % index)
                r = subprocess.run([args.mcrt, "render", str(scene), "--out", str(out),
                                    "--width", str(args.size), "--height", str(args.size),
                                    "--spp", str(args.spp), "--device", str(index), "--quiet"]
                                   + options, capture_output=True, text=True)
                images[platform] = out.read_bytes() if r.returncode == 0 else None
                if r.returncode != 0:
                    print("  %s on %s: exit %d: %s" % (name, platform, r.returncode,
                                                        r.stderr.strip().splitlines()[-1:]))
            same = None not in images.values() and len(set(images.values())) == 1
            bad += not same
            print("%-50s %s" % (name, "same bytes" if same else "DIFFERENT"))
    print("%d of %d configurations the same bytes on every platform" % (total - bad, total))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/python3
"""The textured glTF scenes of ../shared/scenes/textured rendered by mcrt, each beside its model's
own reference screenshot (docs/EXPERIMENTS.md, "Textured scenes").

Every scene is rendered under a uniform sky (`--sky`, default 1), or an environment map (`--env`,
with `--env-scale` and `--env-rotate`), by `mis` paths of up to
--max-depth reflections (default 4), with the glTF materials, from the view of VIEWS: the scene's
own camera where it has one (MultiUVTest), the view of SOURCES.md for Sponza, a frontal view of
the flat test boards (they lie in the XY plane and face +Z), and for the other models (none has
a camera; the bench camera of DESIGN.md is too close to the boxes) a view near the
screenshot's. The figure (--figure) shows each render next to screenshot/screenshot.png (or
.jpg) of the scene's folder. Those screenshots come from rasterisers lit by image-based lighting:
they show what each test should look like, not what a path tracer under a uniform sky computes.

--sponza-picture also renders textured Sponza under the sky at --sponza-depth reflections
(480×320 by default) for the README.

The renders stay in --out (default out/textured-gallery/), one EXR and stats JSON per scene.
A missing --scenes folder, or a scene missing from it, is skipped with one line.

Usage: scripts/experiments/textured_gallery.py [--scenes DIR] [--spp 64] [--only A,B]
           [--env MAP.hdr [--env-scale S] [--env-rotate DEG]]
           [--figure docs/figures/textured-gallery.png] [--sponza-picture PNG] [--mcrt BIN]
"""

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))  # mcrt_run, mcrt_exr
import mcrt_run  # noqa: E402

ROOT = mcrt_run.ROOT
DEFAULT_SCENES = ROOT.parent / "shared" / "scenes" / "textured"


class View:
    """How one scene is shown: its glTF, the image size, mcrt's camera options (none: the
    scene's camera, else the bench camera), and the display exposure in stops."""

    def __init__(self, gltf, size, camera=(), exposure=0.0, sky=None):
        self.gltf, self.size, self.camera = gltf, size, list(camera)
        self.exposure, self.sky = exposure, sky


def front(x, y, distance, fov):
    """A frontal view of a board in the XY plane facing +Z: from (x, y, distance) at (x, y, 0)."""
    return ["--look-from", "%g,%g,%g" % (x, y, distance), "--look-at", "%g,%g,0" % (x, y),
            "--fov", "%g" % fov]


def look(x, y, z, fov):
    """From (x, y, z) at the origin, the centre of the models that are not boards."""
    return ["--look-from", "%g,%g,%g" % (x, y, z), "--look-at", "0,0,0", "--fov", "%g" % fov]


# Scene folder → view. Sizes follow each reference screenshot's aspect; the boards are framed
# from their world-space extents (SOURCES.md).
VIEWS = {
    "Sponza": View("Sponza.gltf", (256, 192),
                   ["--look-from", "9.2,1.44,-0.32", "--look-at", "-11.2,1.44,0", "--fov", "55"],
                   exposure=3.5),
    "DamagedHelmet": View("DamagedHelmet.gltf", (224, 216), look(2.0, 0.6, 2.2, 38)),
    "WaterBottle": View("WaterBottle.gltf", (224, 224), front(0, 0, 0.62, 28)),
    "BoxTextured": View("BoxTextured.gltf", (192, 192), look(1.9, 1.0, -0.9, 42)),
    "BoxTexturedNonPowerOfTwo": View("BoxTexturedNonPowerOfTwo.gltf", (192, 192),
                                     look(1.9, 1.0, -0.9, 42)),
    "MultiUVTest": View("MultiUVTest.gltf", (256, 186)),
    "AlphaBlendModeTest": View("AlphaBlendModeTest.gltf", (256, 120),
                               ["--look-from", "0,1.8,9", "--look-at", "0,1.0,0", "--fov", "22"]),
    "EmissiveStrengthTest": View("EmissiveStrengthTest.gltf", (256, 188),
                                 ["--look-from", "0,3,17", "--look-at", "0,-1,0", "--fov", "45"],
                                 sky=0.25),
    "NormalTangentTest": View("NormalTangentTest.gltf", (240, 226), front(0, -0.12, 4.0, 35)),
    "NormalTangentMirrorTest": View("NormalTangentMirrorTest.gltf", (256, 192),
                                    front(-0.01, -0.07, 4.2, 35)),
    "TextureCoordinateTest": View("TextureCoordinateTest.gltf", (224, 224), front(0, 0, 4.4, 35)),
    # A dimmer sky where the test patches are emitters, so that the white emissive labels
    # stand out as in the screenshots.
    "TextureEncodingTest": View("TextureEncodingTest.gltf", (256, 160), front(0, 0.5, 26, 28),
                                sky=0.25),
    "TextureLinearInterpolationTest": View("TextureLinearInterpolationTest.gltf", (224, 224),
                                           front(0, 0.5, 10, 32), sky=0.25),
    "TextureSettingsTest": View("TextureSettingsTest.gltf", (240, 236), front(0, -0.6, 17, 35)),
    "TextureTransformMultiTest": View("TextureTransformMultiTest.gltf", (224, 230),
                                      front(0, -0.2, 4.2, 34)),
    "TextureTransformTest": View("TextureTransformTest.gltf", (256, 188),
                                 front(0, -0.05, 3.2, 42)),
}


def screenshot(folder):
    """The model's reference picture: screenshot/screenshot.png or .jpg, else None."""
    for suffix in (".png", ".jpg"):
        path = folder / "screenshot" / ("screenshot" + suffix)
        if path.exists():
            return path
    return None


def render_options(view, args, spp, size=None, depth=None):
    width, height = size or view.size
    if args.env:  # the map in the sky's place, scaled as the view dims its sky
        scale = args.env_scale * (float(view.sky) if view.sky is not None else 1.0)
        light = ["--env", args.env, "--env-scale", scale, "--env-rotate", args.env_rotate]
    else:
        light = ["--sky", view.sky if view.sky is not None else args.sky]
    return (["--width", width, "--height", height, "--spp", spp] + light +
            ["--estimator", "mis", "--max-depth", depth or args.max_depth, "--seed", args.seed]
            + view.camera)


def to_srgb(rgb, exposure=0.0):
    """(3, H, W) linear radiance → (H, W, 3) sRGB in [0, 1], clipped (IEC 61966-2-1)."""
    import numpy as np
    x = np.clip(np.moveaxis(rgb, 0, -1) * 2.0 ** exposure, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)


def figure(rows, path):
    """Pairs (name, render sRGB, screenshot path) in a grid, four pairs to a row."""
    import numpy as np
    from PIL import Image
    plt = mcrt_run.pyplot()
    pairs_per_row = 4
    n_rows = (len(rows) + pairs_per_row - 1) // pairs_per_row
    fig, axes = plt.subplots(n_rows, 2 * pairs_per_row, figsize=(16, 2.35 * n_rows), dpi=100,
                             squeeze=False)
    for ax in axes.flat:
        ax.set_xticks([])
        ax.set_yticks([])
        ax.axis("off")
    for k, (name, image, shot) in enumerate(rows):
        ax_render = axes[k // pairs_per_row][2 * (k % pairs_per_row)]
        ax_shot = axes[k // pairs_per_row][2 * (k % pairs_per_row) + 1]
        ax_render.imshow(image, interpolation="bilinear")
        ax_render.set_title("%s: mcrt" % name, fontsize=7)
        if shot is not None:
            ax_shot.imshow(np.asarray(Image.open(shot).convert("RGB")), interpolation="bilinear")
            ax_shot.set_title("reference screenshot", fontsize=7)
    fig.tight_layout(pad=0.3, h_pad=0.6, w_pad=0.2)
    mcrt_run.save_png(fig, path)
    plt.close(fig)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog=__doc__.split("\n\n", 1)[1])
    p.add_argument("--scenes", default=str(DEFAULT_SCENES),
                   help="folder of the textured scenes (default ../shared/scenes/textured)")
    p.add_argument("--only", type=mcrt_run.comma_list, help="scene folders to render, A,B,...")
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--max-depth", type=int, default=4)
    p.add_argument("--sky", default="1", help="sky radiance, one value or R,G,B (default 1)")
    p.add_argument("--env", default="",
                   help="an environment map (.exr, .hdr) in place of the sky, as mcrt's --env "
                   "(e.g. scripts/scenes/make_sky_maps.py's sun-sky.hdr)")
    p.add_argument("--env-scale", type=float, default=1.0, help="with --env: mcrt's --env-scale")
    p.add_argument("--env-rotate", type=float, default=0.0, help="with --env: mcrt's --env-rotate")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", type=mcrt_run.output_directory, default=str(ROOT / "out" / "textured-gallery"),
                   help="folder for the EXRs and stats")
    p.add_argument("--figure", default=str(ROOT / "docs" / "figures" / "textured-gallery.png"),
                   help="the gallery PNG ('' for none)")
    p.add_argument("--sponza-picture", default="",
                   help="also render textured Sponza to this PNG "
                   "(docs/figures/sponza-textured.png)")
    p.add_argument("--sponza-size", type=mcrt_run.image_size, default=(480, 320))
    p.add_argument("--sponza-spp", type=int, default=64)
    p.add_argument("--sponza-depth", type=int, default=8)
    p.add_argument("--sponza-exposure", type=float, default=3.5)
    mcrt_run.add_mcrt_option(p)
    args = p.parse_args()
    mcrt_run.require("numpy", "matplotlib")

    scenes = Path(args.scenes)
    if not scenes.is_dir():
        print("textured_gallery: %s is absent: nothing to render" % scenes)
        return 0
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    names = args.only or list(VIEWS)
    unknown = [n for n in names if n not in VIEWS]
    if unknown:
        raise mcrt_run.ScriptError("no view for %s (one of %s)" % (", ".join(unknown),
                                                                   ", ".join(VIEWS)))
    rows = []
    print("| scene | size | spp | render s | wall s | image mean |")
    print("|---|---|---|---|---|---|")
    for name in names:
        view = VIEWS[name]
        gltf = scenes / name / view.gltf
        if not gltf.exists():
            print("textured_gallery: %s is absent: skipped" % gltf)
            continue
        r = mcrt_run.render(gltf, out / name, render_options(view, args, args.spp),
                            mcrt=args.mcrt)
        print("| %s | %d×%d | %d | %.1f | %.1f | %.4f |" % (
            name, view.size[0], view.size[1], r.stats["spp"], r.stats["seconds_render"],
            r.wall_seconds, r.rgb.mean()), flush=True)
        rows.append((name, to_srgb(r.rgb, view.exposure), screenshot(scenes / name)))
    if args.figure and rows:
        figure(rows, args.figure)
        print("textured_gallery: wrote %s" % args.figure)

    if args.sponza_picture:
        gltf = scenes / "Sponza" / VIEWS["Sponza"].gltf
        if not gltf.exists():
            print("textured_gallery: %s is absent: no Sponza picture" % gltf)
            return 0
        options = render_options(VIEWS["Sponza"], args, args.sponza_spp, args.sponza_size,
                                 args.sponza_depth) + [
            "--sampler", "sobol", "--png", args.sponza_picture,
            "--exposure", args.sponza_exposure]
        start = time.monotonic()
        r = mcrt_run.render(gltf, out / "sponza-picture", options, mcrt=args.mcrt)
        print("textured_gallery: wrote %s (%d×%d, %d spp, depth %d: %.1f s rendering, %.1f s "
              "in all; %s)" % (args.sponza_picture, args.sponza_size[0], args.sponza_size[1],
                               r.stats["spp"], args.sponza_depth, r.stats["seconds_render"],
                               time.monotonic() - start, mcrt_run.shlex.join(map(str, r.command))))
    return 0


if __name__ == "__main__":
    sys.exit(mcrt_run.script_main(main))

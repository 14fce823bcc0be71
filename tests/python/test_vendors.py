"""One image whatever OpenCL implementation renders it, through the module: with PoCL and Intel's
CPU runtime both present (scripts/test-intel runs this as `python_vendors` under
scripts/with-intel), a scene loaded once renders the same bytes on the first device of each
platform. With one implementation the tests skip."""

from pathlib import Path

import numpy as np
import pytest

import mcrt

ROOT = Path(__file__).resolve().parents[2]
CORNELL = str(ROOT / "scenes" / "cornell" / "CornellBox-Original.gltf")
GLOSSY = str(ROOT / "scenes" / "glossy" / "cornell-metal-block.gltf")
TEXTURED = ROOT / "tests" / "data" / "textured"


def first_device_per_platform():
    first = {}
    for d in mcrt.devices():
        first.setdefault(d["platform"], d["index"])
    return first


PLATFORMS = first_device_per_platform()
pytestmark = pytest.mark.skipif(
    len(PLATFORMS) < 2, reason="one OpenCL implementation present (run under scripts/with-intel)")

# (scene, materials, render options): the determinism configurations of tests/cl/test_vendors.cpp.
CONFIGURATIONS = {
    "direct light-area": (CORNELL, "gltf", dict(estimator="light-area")),
    "glossy mis": (GLOSSY, "gltf", dict(estimator="mis")),
    "depth-8 paths": (CORNELL, "gltf", dict(estimator="mis", max_depth=8)),
    "light tree, ambient sky": (CORNELL, "gltf", dict(estimator="light-solid-angle",
                                                      light_select="tree", sky=0.3)),
    "bilinear texture": (str(TEXTURED / "checker_linear.gltf"), "gltf", dict(estimator="mis")),
}


@pytest.mark.parametrize("name", sorted(CONFIGURATIONS))
def test_every_implementation_renders_the_same_bytes(name):
    path, materials, options = CONFIGURATIONS[name]
    images = {}
    for platform, index in PLATFORMS.items():
        with mcrt.Context(device=str(index)) as ctx:
            scene = ctx.load(path, materials=materials)
            r = scene.render(width=32, height=32, spp=8, seed=3, **options)
            images[platform] = (r.image.copy(), r.variance.copy())
    (first, (image, variance)), *others = images.items()
    assert np.isfinite(image).all() and image.max() > 0
    for platform, (other_image, other_variance) in others:
        assert image.tobytes() == other_image.tobytes(), "%s against %s" % (first, platform)
        assert variance.tobytes() == other_variance.tobytes(), "%s against %s" % (first, platform)

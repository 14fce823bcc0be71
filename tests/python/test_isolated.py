"""Context(isolated=True): renders in a supervised child process, so that a user's estimator
that never returns or crashes raises DeviceError and this interpreter, and the context, go on."""

from pathlib import Path

import numpy as np
import pytest

import mcrt

ROOT = Path(__file__).resolve().parents[2]
CORNELL = str(ROOT / "scenes" / "cornell" / "CornellBox-Original.gltf")
LIGHT_AREA = (ROOT / "examples" / "estimators" / "light_area.cl").read_text()
SMALL = dict(width=24, height=24, spp=16)


def with_prologue(statements):
    """light_area.cl with statements run first in estimate()."""
    start = LIGHT_AREA.index("float3 estimate(")
    brace = LIGHT_AREA.index("{", start) + 1
    return LIGHT_AREA[:brace] + "\n" + statements + "\n" + LIGHT_AREA[brace:]


@pytest.fixture(scope="module")
def isolated():
    with mcrt.Context(isolated=True) as ctx:
        yield ctx, ctx.load(CORNELL)


def test_isolated_gives_the_bytes_of_a_context_in_process(isolated):
    ctx, scene = isolated
    with mcrt.Context() as local:
        expected = local.load(CORNELL).render(estimator="mis", **SMALL)
        r = scene.render(estimator="mis", **SMALL)
        assert r.image.tobytes() == expected.image.tobytes()
        assert r.variance.tobytes() == expected.variance.tobytes()
        assert r.spp == 16 and r.stats["spp"] == expected.stats["spp"]
        est = ctx.estimator(LIGHT_AREA, name="light_area.cl")
        user = scene.render(estimator=est, **SMALL)
        assert np.array_equal(user.image, local.load(CORNELL).render(estimator="light-area",
                                                                       **SMALL).image)


def test_isolated_errors_are_the_module_errors(isolated, tmp_path):
    ctx, scene = isolated
    with pytest.raises(mcrt.SettingError, match="--spp"):
        scene.render(spp=0)
    with pytest.raises(mcrt.SceneError):
        ctx.load(str(tmp_path / "missing.gltf"))
    with pytest.raises(TypeError):
        scene.render(width="64")
    with pytest.raises(mcrt.EstimatorError) as error:
        scene.render(estimator=ctx.estimator(with_prologue("nonsense here;"), name="bad.cl"),
                     **SMALL)
    assert error.value.line is not None


def test_an_estimator_that_never_returns_is_killed_after_its_time_limit(isolated):
    ctx, scene = isolated
    hang = ctx.estimator(with_prologue("volatile int spin = 1; while (spin) {}"), name="hang.cl")
    with pytest.raises(mcrt.DeviceError, match="time limit"):
        scene.render(estimator=hang, time_limit=0.5, **SMALL)
    # The context loads its scene into a new child and renders on.
    assert scene.render(estimator="mis", **SMALL).image.max() > 0


def test_an_estimator_that_crashes_raises(isolated, tmp_path):
    ctx, scene = isolated
    crash = ctx.estimator(with_prologue("*(volatile __global float*)0 = 1.0f;"),
                          name="crash.cl")
    with pytest.raises(mcrt.DeviceError, match="isolated render process"):
        scene.render(estimator=crash, **SMALL)
    r = scene.render(estimator="mis", **SMALL)
    assert r.image.max() > 0
    r.save(str(tmp_path / "after.exr"))
    assert (tmp_path / "after.exr").stat().st_size > 0


def test_a_closed_isolated_context(isolated):
    ctx = mcrt.Context(isolated=True)
    scene = ctx.load(CORNELL)
    ctx.close()
    assert ctx.closed
    with pytest.raises(mcrt.DeviceError, match="closed"):
        scene.render(**SMALL)

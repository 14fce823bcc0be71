"""The Python module mcrt against the command line it must agree with (docs/PYTHON.md).

Run by ctest (test python_module) with PYTHONPATH=build/python and MCRT_EXE=build/mcrt, or:
    PYTHONPATH=build/python MCRT_EXE=build/mcrt /usr/bin/python3 -m pytest tests/python
"""

import os
import signal
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import mcrt

ROOT = Path(__file__).resolve().parents[2]
CORNELL = str(ROOT / "scenes" / "cornell" / "CornellBox-Original.gltf")
MCRT_EXE = os.environ.get("MCRT_EXE", str(ROOT / "build" / "mcrt"))
SMALL = dict(width=24, height=24, spp=16)


def cli_error(*args, env=None):
    """The one line `mcrt render` prints for an error, without "mcrt: error: "."""
    run = subprocess.run([MCRT_EXE, "render", *args], capture_output=True, text=True,
                         env=None if env is None else dict(os.environ, **env))
    assert run.returncode != 0, run.stderr
    lines = [l for l in run.stderr.splitlines() if l.startswith("mcrt: error: ")]
    assert lines, run.stderr
    return lines[0][len("mcrt: error: "):]


def cli_render(tmp_path, name, *args):
    out = tmp_path / (name + ".exr")
    run = subprocess.run([MCRT_EXE, "render", CORNELL, "--out", str(out), "--quiet", *args],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    return out.read_bytes()


@pytest.fixture(scope="module")
def ctx():
    with mcrt.Context() as c:
        yield c


@pytest.fixture(scope="module")
def cornell(ctx):
    return ctx.load(CORNELL)


def render_bytes(scene, tmp_path, name, **options):
    path = tmp_path / (name + "-api.exr")
    scene.render(**options).save(str(path))
    return path.read_bytes()


# The same bytes as the command line: every estimator, then the other variants' axes.
ESTIMATORS = [e["name"] for e in mcrt.variants()["estimators"]]


@pytest.mark.parametrize("estimator", ESTIMATORS)
def test_every_estimator_gives_the_cli_bytes(cornell, tmp_path, estimator):
    options = dict(SMALL, estimator=estimator, seed=3)
    args = ["--width", "24", "--height", "24", "--spp", "16", "--estimator", estimator,
            "--seed", "3"]
    if not estimator.startswith("ambient"):
        options.update(max_depth=3)
        args += ["--max-depth", "3"]
    assert render_bytes(cornell, tmp_path, estimator, **options) == \
        cli_render(tmp_path, estimator, *args)


# Every light selection of the table, each with the samplers in turn (a selection added to the
# table is tested here without an edit).
SELECTIONS = [s["name"] for s in mcrt.variants()["light_select"]]
SAMPLERS = [s["name"] for s in mcrt.variants()["samplers"]]
SELECTION_SAMPLERS = [(s, SAMPLERS[(k + 2) % len(SAMPLERS)]) for k, s in enumerate(SELECTIONS)]


@pytest.mark.parametrize("light_select,sampler", SELECTION_SAMPLERS)
def test_light_selections_and_samplers_give_the_cli_bytes(cornell, tmp_path, light_select,
                                                          sampler):
    # One scene rendered under several selections in turn: each keeps its own device data.
    name = light_select + "-" + sampler
    api = render_bytes(cornell, tmp_path, name, estimator="mis", light_select=light_select,
                       sampler=sampler, sky=(0.2, 0.3, 0.4), replicates=4, **SMALL)
    cli = cli_render(tmp_path, name, "--width", "24", "--height", "24", "--spp", "16",
                     "--estimator", "mis", "--light-select", light_select, "--sampler", sampler,
                     "--sky", "0.2,0.3,0.4", "--replicates", "4")
    assert api == cli


def test_camera_options_give_the_cli_bytes(cornell, tmp_path):
    api = render_bytes(cornell, tmp_path, "look", look_from=(0, 1, 3.5), look_at=(0, 1, 0),
                       fov=30, width=32, height=20, spp=16, estimator="bsdf")
    cli = cli_render(tmp_path, "look", "--look-from", "0,1,3.5", "--look-at", "0,1,0", "--fov",
                     "30", "--width", "32", "--height", "20", "--spp", "16", "--estimator",
                     "bsdf")
    assert api == cli
    # The scene's own camera again after the look-at one.
    assert render_bytes(cornell, tmp_path, "default", **SMALL) == \
        cli_render(tmp_path, "default", "--width", "24", "--height", "24", "--spp", "16")


def test_user_estimator_from_text_gives_the_cli_bytes(ctx, cornell, tmp_path):
    path = ROOT / "examples" / "estimators" / "light_area.cl"
    est = ctx.estimator(path.read_text(), name=str(path))
    api = cornell.render(estimator=est, **SMALL)
    api.save(str(tmp_path / "user-api.exr"))
    cli = cli_render(tmp_path, "user", "--width", "24", "--height", "24", "--spp", "16",
                     "--estimator-file", str(path))
    assert (tmp_path / "user-api.exr").read_bytes() == cli
    # The built-in estimator it rewrites gives the same image (docs/ESTIMATORS.md).
    builtin = cornell.render(estimator="light-area", **SMALL)
    assert np.array_equal(api.image, builtin.image)


def write_hdr(path, width, height, texel):
    """A Radiance .hdr of flat RGBE texels, texel(i, j) -> 4 bytes."""
    with open(path, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (height, width))
        for j in range(height):
            for i in range(width):
                f.write(bytes(texel(i, j)))
    return str(path)


def test_environment_map_gives_the_cli_bytes(ctx, tmp_path):
    # A map with a bright band and column, under which a plane shows the map's light; env,
    # env_scale and env_rotate go the command line's way, and --sky with --env is its error.
    env = write_hdr(tmp_path / "band.hdr", 16, 8,
                    lambda i, j: (128, 128, 128, 132 if j == 2 or i == 3 else 129))
    plane = str(ROOT / "scenes" / "glossy" / "white-metal-plane.gltf")
    scene = ctx.load(plane)
    for estimator in ("mis", "bsdf", "ambient-cosine"):
        api = scene.render(env=env, env_scale=2.0, env_rotate=30, estimator=estimator, seed=1,
                           **SMALL)
        path = tmp_path / (estimator + "-api.exr")
        api.save(str(path))
        out = tmp_path / (estimator + ".exr")
        run = subprocess.run([MCRT_EXE, "render", plane, "--out", str(out), "--quiet",
                              "--env", env, "--env-scale", "2", "--env-rotate", "30",
                              "--estimator", estimator, "--seed", "1", "--width", "24",
                              "--height", "24", "--spp", "16"], capture_output=True, text=True)
        assert run.returncode == 0, run.stderr
        assert path.read_bytes() == out.read_bytes(), estimator
        assert api.image.mean() > 0
    with pytest.raises(mcrt.SettingError) as e:
        scene.render(env=env, sky=1)
    assert str(e.value) == cli_error(plane, "--out", "/tmp/unused.exr", "--env", env, "--sky",
                                     "1")
    missing = str(tmp_path / "missing.hdr")
    with pytest.raises(ValueError) as e:
        scene.render(env=missing, **SMALL)
    assert str(e.value) == cli_error(plane, "--out", "/tmp/unused.exr", "--env", missing)


def test_environment_map_is_read_once_while_its_file_is_unchanged(tmp_path):
    # The context keeps a map it read; a file rewritten in place (same size, a new mtime) is
    # read again. Each render gives the command line's bytes for the file as it is then.
    env = tmp_path / "kept.hdr"
    plane = str(ROOT / "scenes" / "glossy" / "white-metal-plane.gltf")

    def cli(name):
        out = tmp_path / (name + ".exr")
        run = subprocess.run([MCRT_EXE, "render", plane, "--out", str(out), "--quiet",
                              "--env", str(env), "--estimator", "mis", "--width", "24",
                              "--height", "24", "--spp", "16"], capture_output=True, text=True)
        assert run.returncode == 0, run.stderr
        return out.read_bytes()

    with mcrt.Context() as ctx:
        scene = ctx.load(plane)
        reads = lambda: ctx._context._environment_reads
        uploads = lambda: ctx._context._environment_uploads
        write_hdr(env, 16, 8, lambda i, j: (128, 128, 128, 132 if j == 2 else 129))
        first = render_bytes(scene, tmp_path, "first", env=str(env), estimator="mis", **SMALL)
        assert reads() == 1 and uploads() == len(ctx.devices)
        again = render_bytes(scene, tmp_path, "again", env=str(env), estimator="mis", **SMALL)
        assert reads() == 1 and uploads() == len(ctx.devices)  # the devices keep the map
        assert first == again == cli("first")
        stat = env.stat()
        write_hdr(env, 16, 8, lambda i, j: (128, 128, 128, 132 if i == 3 else 129))
        os.utime(env, ns=(stat.st_atime_ns, stat.st_mtime_ns + 1000000000))
        assert env.stat().st_size == stat.st_size
        changed = render_bytes(scene, tmp_path, "changed", env=str(env), estimator="mis", **SMALL)
        assert reads() == 2 and uploads() == 2 * len(ctx.devices)
        assert changed == cli("changed") != first
        # Another scale is another map (the texels are scaled as they are read).
        scene.render(env=str(env), env_scale=2.0, estimator="mis", **SMALL)
        assert reads() == 3


def test_image_is_a_view_on_the_result(cornell):
    r = cornell.render(**SMALL)
    image, again = r.image, r.image
    assert image.dtype == np.float32 and image.shape == (24, 24, 3)
    assert not image.flags.owndata and image.base is not None
    assert np.shares_memory(image, again)  # both views on the result's one buffer: no copy
    image[5, 7, 1] = 123.5
    assert again[5, 7, 1] == 123.5
    assert r.variance.shape == (24, 24, 3) and not r.variance.flags.owndata
    del r  # the views keep the result alive
    assert np.isfinite(image).all()


def test_result_fields_and_stats(cornell):
    r = cornell.render(estimator="mis", sampler="sobol", max_depth=2, **SMALL)
    assert r.spp == 16 and r.stopped_by == "" and r.replicates == 2
    s = r.stats
    for key in ("spp", "estimator", "light_select", "seconds_render", "rays", "triangles",
                "image_mean", "devices", "bvh"):
        assert key in s
    assert s["estimator"] == "mis" and s["max_depth"] == 2
    assert np.allclose(s["image_mean"], r.image.reshape(-1, 3).mean(axis=0), rtol=1e-5)
    info = cornell.info
    assert info["triangles"] == s["triangles"] and info["emitters"] > 0


def test_replicate_images_are_the_replicates_means(cornell):
    r = cornell.render(sampler="sobol", replicates=4, **SMALL)
    reps = r.replicate_images
    assert reps.shape == (4, 24, 24, 3) and not reps.flags.owndata
    assert np.shares_memory(reps, r.replicate_images)
    # The image is their mean, the variance their spread over K (K - 1) (render/accumulator.h),
    # each rounded once to float from double.
    mean = reps.astype(np.float64).mean(axis=0)
    assert np.allclose(r.image, mean, rtol=1e-5, atol=1e-7)
    spread = ((reps - mean) ** 2).sum(axis=0) / (4 * 3)
    assert np.allclose(r.variance, spread, rtol=1e-3, atol=1e-9)
    assert cornell.render(replicates=1, **SMALL).replicate_images is None


def test_save_writes_png(cornell, tmp_path):
    r = cornell.render(**SMALL)
    r.save(str(tmp_path / "a.exr"), png=str(tmp_path / "a.png"))
    assert (tmp_path / "a.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_one_shot_render():
    r = mcrt.render(CORNELL, **SMALL)
    assert r.image.shape == (24, 24, 3) and r.image.mean() > 0


# Errors: each class, each with the command line's line.

def test_setting_errors_carry_the_cli_line(cornell):
    cases = [
        (dict(spp=0), ["--spp", "0"]),
        (dict(width=-3), ["--width", "-3"]),
        (dict(height=10 ** 9), ["--height", "1000000000"]),
        (dict(estimator="nosuch"), ["--estimator", "nosuch"]),
        (dict(fov=float("nan"), look_from=(0, 1, 3), look_at=(0, 1, 0)),
         ["--fov", "nan", "--look-from", "0,1,3", "--look-at", "0,1,0"]),
        (dict(sky=(float("inf"), 0, 0)), ["--sky", "inf,0,0"]),
        (dict(estimator="ambient-cosine", max_depth=3),
         ["--estimator", "ambient-cosine", "--max-depth", "3"]),
        (dict(replicates=3), ["--replicates", "3"]),
        (dict(camera=7), ["--camera", "7"]),
        (dict(look_from=(0, 1, 0), look_at=(0, 1, 0)),
         ["--look-from", "0,1,0", "--look-at", "0,1,0"]),
    ]
    for options, args in cases:
        with pytest.raises(mcrt.SettingError) as e:
            cornell.render(**options)
        assert isinstance(e.value, ValueError)
        assert str(e.value) == cli_error(CORNELL, "--out", "/tmp/unused.exr", *args), options


def test_wrong_types_are_type_errors(cornell):
    for options in (dict(width="64"), dict(spp=16.0), dict(spp=True), dict(sky="1,1,1"),
                    dict(look_from=(0, 1)), dict(estimator=3), dict(nosuch=1)):
        with pytest.raises(TypeError):
            cornell.render(**options)
    with pytest.raises(TypeError):
        cornell.render(progress=3)


def test_scene_errors_carry_the_cli_line(ctx, tmp_path):
    with pytest.raises(mcrt.SceneError) as e:
        ctx.load(str(tmp_path / "nosuch.gltf"))
    assert isinstance(e.value, ValueError)
    assert str(e.value) == cli_error(str(tmp_path / "nosuch.gltf"), "--out", "/tmp/unused.exr")
    bad = ROOT / "tests" / "data" / "index_out_of_range.gltf"
    with pytest.raises(mcrt.SceneError) as e:
        ctx.load(str(bad))
    assert str(e.value) == cli_error(str(bad), "--out", "/tmp/unused.exr")
    with pytest.raises(mcrt.SettingError):
        ctx.load(CORNELL, materials="plastic")


def test_estimator_errors(ctx, cornell, tmp_path):
    with pytest.raises(mcrt.EstimatorError) as e:
        ctx.estimator("this is not OpenCL", name="garbage.cl")
    assert str(e.value).startswith("garbage.cl")
    with pytest.raises(mcrt.EstimatorError) as e:
        ctx.estimator("float3 other(void) { return (float3)(0.0f); }", name="none.cl")
    assert "defines no function float3 estimate" in str(e.value)
    # A build error names the user's file and line, as the command line does.
    source = ("float3 estimate(const SceneView* scene, const SurfacePoint* sp,\n"
              "                const SampleStream* stream, uint* rays) {\n"
              "    return undefined_name;\n"
              "}\n")
    path = tmp_path / "broken.cl"
    path.write_text(source)
    est = ctx.estimator(source, name=str(path))
    with pytest.raises(mcrt.EstimatorError) as e:
        cornell.render(estimator=est, **SMALL)
    assert e.value.line == 3
    assert str(e.value) == cli_error(CORNELL, "--out", "/tmp/unused.exr", "--estimator-file",
                                     str(path)).split("\n")[0]
    # The scene still renders.
    assert cornell.render(**SMALL).spp == 16


def test_device_errors(tmp_path):
    with pytest.raises(mcrt.SettingError) as e:
        mcrt.Context(device="nosuch")
    assert str(e.value) == cli_error(CORNELL, "--out", "/tmp/unused.exr", "--device", "nosuch")
    c = mcrt.Context()
    scene = c.load(CORNELL)
    c.close()
    with pytest.raises(mcrt.DeviceError) as e:
        scene.render(**SMALL)
    assert isinstance(e.value, RuntimeError) and "closed" in str(e.value)
    with pytest.raises(mcrt.DeviceError):
        c.load(CORNELL)


def test_a_failing_device_is_a_device_error(cornell, monkeypatch):
    # The test hook fails device 0's first launch (common/test_hooks.h): no device is left.
    monkeypatch.setenv("MCRT_FAULT_INJECT", "0:1")
    with pytest.raises(mcrt.DeviceError) as e:
        cornell.render(**SMALL)
    assert str(e.value) == cli_error(CORNELL, "--out", "/tmp/unused.exr", "--width", "24",
                                     "--height", "24", env={"MCRT_FAULT_INJECT": "0:1"})
    monkeypatch.delenv("MCRT_FAULT_INJECT")
    assert cornell.render(**SMALL).spp == 16


# Threads, interruption, memory.

def test_render_in_a_thread_while_python_runs(cornell):
    cornell.render(width=64, height=64, spp=16)  # the variant built before the clock starts
    done = {}

    def work():
        done["result"] = cornell.render(width=128, height=128, spp=256)

    t = threading.Thread(target=work)
    ticks = 0
    start = time.monotonic()
    t.start()
    while t.is_alive():
        ticks += 1  # Python keeps running while the render holds no GIL
        time.sleep(0.001)
    t.join()
    assert done["result"].spp == 256
    assert ticks > 20, "main thread ran %d times in %.2f s" % (ticks, time.monotonic() - start)


def test_progress_is_called_from_the_calling_thread(cornell):
    calls = []
    me = threading.get_ident()
    cornell.render(progress=lambda done, total: calls.append((done, total, threading.get_ident())),
                   width=64, height=64, spp=64)
    assert calls and calls[-1][:2] == (64, 64)
    assert all(c[2] == me for c in calls)
    assert all(a[0] <= b[0] for a, b in zip(calls, calls[1:]))


def test_progress_exception_stops_the_render(cornell):
    def fail(done, total):
        raise ZeroDivisionError("from progress")

    with pytest.raises(ZeroDivisionError):
        cornell.render(progress=fail, width=64, height=64, spp=64)
    assert cornell.render(**SMALL).spp == 16


def test_ctrl_c_interrupts_and_the_context_stays_usable(cornell):
    cornell.render(width=200, height=200, spp=16)  # kernels built before the clock starts
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        cornell.render(width=200, height=200, spp=1 << 16)
    waited = time.monotonic() - start - 0.5
    timer.join()
    assert waited < 1.0, "KeyboardInterrupt %.2f s after the signal" % waited
    assert cornell.render(**SMALL).spp == 16


def rss_bytes():
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) * 1024
    raise RuntimeError("no VmRSS")


def test_repeated_renders_do_not_grow_memory(cornell):
    for _ in range(20):
        cornell.render(width=16, height=16, spp=16).image
    before = rss_bytes()
    for i in range(200):
        r = cornell.render(width=16, height=16, spp=16, seed=i)
        assert r.image.shape == (16, 16, 3)
    grown = rss_bytes() - before
    assert grown < 50 * 2 ** 20, "RSS grew by %.1f MB over 200 renders" % (grown / 2 ** 20)


def test_repeated_errors_do_not_grow_memory(ctx, cornell, tmp_path):
    def errors():
        for call in (lambda: cornell.render(spp=0),
                     lambda: cornell.render(fov=float("nan"), look_from=(0, 1, 3),
                                            look_at=(0, 1, 0)),
                     lambda: ctx.load(str(tmp_path / "nosuch.gltf")),
                     lambda: ctx.estimator("not OpenCL", name="bad.cl")):
            with pytest.raises(ValueError):
                call()

    for _ in range(20):
        errors()
    before = rss_bytes()
    for _ in range(200):
        errors()
    grown = rss_bytes() - before
    assert grown < 5 * 2 ** 20, "RSS grew by %.1f MB over 800 errors" % (grown / 2 ** 20)


def test_one_shot_renders_share_the_process_programs():
    # Each mcrt.render is a new Context: on the process's device contexts, so that its programs
    # are those built before, not built (and kept) again.
    mcrt.render(CORNELL, width=16, height=16)
    before = rss_bytes()
    for _ in range(30):
        mcrt.render(CORNELL, width=16, height=16)
    grown = rss_bytes() - before
    assert grown < 20 * 2 ** 20, "RSS grew by %.1f MB over 30 one-shot renders" % (grown / 2 ** 20)

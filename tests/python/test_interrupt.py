"""Ctrl-C during the parts of a call that no signal used to reach: a variant's first kernel
build (PoCL's and mcrt's kernel caches cold) and a scene's load. Each runs in a child Python
process sent SIGINT; the child must raise KeyboardInterrupt soon after it and then render the
command line's bytes (docs/PYTHON.md, "Threads and Ctrl-C")."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
CORNELL = str(ROOT / "scenes" / "cornell" / "CornellBox-Original.gltf")
MCRT_EXE = os.environ.get("MCRT_EXE", str(ROOT / "build" / "mcrt"))
# A bound far above the 50 ms between the module's checks for signals: a busy machine's slack,
# not a speed requirement.
GENEROUS_SECONDS = 5.0

# An estimator whose cold build with PoCL takes many seconds (docs/PYTHON.md, "Threads and
# Ctrl-C"): Ctrl-C that waited for the build would come after GENEROUS_SECONDS.
SLOW_ESTIMATOR = (
    "float3 estimate(const SceneView* scene, const SurfacePoint* sp,\n"
    "                const SampleStream* stream, uint* rays) {\n"
    "    float x = sp->p.x;\n" +
    "".join("    x = fma(x, %.6ff, sin(x * %.6ff));\n" % (1 + i * 1e-6, 0.5 + i * 1e-6)
            for i in range(600)) +
    "    return (float3)(x * 0.0f);\n}\n")

CHILD = r"""
import sys, time
import mcrt
out, scene_path, mode = sys.argv[1:4]
ctx = mcrt.Context()
cornell = ctx.load(%(cornell)r)
slow = ctx.estimator(%(slow)r, name="slow.cl")
print("calling", flush=True)
try:
    if mode == "build":
        cornell.render(estimator=slow, width=16, height=16, spp=4)
    else:
        ctx.load(scene_path)
    print("finished", flush=True)
except KeyboardInterrupt:
    print("interrupted %%r" %% time.monotonic(), flush=True)
    # The work goes on in the background: the signal came while it ran, not after it.
    print("background %%d" %% mcrt._mcrt._background_running(), flush=True)
r = cornell.render(width=24, height=24, spp=16)
r.save(out)
print("rendered %%d" %% r.spp, flush=True)
""" % {"cornell": CORNELL, "slow": SLOW_ESTIMATOR}


def interrupt_child(tmp_path, mode, scene_path="", delay=0.3):
    """Runs CHILD with cold kernel caches, sends SIGINT `delay` s after it starts the call;
    returns its output lines and the seconds from the signal to its KeyboardInterrupt."""
    env = dict(os.environ, POCL_CACHE_DIR=str(tmp_path / "pocl"),
               MCRT_CACHE_DIR=str(tmp_path / "mcrt"), PYTHONUNBUFFERED="1")
    out = tmp_path / "after.exr"
    child = subprocess.Popen([sys.executable, "-c", CHILD, str(out), scene_path, mode],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        assert child.stdout.readline().strip() == "calling", child.stderr.read()
        time.sleep(delay)
        sent = time.monotonic()
        child.send_signal(signal.SIGINT)
        stdout, stderr = child.communicate(timeout=300)
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
    assert child.returncode == 0, stderr
    lines = stdout.split("\n")
    interrupted = [l for l in lines if l.startswith("interrupted ")]
    assert interrupted, "no KeyboardInterrupt: %r %r" % (stdout, stderr)
    print(stdout, "waited %.3f s" % (float(interrupted[0].split()[1]) - sent))
    return lines, float(interrupted[0].split()[1]) - sent, out


def cli_bytes(tmp_path):
    out = tmp_path / "cli.exr"
    run = subprocess.run([MCRT_EXE, "render", CORNELL, "--out", str(out), "--quiet",
                          "--width", "24", "--height", "24", "--spp", "16"],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    return out.read_bytes()


def test_ctrl_c_during_the_first_kernel_build(tmp_path):
    # The signal comes 0.3 s into the build of SLOW_ESTIMATOR's variant. The render after it
    # waits for that build to end in the background, then builds its own variant.
    lines, waited, out = interrupt_child(tmp_path, "build")
    assert waited < GENEROUS_SECONDS, "KeyboardInterrupt %.2f s after the signal" % waited
    assert "background 1" in lines
    assert "rendered 16" in lines
    assert out.read_bytes() == cli_bytes(tmp_path)


def write_grid_scene(path, n):
    """An n×n grid of quads (2 n² triangles), emissive: a scene that takes seconds to load."""
    xs = np.linspace(-1, 1, n + 1, dtype=np.float32)
    gx, gz = np.meshgrid(xs, xs)
    gy = np.random.default_rng(1).random(gx.shape, dtype=np.float32) * 0.05
    pos = np.stack([gx, gy, gz], -1).reshape(-1, 3).astype(np.float32)
    i = np.arange(n)[:, None] * (n + 1) + np.arange(n)[None, :]
    idx = np.stack([i, i + n + 1, i + 1, i + 1, i + n + 1, i + n + 2], -1)
    idx = idx.reshape(-1).astype(np.uint32)
    blob = pos.tobytes() + idx.tobytes()
    (path.parent / (path.name + ".bin")).write_bytes(blob)
    path.write_text(json.dumps({
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}], "materials": [{"emissiveFactor": [1, 1, 1]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1,
                                    "material": 0}]}],
        "buffers": [{"uri": path.name + ".bin", "byteLength": len(blob)}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": pos.nbytes},
                        {"buffer": 0, "byteOffset": pos.nbytes, "byteLength": idx.nbytes}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(pos),
                       "type": "VEC3", "min": pos.min(0).tolist(), "max": pos.max(0).tolist()},
                      {"bufferView": 1, "componentType": 5125, "count": len(idx),
                       "type": "SCALAR"}]}))


def test_ctrl_c_during_a_load(tmp_path):
    # About a million triangles, seconds to load; the signal comes 0.3 s in. The child's
    # Cornell box was loaded before, its variant is built at the render after the interrupt.
    scene = tmp_path / "grid.gltf"
    write_grid_scene(scene, 700)
    lines, waited, out = interrupt_child(tmp_path, "load", str(scene))
    assert waited < GENEROUS_SECONDS, "KeyboardInterrupt %.2f s after the signal" % waited
    assert "background 1" in lines
    assert "rendered 16" in lines
    assert out.read_bytes() == cli_bytes(tmp_path)


# OpenCL's start-up in mcrt.Context() and mcrt.devices(), made to last (the test hook
# MCRT_TEST_PAUSE=start-up, host/common/test_hooks.h) until the file MCRT_TEST_PAUSE_UNTIL
# exists or PAUSE_SECONDS pass. A start-up that held the GIL would keep the other Python thread
# (and the signal handler) from running for all of PAUSE_SECONDS, past the child's timeout.
PAUSE_SECONDS = 300
CHILD_TIMEOUT = 120

STARTUP_CHILD = r"""
import os, sys, threading, time
import mcrt
call, flag, stderr_file = sys.argv[1:4]
def other():
    # Runs once the start-up is in its pause (its line is in this process's stderr file).
    while "paused at start-up" not in open(stderr_file).read():
        time.sleep(0.01)
    sys.stdout.write("thread ran\n")
    sys.stdout.flush()
    open(flag, "w").close()  # ends the start-up's pause
if stderr_file:
    threading.Thread(target=other).start()
print("calling", flush=True)
try:
    mcrt.Context() if call == "Context" else mcrt.devices()
    print("returned", flush=True)
except KeyboardInterrupt:
    print("interrupted", flush=True)
    os._exit(0)  # the abandoned start-up sleeps on in the background
"""


def startup_child(tmp_path, call, flag, stderr_file=None):
    """The child, its stderr in `stderr_file` (its other thread waits for the pause's line there)
    or, without one, a pipe."""
    env = dict(os.environ, MCRT_TEST_PAUSE="start-up", MCRT_TEST_PAUSE_SECONDS=str(PAUSE_SECONDS),
               MCRT_TEST_PAUSE_UNTIL=str(flag), PYTHONUNBUFFERED="1")
    return subprocess.Popen(
        [sys.executable, "-c", STARTUP_CHILD, call, str(flag), str(stderr_file or "")],
        stdout=subprocess.PIPE, text=True, env=env,
        stderr=open(stderr_file, "w") if stderr_file else subprocess.PIPE)


@pytest.mark.parametrize("call", ["Context", "devices"])
def test_other_threads_run_during_opencl_start_up(tmp_path, call):
    # The other thread, run during the pause, ends it: the call returns only once it has run.
    stderr_file = tmp_path / "stderr"
    child = startup_child(tmp_path, call, tmp_path / "flag", stderr_file)
    try:
        stdout, _ = child.communicate(timeout=CHILD_TIMEOUT)
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
    assert child.returncode == 0, stderr_file.read_text()
    assert stdout.split("\n")[:3] == ["calling", "thread ran", "returned"], stdout


@pytest.mark.parametrize("call", ["Context", "devices"])
def test_ctrl_c_during_opencl_start_up(tmp_path, call):
    # The pause file never appears: only Ctrl-C ends the call before PAUSE_SECONDS.
    child = startup_child(tmp_path, call, tmp_path / "never" / "flag")
    try:
        while "paused at start-up" not in child.stderr.readline():
            assert child.poll() is None, child.stderr.read()
        child.send_signal(signal.SIGINT)
        stdout, stderr = child.communicate(timeout=CHILD_TIMEOUT)
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
    assert child.returncode == 0, stderr
    assert "interrupted" in stdout.split(), stdout

"""scripts/tools/mcrt_run.py through the Python module against a command per render: the same
files from the same options, and the command's error as one line (docs/PYTHON.md)."""

import json
import os
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts" / "tools"))
import mcrt_run  # noqa: E402

CORNELL = str(ROOT / "scenes" / "cornell" / "CornellBox-Original.gltf")
MCRT_EXE = os.environ.get("MCRT_EXE", str(ROOT / "build" / "mcrt"))


@pytest.fixture(scope="module")
def via_module():
    where = mcrt_run.use_module(MCRT_EXE)
    assert where is not None, "the module was not chosen for %s" % MCRT_EXE
    yield
    mcrt_run._MODULE.update(module=None, binary=None, contexts={}, scenes={})


# Options as the experiment scripts give them: numbers as ints, the scene's materials, a PNG.
OPTIONS = [
    ["--estimator", "mis", "--light-select", "tree", "--sampler", "sobol", "--seed", 3,
     "--width", 24, "--height", 16, "--spp", 16, "--materials", "lambert"],
    ["--estimator", "bsdf", "--max-depth", 3, "--rr-depth", 2, "--spp", 8, "--width", 16,
     "--height", 16, "--png", "PNG", "--exposure", "1.5", "--replicates", 2],
    ["--estimator-file", str(ROOT / "examples" / "estimators" / "light_area.cl"),
     "--width=16", "--height=16", "--spp=16", "--sky=0.5,0.25,1"],
]


@pytest.mark.parametrize("options", OPTIONS, ids=["mis-lambert", "bsdf-png", "estimator-file"])
def test_module_renders_the_commands_files(via_module, tmp_path, options):
    files = {}
    for way, env in (("module", None), ("command", {})):  # an env: always a command
        stem = tmp_path / way
        opts = [str(stem) + ".png" if o == "PNG" else o for o in options]
        r = mcrt_run.render(CORNELL, stem, opts, mcrt=MCRT_EXE, env=env)
        files[way] = (Path(str(stem) + ".exr").read_bytes(), r,
                      json.loads(Path(str(stem) + ".json").read_text()))
        if "PNG" in options:
            files[way] += (Path(str(stem) + ".png").read_bytes(),)
    module, command = files["module"], files["command"]
    assert module[0] == command[0]
    assert (module[1].rgb == command[1].rgb).all()
    assert set(module[2]) == set(command[2])
    assert module[2]["spp"] == command[2]["spp"]
    if "PNG" in options:
        assert module[3] == command[3]


def test_module_loads_each_scene_once(via_module, tmp_path):
    loaded = []
    for seed in (1, 2):
        mcrt_run.render(CORNELL, tmp_path / ("s%d" % seed), ["--spp", 4, "--seed", seed,
                                                             "--width", 8, "--height", 8])
        loaded.append(dict(mcrt_run._MODULE["scenes"]))
    assert loaded[0] == loaded[1]  # the same Scene objects: no second load


def test_module_errors_are_the_commands_line(via_module, tmp_path):
    with pytest.raises(mcrt_run.ScriptError) as module_error:
        mcrt_run.render(CORNELL, tmp_path / "m", ["--spp", 0], mcrt=MCRT_EXE)
    with pytest.raises(mcrt_run.ScriptError) as command_error:
        mcrt_run.render(CORNELL, tmp_path / "c", ["--spp", 0], mcrt=MCRT_EXE, env={})
    assert str(module_error.value).split(": ", 1)[1] in str(command_error.value)
    with pytest.raises(mcrt_run.ScriptError, match="cannot open"):
        mcrt_run.render(str(tmp_path / "none.gltf"), tmp_path / "n", ["--spp", 1])

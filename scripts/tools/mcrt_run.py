"""What every script needs of mcrt, once: the interpreter check, the default binary, running
`mcrt render` and reading its EXR and stats, and the table of variants (`mcrt variants --json`).

    import mcrt_run
    mcrt_run.require("numpy")            # first, before importing numpy (see require)
    import numpy as np
    table = mcrt_run.variants()          # estimators, light selections, samplers, heuristics
    r = mcrt_run.render(scene, stem, ["--estimator", "mis", "--spp", "64"])
    r.rgb, r.variance, r.stats, r.wall_seconds

Also: estimator_arguments / estimator_label / uses_light_select / check_estimators for built-in
names and users' FILE.cl alike; read_image_file (an EXR as (3, H, W) arrays); comma_list,
image_size, add_mcrt_option, check_choices for command lines; pyplot and save_png for charts.
Scripts that only read the stats JSON (render(..., read_image=False)) need no numpy.

A sweep renders through the Python module instead of a command per point once it calls
use_module(args.mcrt, args.cli) (add_cli_option adds --cli): each scene is then loaded once and
each variant built once per process, and render() writes the same STEM.exr (the same bytes)
and STEM.json (the same keys; the timings are the call's) as the command would.

Errors are raised as ScriptError (one line, naming the command); `script_main` turns them into
one `NAME: error: ...` line and exit status 2, so no script prints a traceback for them.
"""

import argparse
import functools
import importlib.util
import json
import os
import shlex
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]  # scripts/tools/ → the repository
SYSTEM_PYTHON = "/usr/bin/python3"  # Debian's, with python3-numpy and python3-matplotlib


class ScriptError(Exception):
    """A failure worth one line: a command that failed, a missing file or binary."""


def require(*modules):
    """Makes sure this interpreter can import `modules` (e.g. numpy). When it cannot (a pyenv
    or a venv first on PATH) and Debian's /usr/bin/python3 can, the script is run again under
    that one; otherwise the process ends with one line saying which interpreter to use. The one
    place this module ends the process: nothing else can run without those modules."""
    missing = [m for m in modules if importlib.util.find_spec(m) is None]
    if not missing:
        return
    script = os.path.abspath(sys.argv[0])
    here = os.path.realpath(sys.executable or "")
    if (os.path.exists(SYSTEM_PYTHON) and here != os.path.realpath(SYSTEM_PYTHON)
            and not os.environ.get("MCRT_SCRIPT_REEXEC")):
        os.environ["MCRT_SCRIPT_REEXEC"] = "1"
        os.execv(SYSTEM_PYTHON, [SYSTEM_PYTHON, script] + sys.argv[1:])
    print("%s: error: this Python (%s) lacks %s; run it with %s and Debian's "
          "python3-numpy / python3-matplotlib (scripts/setup installs them)"
          % (os.path.basename(script), sys.executable, ", ".join(missing), SYSTEM_PYTHON),
          file=sys.stderr)
    raise SystemExit(2)  # as script_main's one line


def script_main(main):
    """Runs main() and returns its exit status; a ScriptError becomes one line and status 2."""
    name = os.path.basename(sys.argv[0])
    try:
        return main() or 0
    except ScriptError as e:
        print("%s: error: %s" % (name, e), file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("%s: interrupted" % name, file=sys.stderr)
        return 130


def default_mcrt():
    """$MCRT, else build/mcrt of this checkout."""
    return os.environ.get("MCRT") or str(ROOT / "build" / "mcrt")


def mcrt_binary(path=None):
    """The mcrt executable to run: `path`, or default_mcrt(); ScriptError when it is missing."""
    path = path or default_mcrt()
    if not (os.path.isfile(path) and os.access(path, os.X_OK)):
        raise ScriptError("%s is not an executable: build mcrt first (scripts/setup)" % path)
    return path


def run(command, env=None):
    """Runs a command, returning its CompletedProcess (text); ScriptError when it fails."""
    full_env = dict(os.environ, **env) if env else None
    try:
        done = subprocess.run([str(c) for c in command], capture_output=True, text=True,
                              env=full_env)
    except OSError as e:
        raise ScriptError("%s: %s" % (shlex.join(map(str, command)), e))
    if done.returncode != 0:
        # mcrt's own "mcrt: error:" line, not what a kernel compiler printed before it
        lines = [l for l in done.stderr.strip().splitlines() if l.strip()]
        ours = [l for l in lines if l.startswith("mcrt: error:")]
        raise ScriptError("%s exited %d: %s" % (shlex.join(map(str, command)), done.returncode,
                                                (ours or lines or ["(no message)"])[0]))
    return done


@functools.lru_cache(maxsize=None)
def variants(mcrt=None):
    """The table of variants of `mcrt variants --json`: {"estimators": [{name, function, uses,
    description}], "light_select": [...], "samplers": [...], "mis_heuristics": [...]}."""
    return json.loads(run([mcrt_binary(mcrt), "variants", "--json"]).stdout)


def names(table, uses=None, mcrt=None):
    """Names of one table of variants ("estimators", "light_select", "samplers",
    "mis_heuristics"); for estimators, only those whose uses include `uses` when given."""
    rows = variants(mcrt)[table]
    return [r["name"] for r in rows if uses is None or uses in r.get("uses", [])]


def is_estimator_file(estimator):
    """True when `estimator` names a user's estimator file rather than a built-in."""
    return estimator.endswith(".cl")


def estimator_arguments(estimator):
    """The render options that choose `estimator`: a built-in name or a user's .cl file."""
    if is_estimator_file(estimator):
        if not os.path.isfile(estimator):
            raise ScriptError("estimator file %s does not exist" % estimator)
        return ["--estimator-file", estimator]
    return ["--estimator", estimator]


def estimator_uses(estimator, mcrt=None):
    """What an estimator uses ("lights", "sky", "mis-heuristic", "bsdf-sampling")."""
    table = variants(mcrt)
    if is_estimator_file(estimator):
        return table["user_estimator"]["uses"]
    for row in table["estimators"]:
        if row["name"] == estimator:
            return row["uses"]
    raise ScriptError("unknown estimator %s (one of %s, or a file FILE.cl)"
                      % (estimator, ", ".join(r["name"] for r in table["estimators"])))


def uses_light_select(estimator, mcrt=None):
    """True when --light-select changes what `estimator` computes: its uses include
    "light-selection" (a user's file is assumed to, as the table's user_estimator row says)."""
    return "light-selection" in estimator_uses(estimator, mcrt)


def check_estimators(estimators, mcrt=None):
    """ScriptError unless each is a built-in estimator or an existing .cl file, and their
    labels (estimator_label) are distinct."""
    labels = {}
    for e in estimators:
        estimator_arguments(e)  # a missing file
        estimator_uses(e, mcrt)  # an unknown name
        label = estimator_label(e)
        if label in labels and labels[label] != e:
            raise ScriptError("%s and %s would both be labelled %s: rename one" % (
                labels[label], e, label))
        labels[label] = e


def estimator_label(estimator):
    """A short name for charts: a file's stem, or the built-in name."""
    return Path(estimator).stem if is_estimator_file(estimator) else estimator


class Render:
    """One finished render: rgb and variance as (3, H, W) float64, its stats JSON, wall time."""

    def __init__(self, rgb, variance, stats, wall_seconds, command):
        self.rgb, self.variance, self.stats = rgb, variance, stats
        self.wall_seconds, self.command = wall_seconds, command


def render(scene, stem, options, mcrt=None, env=None, read_image=True):
    """`mcrt render SCENE --out STEM.exr --stats STEM.json --quiet OPTIONS`; returns a Render
    (rgb and variance None when not `read_image`: then numpy is not needed). After use_module,
    rendered by the Python module when `mcrt` is the executable it was built with and no `env`
    is asked for; `wall_seconds` is then the call's (the render and the files' writing)."""
    stem = str(stem)
    command = [mcrt_binary(mcrt), "render", str(scene), "--out", stem + ".exr",
               "--stats", stem + ".json", "--quiet"] + [str(o) for o in options]
    start = time.monotonic()
    if env is None and _module_for(command[0]) is not None:
        _render_in_module(scene, stem, [str(o) for o in options], command)
    else:
        run(command, env)
    wall = time.monotonic() - start
    stats = json.loads(Path(stem + ".json").read_text())
    if not read_image:
        return Render(None, None, stats, wall, command)
    rgb, variance = read_image_file(stem + ".exr")
    return Render(rgb, variance, stats, wall, command)


# ----- the Python module ---------------------------------------------------------------------

_MODULE = {"module": None, "binary": None, "contexts": {}, "scenes": {}}
# Options of `mcrt render` that the module takes elsewhere than in a render: the scene's
# materials (Context.load), the devices (Context), the PNG (Result.save).
_LOAD_OPTIONS = ("--materials", "--device", "--png", "--exposure")


def add_cli_option(parser):
    """--cli: a command per render even where the Python module could render the sweep."""
    parser.add_argument("--cli", action="store_true",
                        help="render each point with an `mcrt render` command instead of the "
                             "Python module built beside the executable (the same images)")


def use_module(binary=None, cli=False):
    """From now on, render() renders through the Python module `mcrt` when it can be imported
    (from PYTHONPATH, else from python/ beside the executable, as scripts/setup builds it), was
    built with `binary` (default_mcrt()) and not before its library; not with `cli`. Returns where it was imported
    from, or None when renders stay commands."""
    if cli:
        return None
    binary = os.path.realpath(mcrt_binary(binary))
    module = None
    try:
        import mcrt as module
    except ImportError:
        beside = Path(binary).parent / "python"
        if (beside / "mcrt" / "__init__.py").is_file():
            sys.path.insert(0, str(beside))
            try:
                import mcrt as module
            except ImportError:
                sys.path.remove(str(beside))
    if module is None:
        return None
    # build/python/mcrt/__init__.py belongs to build/mcrt
    built_with = Path(module.__file__).resolve().parents[2] / "mcrt"
    if os.path.realpath(built_with) != binary:
        print("%s: the module %s is not %s's: rendering with commands"
              % (os.path.basename(sys.argv[0]), module.__file__, binary), file=sys.stderr)
        return None
    # A module linked before the libraries it shares with the executable (only `mcrt` rebuilt
    # after a change) would render with the old host code or the old kernels.
    extension = Path(module._mcrt.__file__)
    for name in ("libmcrt_core.a", "libmcrt_kernels.a"):
        shared = Path(binary).parent / name
        if shared.is_file() and extension.stat().st_mtime < shared.stat().st_mtime:
            print("%s: the module %s is older than %s (cmake --build %s --target mcrt_python): "
                  "rendering with commands" % (os.path.basename(sys.argv[0]), extension, shared,
                                               Path(binary).parent), file=sys.stderr)
            return None
    _MODULE.update(module=module, binary=binary)
    print("%s: rendering through the Python module in %s (--cli: a command per render)"
          % (os.path.basename(sys.argv[0]), os.path.dirname(os.path.dirname(module.__file__))),
          file=sys.stderr)
    return os.path.dirname(module.__file__)


def _module_for(binary):
    """The module when use_module chose it for this executable; None otherwise."""
    if _MODULE["module"] is None or os.path.realpath(binary) != _MODULE["binary"]:
        return None
    return _MODULE["module"]


def _render_in_module(scene, stem, words, command):
    """What `command` (mcrt render SCENE --out STEM.exr --stats STEM.json --quiet WORDS) does,
    through the module: the scene loaded once per (devices, materials), WORDS read by the
    command's own parser. ScriptError, naming the command, for what the command would refuse."""
    mcrt = _MODULE["module"]
    taken, rest, i = {}, [], 0
    while i < len(words):
        name, equals, value = words[i].partition("=")
        if name in _LOAD_OPTIONS:
            if not equals:
                if i + 1 >= len(words):
                    raise ScriptError("%s: %s needs a value" % (shlex.join(command), name))
                value = words[i + 1]
                i += 1
            taken.setdefault(name, []).append(value)
        else:
            rest.append(words[i])
        i += 1
    devices = tuple(taken.get("--device", []))
    materials = taken.get("--materials", ["gltf"])[-1]
    try:
        context = _MODULE["contexts"].get(devices)
        if context is None:
            context = _MODULE["contexts"][devices] = mcrt.Context(list(devices) or None)
        key = (devices, str(scene), materials)
        loaded = _MODULE["scenes"].get(key)
        if loaded is None:
            loaded = _MODULE["scenes"][key] = context.load(str(scene), materials)
        # The command's words as they are, to the command's parser (Scene.render's keywords
        # become these words too).
        result = loaded._scene._render(rest, None, None)
        png = taken.get("--png", [""])[-1]
        exposure = float(taken.get("--exposure", ["0"])[-1])
        result.save(stem + ".exr", png=png, exposure=exposure)
    except (ValueError, RuntimeError) as e:  # the module's errors: the command's one line
        raise ScriptError("%s: %s" % (shlex.join(command), str(e).split("\n")[0]))
    Path(stem + ".json").write_text(json.dumps(result.stats, indent=2) + "\n")


def read_image_file(path):
    """(rgb, variance) of an EXR as (3, H, W) float64 arrays; variance None when the file has no
    variance.R/G/B layer. ScriptError when it cannot be read."""
    import numpy as np
    from mcrt_exr import read_exr

    try:
        exr = read_exr(path)
    except (OSError, ValueError, KeyError) as e:
        raise ScriptError("cannot read %s: %s" % (path, e))
    if not all(c in exr for c in "RGB"):
        raise ScriptError("%s has no R, G, B channels" % path)
    rgb = np.stack([exr[c] for c in "RGB"]).astype(np.float64)
    variance = None
    if all("variance." + c in exr for c in "RGB"):
        variance = np.stack([exr["variance." + c] for c in "RGB"]).astype(np.float64)
    return rgb, variance


def remove_outputs(stem):
    """Deletes STEM.exr and STEM.json of a render."""
    for suffix in (".exr", ".json"):
        Path(str(stem) + suffix).unlink(missing_ok=True)


# ----- command-line helpers --------------------------------------------------------------------

def comma_list(text):
    """'a,b,,c' → ['a', 'b', 'c']."""
    return [t for t in text.split(",") if t]


def image_size(text):
    """'WxH' → (W, H); an argparse type."""
    import argparse

    try:
        width, height = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError("expected WIDTHxHEIGHT, e.g. 64x64: %r" % text)
    if width <= 0 or height <= 0:
        raise argparse.ArgumentTypeError("expected a positive size: %r" % text)
    return width, height


def output_directory(text):
    """argparse type of an --out DIR: a directory, or a path where one can be made. A file
    there (or above it) is argparse's error ("argument --out: ... is a file, not a directory"),
    one line and status 2, before any work."""
    path = Path(text)
    for above in [path] + list(path.parents):
        if above.exists():
            if not above.is_dir():
                what = "is a file" if above == path else "lies under the file %s" % above
                raise argparse.ArgumentTypeError("%s %s, not a directory" % (text, what))
            if not os.access(above, os.W_OK | os.X_OK):
                raise argparse.ArgumentTypeError("%s: %s is not writable" % (text, above))
            break
    return text


def add_mcrt_option(parser):
    """--mcrt BINARY, default default_mcrt()."""
    parser.add_argument("--mcrt", default=default_mcrt(),
                        help="mcrt executable (default $MCRT, else build/mcrt)")


def check_choices(kind, given, table, mcrt=None):
    """ScriptError unless every name of `given` is one of the names of `table`, e.g.
    check_choices("sampler", ["sobol"], "samplers")."""
    known = names(table, mcrt=mcrt)
    for name in given:
        if name not in known:
            raise ScriptError("unknown %s %s (one of %s)" % (kind, name, ", ".join(known)))


# ----- charts ----------------------------------------------------------------------------------

def pyplot():
    """matplotlib.pyplot on the Agg backend (files only, no display)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def save_png(fig, path):
    """Saves a figure as a small PNG: reduced to a 256-colour palette when Pillow is there."""
    import io
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png")
    try:
        from PIL import Image
        image = Image.open(io.BytesIO(buffer.getvalue())).convert("RGB")
        image.quantize(256, method=Image.Quantize.MEDIANCUT).save(path, optimize=True)
    except (ImportError, AttributeError):
        Path(path).write_bytes(buffer.getvalue())

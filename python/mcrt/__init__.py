"""mcrt: load a scene once, render it many times (docs/PYTHON.md).

    import mcrt
    ctx = mcrt.Context(device="pocl")
    scene = ctx.load("scenes/cornell/CornellBox-Original.gltf")
    r = scene.render(width=64, height=64, spp=16, estimator="mis")
    r.image            # numpy float32 (H, W, 3), a view on the result (no copy)
    r.save("out.exr", png="out.png")

Keyword names are those of `mcrt render` with `_` for `-`; their defaults and their checks are
the command line's own (the arguments are parsed by its parser), and the same request gives
the same bytes.
"""

import atexit as _atexit
import json as _json
import math as _math
import numbers as _numbers

from . import _mcrt
from ._mcrt import DeviceError, EstimatorError, Estimator, Result, SceneError, SettingError

# A render or load interrupted by Ctrl-C ends in the background (a kernel build cannot be cut
# short); the interpreter waits for it before it tears down (docs/PYTHON.md, "Threads and Ctrl-C").
_atexit.register(_mcrt._wait_background)

__all__ = ["Context", "Scene", "Result", "Estimator", "devices", "variants", "render",
           "SettingError", "SceneError", "EstimatorError", "DeviceError"]

# Keyword -> kind of value, for every option of `mcrt render` a render takes. The outputs
# (--out, --png, --stats, --exposure) are Result.save's, --device is the Context's and
# --materials the scene's (Context.load).
_INT, _FLOAT, _STR, _VEC3 = "an int", "a number", "a str", "three numbers"
_OPTIONS = {
    "width": _INT, "height": _INT, "spp": _INT, "seed": _INT, "max_depth": _INT,
    "rr_depth": _INT, "camera": _INT, "batch": _INT, "replicates": _INT,
    "ao_distance": _FLOAT, "fov": _FLOAT, "time_limit": _FLOAT,
    "env_scale": _FLOAT, "env_rotate": _FLOAT,
    "estimator": _STR, "estimator_file": _STR, "light_select": _STR, "sampler": _STR,
    "mis_heuristic": _STR, "env": _STR,
    "sky": _VEC3, "look_from": _VEC3, "look_at": _VEC3, "up": _VEC3,
}


def _number_text(name, value, kind):
    """The command line's text of one number; TypeError for what is no number of that kind."""
    if isinstance(value, bool) or not isinstance(value, _numbers.Real):
        raise TypeError("%s: expected %s, got %s" % (name, kind, type(value).__name__))
    if kind == _INT:
        if not isinstance(value, _numbers.Integral):
            raise TypeError("%s: expected an int, got %s" % (name, type(value).__name__))
        return str(int(value))
    if isinstance(value, _numbers.Integral):
        return str(int(value))  # as written: the command line reads it as the same number
    value = float(value)
    # repr() is the shortest text that reads back as the same double: the parser's value.
    return "nan" if _math.isnan(value) else repr(value)


def _arguments(options):
    """`mcrt render` arguments for keyword options; TypeError for a name or type it has not."""
    args = []
    for name, value in options.items():
        kind = _OPTIONS.get(name)
        if kind is None:
            raise TypeError("render() got an unexpected keyword argument '%s'" % name)
        if value is None:
            continue  # the command line's default
        flag = "--" + name.replace("_", "-")
        if kind == _STR:
            if not isinstance(value, str):
                raise TypeError("%s: expected a str, got %s" % (name, type(value).__name__))
            text = value
        elif kind == _VEC3:
            if name == "sky" and isinstance(value, _numbers.Real) and not isinstance(value, bool):
                text = _number_text(name, value, _FLOAT)
            else:
                if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") \
                        or len(value) != 3:
                    raise TypeError("%s: expected three numbers (x, y, z)" % name)
                text = ",".join(_number_text(name, v, _FLOAT) for v in value)
        else:
            text = _number_text(name, value, kind)
        # One word, --flag=value: a value is never read as another option ("--seed").
        args.append(flag + "=" + text)
    return args


def devices():
    """The OpenCL devices, as `mcrt devices` lists them: one dict each, by index."""
    return _mcrt.devices()


def variants():
    """Every estimator, light selection, sampler, MIS heuristic and material model, as
    `mcrt variants --json` prints them."""
    return _json.loads(_mcrt.variants_json())


class Scene:
    """A scene loaded once on a Context: render it any number of times."""

    def __init__(self, context, scene):
        self._context = context
        self._scene = scene

    @property
    def path(self):
        return self._scene.path

    @property
    def info(self):
        """Triangles, emitters, textures, cameras, bounds, load time and the import's warnings."""
        return self._scene.info

    def render(self, progress=None, **options):
        """Renders the scene; keywords are `mcrt render`'s options with `_` for `-`
        (estimator may also be an Estimator from Context.estimator). `progress(done, total)`
        is called from this thread with the samples per pixel done. Ctrl-C raises
        KeyboardInterrupt at once, even during a kernel build (docs/PYTHON.md). Returns a
        Result."""
        estimator = options.get("estimator")
        user = None
        if isinstance(estimator, Estimator):
            user = estimator
            options = dict(options)
            del options["estimator"]
        if progress is not None and not callable(progress):
            raise TypeError("progress: expected a callable (done, total)")
        return self._scene._render(_arguments(options), user, progress)

    def __repr__(self):
        return "<mcrt.Scene %r>" % self.path


class Context:
    """The devices of a render session, with the programs and scenes kept on them.

    device: as `mcrt render --device`, one spec or a list (an index from mcrt.devices(),
    cpu, gpu, all, or a platform such as pocl); None: the first device.
    isolated: render in a supervised child process (a user's estimator that hangs or crashes
    raises DeviceError instead of ending Python); see docs/PYTHON.md."""

    def __new__(cls, device=None, isolated=False):
        if cls is Context and isolated:
            from ._isolated_api import IsolatedContext
            return IsolatedContext(device)
        return super().__new__(cls)

    def __init__(self, device=None, isolated=False):
        if device is None:
            specs = []
        elif isinstance(device, (str, int)) and not isinstance(device, bool):
            specs = [str(device)]
        else:
            try:
                specs = [str(d) if isinstance(d, int) and not isinstance(d, bool) else d
                         for d in device]
            except TypeError:
                raise TypeError("device: expected a spec or a list of specs") from None
            if not all(isinstance(d, str) for d in specs):
                raise TypeError("device: expected str or int specs")
        self._context = _mcrt._Context(specs)

    @property
    def devices(self):
        """The devices the context renders on (empty once closed)."""
        return self._context.devices

    @property
    def warnings(self):
        return self._context.warnings

    def load(self, path, materials="gltf"):
        """Reads a glTF scene once (SceneError when it cannot be read); materials as
        `mcrt render --materials`. Ctrl-C raises KeyboardInterrupt at once."""
        if not isinstance(path, (str, bytes)) and not hasattr(path, "__fspath__"):
            raise TypeError("path: expected a str or path, got %s" % type(path).__name__)
        if not isinstance(materials, str):
            raise TypeError("materials: expected a str, got %s" % type(materials).__name__)
        import os
        return Scene(self, self._context.load(os.fsdecode(path), materials))

    def estimator(self, source, name="estimator.cl"):
        """A user's estimator from its OpenCL C text (as an --estimator-file holds), checked
        now; build errors come at its first render, as EstimatorError naming `name`:LINE."""
        if not isinstance(source, str) or not isinstance(name, str):
            raise TypeError("estimator: expected the source and its name as str")
        return self._context.estimator(source, name)

    def close(self):
        """Releases the devices; scenes of this context cannot render afterwards."""
        self._context.close()

    @property
    def closed(self):
        return self._context.closed

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def render(path, device=None, materials="gltf", **options):
    """One render of one scene: Context(device).load(path, materials).render(**options)."""
    with Context(device) as ctx:
        return ctx.load(path, materials).render(**options)

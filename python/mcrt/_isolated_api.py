"""Context(isolated=True): the API of Context, Scene and Result over a child process
(_isolated.Worker), which keeps the real ones."""

from . import Estimator, _arguments
from ._isolated import Worker


class IsolatedResult:
    """A Result whose arrays were copied from the child (they own their memory)."""

    def __init__(self, worker, key, fields):
        self._worker, self._key = worker, key
        for name, value in fields.items():
            setattr(self, name, value)

    def save(self, path, png="", exposure=0):
        """As Result.save: the child, which keeps the last result, writes the files."""
        import os
        self._worker.request("save", None, (self._key, os.fsdecode(path), png, exposure))


class IsolatedEstimator:
    def __init__(self, key, name):
        self._key, self.name = key, name

    def __repr__(self):
        return "<mcrt.Estimator %r, isolated>" % self.name


class IsolatedScene:
    def __init__(self, context, key, path, info):
        self._context, self._key, self.path, self._info = context, key, path, info

    @property
    def info(self):
        return self._info

    def render(self, progress=None, **options):
        """As Scene.render, in the child process."""
        from . import DeviceError
        estimator = options.get("estimator")
        user = None
        if isinstance(estimator, IsolatedEstimator):
            user = estimator._key
            options = {k: v for k, v in options.items() if k != "estimator"}
        elif isinstance(estimator, Estimator):
            raise TypeError("estimator: an Estimator of another context")
        if progress is not None and not callable(progress):
            raise TypeError("progress: expected a callable (done, total)")
        _arguments(options)  # TypeError here, before the child is asked
        if self._context.closed:
            raise DeviceError("the context of this scene is closed")
        worker = self._context._worker
        key = worker.key()
        fields = worker.request("render", key, (self._key, options, user),
                                time_limit=options.get("time_limit"), progress=progress)
        return IsolatedResult(worker, key, fields)

    def __repr__(self):
        return "<mcrt.Scene %r, isolated>" % self.path


class IsolatedContext:
    """mcrt.Context(device, isolated=True)."""

    isolated = True

    def __init__(self, device=None):
        self._worker = Worker()
        self._key = self._worker.key()
        self.closed = False
        self._devices, self._warnings = self._worker.request(
            "context", self._key, (device,), setup=True)

    @property
    def devices(self):
        return [] if self.closed else self._devices

    @property
    def warnings(self):
        return self._warnings

    def _check_open(self):
        if self.closed:
            from . import DeviceError
            raise DeviceError("the context is closed")

    def load(self, path, materials="gltf"):
        import os
        if not isinstance(path, (str, bytes)) and not hasattr(path, "__fspath__"):
            raise TypeError("path: expected a str or path, got %s" % type(path).__name__)
        if not isinstance(materials, str):
            raise TypeError("materials: expected a str, got %s" % type(materials).__name__)
        self._check_open()
        key = self._worker.key()
        path = os.fsdecode(path)
        info = self._worker.request("load", key, (self._key, path, materials), setup=True)
        return IsolatedScene(self, key, path, info)

    def estimator(self, source, name="estimator.cl"):
        if not isinstance(source, str) or not isinstance(name, str):
            raise TypeError("estimator: expected the source and its name as str")
        self._check_open()
        key = self._worker.key()
        self._worker.request("estimator", key, (self._key, source, name), setup=True)
        return IsolatedEstimator(key, name)

    def close(self):
        if not self.closed:
            self.closed = True
            self._worker.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        try:
            self.close()
        except Exception:
            pass

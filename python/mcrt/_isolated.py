"""Contexts that render in a supervised child process (Context(isolated=True)): a user's
estimator that never returns, or that crashes its process, raises DeviceError here instead of
hanging or ending this interpreter. The child is a Python process running this module; this
process (the supervisor) sends it each request and waits for the answer. As `mcrt render`'s
supervisor does (docs/ROBUSTNESS.md, "Kernels that hang or crash"), it kills a render that has
not ended kGrace seconds after its time limit, and turns a death by a signal into one line.
The next request starts a new child, which loads the context's scenes and estimators again."""

import os
import pickle
import signal
import struct
import subprocess
import sys
import time

GRACE_SECONDS = 5.0  # the command line's kSupervisorGraceSeconds (host/cli/supervisor.h)


def _send(stream, message):
    data = pickle.dumps(message, protocol=pickle.HIGHEST_PROTOCOL)
    stream.write(struct.pack("<Q", len(data)) + data)
    stream.flush()


def _receive_exactly(fd, size, deadline):
    """size bytes from fd, or None at its end; TimeoutError after deadline (a monotonic time)."""
    import select
    chunks, left = [], size
    while left:
        if deadline is not None:
            wait = deadline - time.monotonic()
            if wait <= 0 or not select.select([fd], [], [], wait)[0]:
                raise TimeoutError
        chunk = os.read(fd, min(left, 1 << 20))
        if not chunk:
            return None
        chunks.append(chunk)
        left -= len(chunk)
    return b"".join(chunks)


def _receive(fd, deadline=None):
    header = _receive_exactly(fd, 8, deadline)
    if header is None:
        return None
    data = _receive_exactly(fd, struct.unpack("<Q", header)[0], deadline)
    return None if data is None else pickle.loads(data)


def _error_message(error):
    return ("error", type(error).__name__, str(error), getattr(error, "line", None),
            getattr(error, "log", None))


def _worker():
    """The child: answers requests on stdin over the file that was its stdout (its own prints
    go to stderr)."""
    import mcrt
    channel = os.fdopen(os.dup(1), "wb")
    os.dup2(2, 1)
    requests = sys.stdin.buffer
    contexts, scenes, estimators, results = {}, {}, {}, {}

    def read_request():
        header = requests.read(8)
        if len(header) < 8:
            return None
        return pickle.loads(requests.read(struct.unpack("<Q", header)[0]))

    while True:
        request = read_request()
        if request is None:
            return
        kind, key, arguments = request
        try:
            if kind == "context":
                contexts[key] = mcrt.Context(*arguments)
                answer = (contexts[key].devices, contexts[key].warnings)
            elif kind == "load":
                context, path, materials = arguments
                scenes[key] = contexts[context].load(path, materials)
                answer = scenes[key].info
            elif kind == "estimator":
                context, source, name = arguments
                estimators[key] = contexts[context].estimator(source, name)
                answer = None
            elif kind == "render":
                scene, options, estimator = arguments
                if estimator is not None:
                    options = dict(options, estimator=estimators[estimator])

                def progress(done, total):
                    _send(channel, ("progress", done, total))
                result = scenes[scene].render(progress=progress, **options)
                results.clear()  # the last result is kept for its save()
                results[key] = result
                answer = dict(image=result.image, variance=result.variance,
                              replicate_images=result.replicate_images, spp=result.spp,
                              replicates=result.replicates, stopped_by=result.stopped_by,
                              warnings=result.warnings, stats=result.stats)
            elif kind == "save":
                result, path, png, exposure = arguments
                results[result].save(path, png=png, exposure=exposure)
                answer = None
            elif kind == "close":
                contexts[key].close()
                answer = None
            else:
                raise RuntimeError("unknown request " + kind)
            _send(channel, ("ok", answer))
        except BaseException as error:  # KeyboardInterrupt too: the parent re-raises it
            _send(channel, _error_message(error))


class Worker:
    """The supervisor's side of one child, started at the first request and again after a
    child died. Requests that set up state (contexts, loads, estimators) are replayed into a
    new child."""

    def __init__(self):
        self._process = None
        self._setup = []  # (kind, key, arguments) to replay
        self._next_key = 0

    def key(self):
        self._next_key += 1
        return self._next_key

    def _start(self):
        import mcrt
        package_parent = os.path.dirname(os.path.dirname(os.path.abspath(mcrt.__file__)))
        env = dict(os.environ)
        env["PYTHONPATH"] = package_parent + (os.pathsep + env["PYTHONPATH"]
                                              if env.get("PYTHONPATH") else "")
        self._process = subprocess.Popen(
            [sys.executable, "-c", "from mcrt._isolated import _worker; _worker()"],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, env=env,
            start_new_session=True)  # a terminal's Ctrl-C reaches the supervisor only
        for request in self._setup:
            _send(self._process.stdin, request)
            reply = _receive(self._process.stdout.fileno())
            if reply is None or reply[0] != "ok":
                self._reap()
                raise self._died()

    def _reap(self):
        if self._process is not None:
            if self._process.poll() is None:
                self._process.kill()
            self._process.wait()
            self._process.stdin.close()
            self._process.stdout.close()
            self._process = None

    def _died(self):
        from . import DeviceError
        status = self._last_status
        if status is not None and status < 0:
            how = "was killed by signal %s" % signal.Signals(-status).name
        else:
            how = "ended with status %s" % status
        return DeviceError("the isolated render process %s; its context's scenes are loaded "
                           "again for the next request" % how)

    def request(self, kind, key, arguments, setup=False, time_limit=None, progress=None):
        """Sends one request and returns its answer, raising what the child raised."""
        from . import DeviceError
        if self._process is None:
            self._start()
        request = (kind, key, arguments)
        _send(self._process.stdin, request)
        deadline = None if not time_limit else time.monotonic() + time_limit + GRACE_SECONDS
        fd = self._process.stdout.fileno()
        interrupted = False
        while True:
            try:
                reply = _receive(fd, deadline)
            except TimeoutError:
                self._reap_and_remember()
                raise DeviceError("the isolated render did not stop within %g s of its time "
                                  "limit (a kernel that never returns?); its process was killed"
                                  % GRACE_SECONDS) from None
            except KeyboardInterrupt:
                # Ctrl-C: the child stops its render as the module does, and answers.
                interrupted = True
                self._process.send_signal(signal.SIGINT)
                deadline = time.monotonic() + GRACE_SECONDS
                continue
            if reply is None:
                self._reap_and_remember()
                raise self._died()
            if reply[0] == "progress":
                if progress is not None:
                    progress(reply[1], reply[2])
                continue
            break
        if interrupted and reply[0] != "error":
            raise KeyboardInterrupt
        if reply[0] == "error":
            raise _rebuilt(reply)
        if setup:
            self._setup.append(request)
        return reply[1]

    def _reap_and_remember(self):
        process = self._process
        if process.poll() is None:
            process.kill()
        self._last_status = process.wait()
        self._reap()

    _last_status = None

    def close(self):
        if self._process is not None:
            self._process.stdin.close()
            try:
                self._process.wait(timeout=GRACE_SECONDS)
            except subprocess.TimeoutExpired:
                pass
            self._reap()


def _rebuilt(reply):
    """The exception the child raised, of the same class."""
    import builtins
    from . import _mcrt
    _, name, message, line, log = reply
    cls = getattr(_mcrt, name, None) or getattr(builtins, name, None)
    if not (isinstance(cls, type) and issubclass(cls, BaseException)):
        cls = RuntimeError
    error = cls(message)
    if line is not None or log is not None:
        error.line, error.log = line, log
    return error

"""The sandboxed side of grading: imports a submission and answers calls over pipes.

Run by `msdlab.instructor.judging.sandbox` as ``python -I -S sandbox_child.py CONFIG_JSON``.
It imports the trusted libraries first, then installs an audit hook that keeps
the submission inside its folders (no reading outside the allowed roots, no
writing outside its scratch folder, no processes, sockets, signals or ctypes),
then serves requests: import a task, get an attribute, call something. Every
answer is plain data (see `msdlab.instructor.judging.wire`) or a reference to an object
kept here, so nothing the submission builds ever runs in the grader.
"""

from __future__ import annotations

import json
import linecache
import os
import sys
import traceback
from typing import Any


def main(config: dict[str, Any]) -> None:
    _die_with_parent()
    sys.path[:0] = config["sys_path"]
    # stdout and stderr are the grader's log of what the submission printed
    sys.stdout = os.fdopen(1, "w", buffering=1)
    sys.stderr = os.fdopen(2, "w", buffering=1)
    _limit_resources(config["memory_bytes"], config["cpu_seconds"])
    import importlib.util

    import numpy  # noqa: F401  trusted libraries load before the guard
    import scipy.linalg
    import scipy.sparse
    import scipy.sparse.linalg  # noqa: F401  what the engine imports only when used

    import msdlab  # noqa: F401
    from msdlab.course import delegation, failure  # noqa: F401  failure: _raised_in's
    from msdlab.instructor.judging import wire

    _load_engine()
    delegation.install()  # before the submission is imported: see msdlab.course.delegation

    _refuse_new_processes()
    _install_guard(config["read_roots"], config["scratch"])
    os.chdir(config["scratch"])
    Server(config["folder"], config["in_fd"], config["out_fd"], wire, importlib.util).serve()


def _die_with_parent() -> None:
    """Ask Linux to kill this process when the grader that started it dies."""
    import contextlib
    import ctypes
    import signal

    parent = os.getppid()  # in a PID namespace the parent may be 1 (bubblewrap's init)
    with contextlib.suppress(OSError, AttributeError):  # not Linux: time limits still apply
        ctypes.CDLL(None).prctl(1, int(signal.SIGKILL))  # PR_SET_PDEATHSIG
    if os.getppid() != parent:  # the grader died before we asked
        os._exit(1)


NOT_ENGINE = frozenset({
    "instructor", "course", "viz", "scenes", "commands", "cli", "__main__",
    "jupyter_extension", "engine.backends.numba", "engine.backends.warp",
})  # fmt: skip
"""The parts of msdlab a submission's calls do not need (dotted names below ``msdlab``): the
grader's and the course's tools, the pictures, and the numba and Warp backends (the sandbox
runs the numpy backend)."""


def _load_engine() -> None:
    """Import every module of the engine now, before the guard and the submission: its calls
    never need a file read once the submission's code has run (``msdlab`` imports its
    names on first use, the guard refuses files outside its roots, and the submission
    may have changed how its process imports)."""
    import importlib

    for name in engine_modules():
        importlib.import_module(name)


def engine_modules() -> list[str]:
    """The names of the engine's modules: msdlab's, but for the parts in `NOT_ENGINE`."""
    import pkgutil

    import msdlab

    names, folders = [], [(list(msdlab.__path__), "msdlab.")]
    while folders:
        path, prefix = folders.pop()
        for module in pkgutil.iter_modules(path, prefix):
            parts = module.name.removeprefix("msdlab.").split(".")
            if any(".".join(parts[:end]) in NOT_ENGINE for end in range(1, len(parts) + 1)):
                continue
            names.append(module.name)
            if module.ispkg:
                inside = [os.path.join(folder, module.name.rsplit(".", 1)[-1]) for folder in path]
                folders.append((inside, module.name + "."))
    return sorted(names)


MAX_PROCESSES = 32  # of the sandbox's user: threads and helpers, not a fork bomb


def _limit_resources(memory_bytes: int, cpu_seconds: int) -> None:
    """Memory (bytes), CPU time (s), file size, processes of this user, no core dumps."""
    import resource

    for limit, value in (
        (resource.RLIMIT_AS, memory_bytes),
        (resource.RLIMIT_CPU, cpu_seconds),
        (resource.RLIMIT_FSIZE, 64 * 2**20),
        (resource.RLIMIT_NPROC, MAX_PROCESSES),
        (resource.RLIMIT_CORE, 0),
    ):
        resource.setrlimit(limit, (value, value))


def _refuse_new_processes() -> None:
    """From now on this process can start no process and no thread: whatever the submission
    runs runs here, in the one process whose processor time its budget is charged. Twice
    over: ``RLIMIT_NPROC`` 0, and a seccomp filter (`_refuse_clone`) for root, whom Linux
    never holds to the process limit (the ``process`` isolation run as root, as on
    Gradescope)."""
    import resource

    resource.setrlimit(resource.RLIMIT_NPROC, (0, 0))
    _refuse_clone()


# The system calls that make a process or a thread, by the machine's audit architecture.
CLONE_CALLS = {
    "x86_64": (0xC000003E, (56, 57, 58, 435)),  # clone, fork, vfork, clone3
    "aarch64": (0xC00000B7, (220, 435)),  # clone, clone3
}


def _refuse_clone() -> None:
    """A seccomp filter under which the kernel answers every clone, fork, vfork and clone3
    with EAGAIN, as the process limit does (other ABIs of the machine: EPERM to every call).
    Left out, as before, on a machine or kernel that has none."""
    import ctypes
    import errno
    import platform

    if platform.machine() not in CLONE_CALLS:
        return
    arch, calls = CLONE_CALLS[platform.machine()]
    allow, refuse = 0x7FFF0000, 0x00050000 | errno.EAGAIN  # SECCOMP_RET_ALLOW, _RET_ERRNO
    load, equal, at_least, answer = 0x20, 0x15, 0x35, 0x06  # BPF LD|W|ABS, JEQ, JGE, RET
    program = [(load, 0, 0, 4), (equal, 1, 0, arch), (answer, 0, 0, 0x00050000 | errno.EPERM)]
    program += [(load, 0, 0, 0), (at_least, len(calls) + 1, 0, 0x40000000)]  # x32's calls
    program += [(equal, len(calls) - i, 0, call) for i, call in enumerate(calls)]
    program += [(answer, 0, 0, allow), (answer, 0, 0, refuse)]

    class Instruction(ctypes.Structure):
        _fields_ = [("code", ctypes.c_ushort), ("jt", ctypes.c_ubyte),
                    ("jf", ctypes.c_ubyte), ("k", ctypes.c_uint)]  # fmt: skip

    class Program(ctypes.Structure):
        _fields_ = [("len", ctypes.c_ushort), ("filter", ctypes.POINTER(Instruction))]

    instructions = (Instruction * len(program))(*program)
    filter_program = Program(len(program), instructions)
    prctl = ctypes.CDLL(None, use_errno=True).prctl
    prctl.argtypes = [ctypes.c_int, ctypes.c_ulong, ctypes.c_void_p, ctypes.c_ulong,
                      ctypes.c_ulong]  # fmt: skip
    prctl(38, 1, None, 0, 0)  # PR_SET_NO_NEW_PRIVS: needed to filter without root
    prctl(22, 2, ctypes.addressof(filter_program), 0, 0)  # PR_SET_SECCOMP, MODE_FILTER


_BLOCKED = {
    "subprocess.Popen", "os.system", "os.exec", "os.posix_spawn", "os.spawn", "os.fork",
    "os.forkpty", "pty.spawn", "os.kill", "os.killpg", "signal.pthread_kill",
    "socket.connect", "socket.bind", "socket.sendto", "socket.sendmsg", "socket.getaddrinfo",
    "ctypes.dlopen", "ctypes.dlsym", "ctypes.call_function", "ctypes.cdata",
    "ctypes.cdata/buffer", "ctypes.string_at", "ctypes.wstring_at", "ctypes.addressof",
    "resource.setrlimit", "resource.prlimit", "sys.remote_exec", "os.setuid", "os.setgid",
    "webbrowser.open", "urllib.Request",
}  # fmt: skip
_WRITES = {
    "os.remove", "os.rename", "os.rmdir", "os.mkdir", "os.chmod", "os.chown", "os.link",
    "os.symlink", "os.truncate", "os.utime", "shutil.rmtree", "shutil.move", "shutil.copyfile",
    "shutil.copytree", "os.chflags", "os.lchflags", "os.setxattr", "os.removexattr",
}  # fmt: skip
_LISTS = {"os.listdir", "os.scandir", "glob.glob", "glob.glob/2", "os.chdir"}
_WRITE_FLAGS = os.O_WRONLY | os.O_RDWR | os.O_CREAT | os.O_TRUNC | os.O_APPEND


def _install_guard(read_roots: list[str], scratch: str) -> None:
    """Audit hook: the submission reads only under ``read_roots`` and writes only in ``scratch``."""
    realpath, fspath, sep = os.path.realpath, os.fspath, os.sep
    readable = tuple(realpath(r) for r in [*read_roots, scratch])
    writable = (realpath(scratch),)

    def inside(path: object, roots: tuple[str, ...]) -> bool:
        if path is None or isinstance(path, int):
            return True  # an already open descriptor
        real = realpath(fspath(path))
        return any(real == r or real.startswith(r + sep) for r in roots)

    def guard(event: str, args: tuple) -> None:
        if event == "open":
            path, mode, flags = args
            writing = bool(mode and any(c in str(mode) for c in "wax+")) or bool(
                isinstance(flags, int) and flags & _WRITE_FLAGS
            )
            if not inside(path, writable if writing else readable):
                what = "write" if writing else "read"
                raise PermissionError(f"grading sandbox: submissions may not {what} {path}")
        elif event in _BLOCKED or event.startswith("ctypes."):
            raise PermissionError(f"grading sandbox: submissions may not use {event}")
        elif event in _WRITES:
            for path in args[:2]:
                if isinstance(path, (str, bytes, os.PathLike)) and not inside(path, writable):
                    raise PermissionError(f"grading sandbox: submissions may not change {path}")
        elif event in _LISTS and args and not inside(args[0] or ".", readable):
            raise PermissionError(f"grading sandbox: submissions may not look at {args[0]}")

    sys.addaudithook(guard)


class Server:
    """Answers the grader's requests; keeps the submission's objects in a table of references."""

    def __init__(self, folder: str, in_fd: int, out_fd: int, wire: Any, importer: Any) -> None:
        self.folder, self.out_fd, self.wire, self.importer = folder, out_fd, wire, importer
        self.read = wire.reader(in_fd)
        self.objects: dict[int, Any] = {}
        self.modules: dict[int, Any] = {}
        self.grader_objects: dict[int, GraderObject] = {}
        self.hint: dict | None = None  # the grader's answer to a callback it foresaw (a step's)

    def serve(self) -> None:
        while True:
            try:
                request = self.wire.decode(self.read)
            except EOFError:
                return
            self.send(self.answer(request))

    def answer(self, request: dict) -> dict:
        try:
            op = request["op"]
            if op == "ping":
                value = "pong"
            elif op == "task":
                value = self.task(int(request["n"]))
            elif op == "getattr":
                value = getattr(self.objects[request["ref"].id], request["name"])
            elif op == "call":  # of the object, or of its method "name"
                target = self.objects[request["ref"].id]
                if "name" in request:
                    target = getattr(target, request["name"])
                args, kwargs = self.local(request["args"]), self.local(request["kwargs"])
                _refuse_delegation(request.get("refuse"), self.folder)
                before = _array_arguments(args, kwargs)
                self.hint = request.get("hint")
                try:
                    value = target(*args, **kwargs)
                finally:
                    self.hint = None
                changed = _changed_arguments(before, args, kwargs)
                if changed:
                    return {"ok": value, "args": changed}
            elif op == "inherited":
                value = _inherited(self.objects[request["ref"].id], request["names"])
            elif op == "release":
                for ref in request["refs"]:
                    self.objects.pop(ref.id, None)
                value = None
            else:
                raise ValueError(f"unknown request {op!r}")
            return {"ok": value}
        except BaseException as error:  # the submission's failure is an answer, not our crash
            return {"error": _describe(error, self.folder)}

    def task(self, number: int) -> Any:
        if number not in self.modules:
            path = os.path.join(self.folder, f"task{number}.py")
            if not os.path.isfile(path):
                raise FileNotFoundError(f"task{number}.py is missing from the submission")
            spec = self.importer.spec_from_file_location(f"submission_task{number}", path)
            module = self.importer.module_from_spec(spec)
            sys.modules[spec.name] = module
            spec.loader.exec_module(module)
            self.modules[number] = module
        return self.modules[number]

    def local(self, value: Any) -> Any:
        """Arguments with the grader's references turned into proxies that call back."""
        if isinstance(value, self.wire.Ref):
            if value.kind != "grader":
                return self.objects[value.id]
            if value.id not in self.grader_objects:
                self.grader_objects[value.id] = GraderObject(self, value)
            return self.grader_objects[value.id]
        if isinstance(value, (list, tuple)):
            return type(value)(self.local(v) for v in value)
        if isinstance(value, dict):
            return {k: self.local(v) for k, v in value.items()}
        return value

    def reference(self, value: Any) -> Any:
        """Keep a non-data value here and describe it to the grader."""
        import types

        import msdlab

        self.objects[id(value)] = value
        if isinstance(value, msdlab.Integrator):
            kind = "integrator"
        elif isinstance(value, types.ModuleType):
            kind = "module"
        else:
            kind = "callable" if callable(value) else "object"
        return self.wire.Ref(id(value), kind)

    def send(self, message: dict) -> None:
        try:
            data = self.wire.encode(message, self.reference)
        except Exception as error:  # e.g. a result that is too large
            data = self.wire.encode({"error": _describe(error, self.folder)})
        self.wire.write_all(self.out_fd, data)

    def foreseen(self, owner: tuple[int, str] | None, args: tuple, kwargs: dict) -> Any:
        """The grader's answer to the call ``args`` of the member ``owner`` (its object's
        reference, its name) if the grader sent it with the request being served (`hint`:
        a step's ``dynamics.acceleration`` at the state the step starts from), else None."""
        import numpy

        hint = self.hint
        if hint is None or kwargs or len(args) != 2 or owner != (hint["ref"].id, hint["name"]):
            return None
        try:
            given = [numpy.asarray(a, dtype=float) for a in args]
        except (TypeError, ValueError):
            return None
        if all(numpy.array_equal(a, b) for a, b in zip(given, hint["args"])):
            return hint["ok"].copy()
        return None

    def callback(self, message: dict) -> Any:
        """Send a request to the grader (during a call) and return its answer."""
        self.send(message)
        reply = self.wire.decode(self.read)
        if "error" in reply:
            raise RuntimeError(f"grader: {reply['error']}")
        return self.local(reply["ok"])


class GraderObject:
    """An object of the grader handed to the submission (e.g. the dynamics of a step)."""

    def __init__(self, server: Server, ref: Any) -> None:
        self._server, self._ref = server, ref
        self._methods: dict[str, GraderObject] = {}
        self._owner: tuple[int, str] | None = None  # (object's reference, name) of a method

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_"):
            raise AttributeError(name)
        if name in self._methods:
            return self._methods[name]
        value = self._server.callback({"op": "getattr", "ref": self._ref, "name": name})
        if isinstance(value, GraderObject):
            value._owner = (self._ref.id, name)
            self._methods[name] = value
        return value

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        foreseen = self._server.foreseen(self._owner, args, kwargs)
        if foreseen is not None:
            return foreseen
        message = {"op": "call", "ref": self._ref, "args": args, "kwargs": kwargs}
        return self._server.callback(message)


def _inherited(integrator: Any, names: list[str]) -> list[str]:
    """Those of ``names`` that ``integrator`` takes unchanged from ``msdlab.Integrator``."""
    import msdlab

    kind = type(integrator)
    if not isinstance(integrator, msdlab.Integrator) or (
        kind.__getattribute__ is not object.__getattribute__
    ):
        return []
    own = getattr(integrator, "__dict__", {})
    return [
        name
        for name in names
        if name not in own
        and getattr(kind, name, None) is getattr(msdlab.Integrator, name, object())
    ]


def _refuse_delegation(task: Any, folder: str) -> None:
    """The task being checked: the engine's answer to it refuses the submission's calls."""
    from msdlab.course import delegation

    delegation.set_refused(task if isinstance(task, int) else None, folder)


def _array_arguments(args: tuple, kwargs: dict) -> dict[str, Any]:
    """Copies of the call's array arguments, keyed by position ("0", "1", ...) or name."""
    import numpy

    named = {**{str(i): a for i, a in enumerate(args)}, **kwargs}
    return {k: a.copy() for k, a in named.items() if isinstance(a, numpy.ndarray)}


def _changed_arguments(before: dict[str, Any], args: tuple, kwargs: dict) -> dict[str, Any]:
    """The array arguments the call changed in place: their new values, so that the grader's
    arrays change as they would in one process; for a changed shape or dtype only a
    description (the grader refuses to apply it)."""
    import numpy

    named = {**{str(i): a for i, a in enumerate(args)}, **kwargs}
    changed: dict[str, Any] = {}
    for key, old in before.items():
        new = named[key]
        if new.shape != old.shape or new.dtype != old.dtype:
            changed[key] = {"shape": list(new.shape), "dtype": new.dtype.str}
        elif new.tobytes() != old.tobytes() and not numpy.array_equal(
            new, old, equal_nan=new.dtype.kind in "fc"
        ):  # the same bytes are the same values: the common case costs no comparison
            changed[key] = new
    return changed


def _describe(error: BaseException, folder: str) -> dict:
    """The error's type and message, and where in the submission's files it was raised."""
    if isinstance(error, SystemExit):
        message = f"the submission called sys.exit({error.code!r})"
    else:
        message = str(error)
    described = {"type": type(error).__name__, "message": message[:4000]}
    return described | _raised_in(error, folder)


def _raised_in(error: BaseException, folder: str) -> dict:
    """The innermost line of the submission's files in ``error``'s traceback outside their
    given code (`outside_given_code`): its file (from ``folder``), line, function (a method
    with its class) and code; {} where there is none."""
    frames = [
        (frame, line)
        for frame, line in traceback.walk_tb(error.__traceback__)
        if frame.f_code.co_filename.startswith(folder)
    ]
    if not frames:
        return {}
    from msdlab.course.failure import outside_given_code  # loaded before the guard: main

    frame, line = frames[outside_given_code([(f.f_code.co_filename, n) for f, n in frames])]
    path = frame.f_code.co_filename
    return {
        "file": os.path.relpath(path, folder),
        "line": line,
        "function": getattr(frame.f_code, "co_qualname", frame.f_code.co_name),  # 3.11+
        "code": linecache.getline(path, line).strip(),
    }


if __name__ == "__main__":
    main(json.loads(sys.argv[1]))

"""``python -m MODULE --help`` for many modules in one process (tests/cli/test_entry_points.py).

The heavy libraries are imported once; then each module runs in a forked child exactly as
``python -m`` runs it (:func:`runpy.run_module` as ``__main__``, ``sys.argv = [path,
"--help"]``), in its own empty working folder, killed after ``TIMEOUT_S`` seconds: the same
run as a fresh ``python -m MODULE --help`` without paying the libraries' import for each.
:func:`run` is called in a fresh interpreter (a single-threaded one: the children fork)."""

from __future__ import annotations

import os
import runpy
import signal
import subprocess
import sys
import tempfile
import traceback

#: imported once before the children fork (the entry points import most of them)
PRELOAD = (
    "numpy", "scipy", "shapely", "matplotlib.pyplot", "gymnasium", "torch", "stable_baselines3",
    "pettingzoo", "ray", "yaml", "numba", "geometry", "sensorplan_gym", "agents",
)  # fmt: skip
TIMEOUT_S = 120


def _child(module: str, cwd: str, out: str, err: str) -> None:
    code = 1
    try:
        os.chdir(cwd)
        for fd, path in ((1, out), (2, err)):
            f = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
            os.dup2(f, fd)
            os.close(f)
        signal.alarm(TIMEOUT_S)
        sys.argv = [module, "--help"]
        try:
            runpy.run_module(module, run_name="__main__", alter_sys=True)
            code = 0
        except SystemExit as e:
            code = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
        except BaseException:
            traceback.print_exc()
        sys.stdout.flush()
        sys.stderr.flush()
    finally:
        os._exit(code)


def run(modules: list[str]) -> dict[str, list]:
    """Per module: ``[exit status, stdout, stderr, names left in its working folder]``
    (exit status negative: killed by that signal).  Without ``os.fork`` (not POSIX) each
    module runs as its own ``python -m MODULE --help``."""
    if hasattr(os, "fork"):
        for lib in PRELOAD:
            try:
                __import__(lib)
            except ImportError:
                pass
    got = {}
    for module in modules:
        with tempfile.TemporaryDirectory() as io, tempfile.TemporaryDirectory() as cwd:
            out, err = os.path.join(io, "out"), os.path.join(io, "err")
            if hasattr(os, "fork"):
                sys.stdout.flush()
                sys.stderr.flush()
                pid = os.fork()
                if pid == 0:
                    _child(module, cwd, out, err)
                rc = os.waitstatus_to_exitcode(os.waitpid(pid, 0)[1])
            else:
                with open(out, "w") as fo, open(err, "w") as fe:
                    cmd = [sys.executable, "-m", module, "--help"]
                    try:
                        rc = subprocess.run(
                            cmd, cwd=cwd, stdout=fo, stderr=fe, timeout=TIMEOUT_S
                        ).returncode
                    except subprocess.TimeoutExpired:
                        rc = -int(signal.SIGTERM)
            texts = []
            for path in (out, err):
                with open(path, encoding="utf-8", errors="replace") as f:
                    texts.append(f.read())
            got[module] = [rc, *texts, sorted(os.listdir(cwd))]
    return got

"""The C library's transcendental functions, elementwise over numpy arrays.

numpy may evaluate ``arctan2``, ``sin`` and ``cos`` with its own SIMD code (SVML on
AVX-512 machines), which can differ from the C library in the last bit.  The compiled
kernels of :mod:`geometry.visindex` call the C library (numba lowers :mod:`math` to it),
so the numpy code paths that must answer bitwise as the kernels do use these instead.
With numba installed they are numba ufuncs (compiled on first use, as fast as numpy's);
without it they loop over :mod:`math` (the same C library calls, slower)."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

try:  # numba is the optional `fast` extra
    import numba as _numba
except ImportError:  # pragma: no cover - exercised in installs without the extra
    _numba = None

__all__ = ["atan2", "cos", "sin"]


def _ufunc(f: Callable, nargs: int) -> Callable[..., np.ndarray]:
    """``f`` as an elementwise function of float64 arrays, compiled on first call."""
    compiled: list = []

    def call(*args: np.ndarray) -> np.ndarray:
        if not compiled:
            if _numba is not None:
                sig = "float64(" + ", ".join(["float64"] * nargs) + ")"
                compiled.append(_numba.vectorize([sig], nopython=True)(f))
            else:
                compiled.append(np.frompyfunc(f, nargs, 1))
        out = compiled[0](*(np.asarray(a, dtype=np.float64) for a in args))
        return np.asarray(out, dtype=np.float64)

    return call


def _atan2(y: float, x: float) -> float:
    return math.atan2(y, x)


def _cos(x: float) -> float:
    return math.cos(x)


def _sin(x: float) -> float:
    return math.sin(x)


atan2 = _ufunc(_atan2, 2)
"""``atan2(y, x)`` elementwise (radians in (-pi, pi]), bitwise as the C library's."""
cos = _ufunc(_cos, 1)
"""``cos(x)`` elementwise (x in radians), bitwise as the C library's."""
sin = _ufunc(_sin, 1)
"""``sin(x)`` elementwise (x in radians), bitwise as the C library's."""

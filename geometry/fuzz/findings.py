"""What the fuzzer reports: one :class:`Finding` per violation, and each query's CPU time."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ..scene import SceneError

#: A query slower than this (seconds) is a hang.
HANG_S = 10.0


@dataclass
class Finding:
    kind: str
    query: str
    detail: str


def _timed(
    fn: Callable[[], Any], name: str, out: list[Finding], times: dict, hang_s: float = HANG_S
) -> Any:
    t0 = time.process_time()  # CPU time: wall clock on a shared machine measures the load
    try:
        r = fn()
    except (SceneError, NotImplementedError):
        r = None
    except Exception as e:  # noqa: BLE001 -- the point of the fuzzer
        out.append(Finding("crash", name, f"{type(e).__name__}: {e}"))
        r = None
    dt = time.process_time() - t0
    times[name] = dt
    if dt > hang_s:
        out.append(Finding("hang", name, f"{dt:.1f} s"))
    return r

"""Debian's chromium, headless, for the browser tests (no driver, nothing downloaded).

``CHROMIUM`` is the executable or ``None`` (tests skip then); :func:`chromium` runs it with
:data:`FLAGS` and a profile folder under ``tmp``.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

CHROMIUM = shutil.which("chromium") or (
    "/usr/bin/chromium" if os.path.exists("/usr/bin/chromium") else None
)

FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--hide-scrollbars",
    "--disable-dev-shm-usage",
]


def chromium(tmp: Path, *args: str, timeout: float = 60) -> subprocess.CompletedProcess:
    """Run headless chromium with ``args`` (e.g. ``--dump-dom URL``); output captured as text."""
    assert CHROMIUM is not None, "chromium is not installed"
    return subprocess.run(
        [CHROMIUM, *FLAGS, f"--user-data-dir={tmp / 'profile'}", *args],
        capture_output=True,
        text=True,
        timeout=timeout,
    )

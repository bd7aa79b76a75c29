"""An on-disk cache of recognizable regions, so that a scene pool built once builds again in
seconds (in this process or the next).

What is cached is the one expensive part of a :class:`~.world.World`: the exact region
returned by :func:`geometry.recognizable_region` (for polygonal G/H under the partial model,
the paper's 5.2 swept construction: about 0.5-3.5 s per procedural scene).  Everything else a
world holds is rebuilt from the scene in about a millisecond.  Regions are stored as WKB
(float64 coordinates, so a stored region is bit-for-bit the computed one), one file per key.

The key is the SHA-256 of everything the region depends on: the scene as the geometry sees
it (its JSON dict, after the world's configuration is applied), the region's arguments
(``model``, ``theta``, ``eps_pos``, ``eps_aim``), the library version, a digest of the
``geometry`` package's source files (an edited algorithm is a different key, even without a
version bump), and the numpy / shapely / GEOS versions and the platform.  A changed scene or
configuration is therefore a miss, never a stale hit.

Where: ``$SENSORPLAN_GYM_CACHE`` if it names a folder; otherwise
``$XDG_CACHE_HOME/sensorplan-gym`` (``~/.cache/sensorplan-gym`` when ``XDG_CACHE_HOME`` is not
set).  Opt out with ``SENSORPLAN_GYM_CACHE=off`` (or ``0``, ``false``, ``no``, empty), or per
pool with ``disk_cache=False`` (``scene_pool_cache=False`` in the envs).  Deleting the folder
is always safe.
"""

from __future__ import annotations

import functools
import hashlib
import importlib.metadata
import json
import os
import platform
import tempfile
import time
from pathlib import Path
from typing import Any

import shapely

__all__ = ["ENV_VAR", "RegionCache", "default_cache_dir", "resolve_cache"]

#: the environment variable that relocates (a folder) or switches off (``off``) the cache
ENV_VAR = "SENSORPLAN_GYM_CACHE"
_OFF = {"", "0", "off", "false", "no", "none"}
#: bumped when the stored format or the key's contents change
FORMAT = 1


def default_cache_dir() -> Path | None:
    """The cache folder from the environment (see the module docstring); ``None`` when the
    cache is switched off with ``SENSORPLAN_GYM_CACHE=off``."""
    v = os.environ.get(ENV_VAR)
    if v is not None:
        if v.strip().lower() in _OFF:
            return None
        return Path(v).expanduser()
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "sensorplan-gym"


@functools.lru_cache(maxsize=1)
def _code_digest() -> str:
    """SHA-256 over the library version, the ``geometry`` package's ``.py`` files (path and
    contents), and the numerical libraries' versions and the platform."""
    import numpy as np

    import geometry

    try:  # the installed distribution's version (the core imports nothing above it)
        version = importlib.metadata.version("sensorplan-gym")
    except importlib.metadata.PackageNotFoundError:  # pragma: no cover - not installed
        version = "unknown"
    h = hashlib.sha256()
    h.update(f"format={FORMAT};version={version};".encode())
    h.update(
        f"numpy={np.__version__};shapely={shapely.__version__};geos={shapely.geos_version_string};"
        f"machine={platform.machine()};system={platform.system()};".encode()
    )
    root = Path(geometry.__file__).resolve().parent
    for p in sorted(root.rglob("*.py")):
        h.update(str(p.relative_to(root)).encode() + b"\0")
        h.update(p.read_bytes() + b"\0")
    return h.hexdigest()


class RegionCache:
    """Recognizable regions on disk under ``directory`` (see the module docstring).

    ``min_seconds``: a region is stored only when computing it took at least this long
    (seconds), so cheap regions (point G/H, the complete model) do not fill the folder; 0
    stores every region.  Looking up always happens.
    """

    def __init__(self, directory: str | os.PathLike[str], min_seconds: float = 0.05) -> None:
        if not isinstance(min_seconds, (int, float)) or not min_seconds >= 0:
            raise ValueError(f"min_seconds must be a non-negative number, got {min_seconds!r}")
        self.directory = Path(directory).expanduser()
        self.min_seconds = float(min_seconds)
        #: lookups answered from disk / regions computed, in this process
        self.hits = 0
        self.misses = 0

    def __repr__(self) -> str:
        return f"RegionCache({str(self.directory)!r}, min_seconds={self.min_seconds})"

    def __eq__(self, other: object) -> bool:
        return (
            isinstance(other, RegionCache)
            and other.directory == self.directory
            and other.min_seconds == self.min_seconds
        )

    def __hash__(self) -> int:
        return hash((self.directory, self.min_seconds))

    @staticmethod
    def key(scene_dict: dict[str, Any], **region_args: Any) -> str:
        """The key (hex SHA-256) of the region of the scene ``scene_dict`` (its JSON dict)
        computed with ``geometry.recognizable_region(scene, **region_args)``."""
        blob = json.dumps(
            {"scene": scene_dict, "args": region_args, "code": _code_digest()},
            sort_keys=True,
            allow_nan=True,
        )
        return hashlib.sha256(blob.encode()).hexdigest()

    def path(self, key: str) -> Path:
        """The file holding region ``key``."""
        return self.directory / "regions" / key[:2] / f"{key}.wkb"

    def load(self, key: str) -> shapely.Geometry | None:
        """The stored region ``key``, or ``None`` (not stored, or unreadable: then it is
        computed again and overwritten)."""
        try:
            data = self.path(key).read_bytes()
        except OSError:
            return None
        try:
            g = shapely.from_wkb(data)
        except Exception:  # a truncated or foreign file: a miss
            return None
        return g if isinstance(g, shapely.Geometry) else None

    def store(self, key: str, region: shapely.Geometry) -> None:
        """Write region ``key`` atomically (a temporary file renamed into place, so parallel
        builders never see half a file).  A folder that cannot be written is ignored."""
        p = self.path(key)
        try:
            p.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(dir=p.parent, prefix=".tmp-", suffix=".wkb")
            with os.fdopen(fd, "wb") as f:
                f.write(shapely.to_wkb(region))
            os.replace(tmp, p)
        except OSError:
            pass

    def region(self, scene: Any, compute: Any, **region_args: Any) -> shapely.Geometry:
        """The region of ``scene`` (a :class:`geometry.Scene`) for ``region_args``: from disk,
        or ``compute()`` (stored when it took at least ``min_seconds``)."""
        key = self.key(scene.to_dict(), **region_args)
        g = self.load(key)
        if g is not None:
            self.hits += 1
            return g
        self.misses += 1
        t = time.perf_counter()
        g = compute()
        if time.perf_counter() - t >= self.min_seconds:
            self.store(key, g)
        return g


def resolve_cache(
    disk_cache: bool | str | os.PathLike[str] | RegionCache | None,
) -> RegionCache | None:
    """The :class:`RegionCache` a pool uses: ``None`` or ``True`` the default folder from the
    environment (``None`` when switched off there), ``False`` none, a path that folder, or a
    :class:`RegionCache` itself."""
    if isinstance(disk_cache, RegionCache):
        return disk_cache
    if disk_cache is False:
        return None
    if disk_cache is None or disk_cache is True:
        d = default_cache_dir()
        return None if d is None else RegionCache(d)
    if isinstance(disk_cache, (str, os.PathLike)):
        if not str(disk_cache).strip():
            raise ValueError("disk_cache: an empty path (use False to switch the cache off)")
        return RegionCache(disk_cache)
    raise TypeError(
        f"disk_cache must be None, True, False, a folder path or a RegionCache, got {disk_cache!r}"
    )

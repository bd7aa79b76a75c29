"""The LRU cache of :class:`~.world.World` objects keyed by scene JSON and configuration, so
resetting an environment on a known scene costs nothing."""

from __future__ import annotations

import json
from collections import OrderedDict
from typing import TYPE_CHECKING

from .diskcache import RegionCache
from .world import World, WorldConfig

if TYPE_CHECKING:  # pragma: no cover
    from geometry import Scene

__all__ = ["CACHE_SIZE", "clear_cache", "get_world"]

CACHE_SIZE = 64
_CACHE: OrderedDict[tuple, World] = OrderedDict()


def get_world(
    scene: Scene,
    cfg: WorldConfig,
    data: dict | None = None,
    *,
    disk_cache: RegionCache | None = None,
) -> World:
    """The cached :class:`World` for ``(scene, cfg)`` (LRU of ``CACHE_SIZE`` entries).
    ``data``: the scene's JSON dict when the caller has it (saves a deep copy).
    ``disk_cache``: where a world not in memory looks up its region before computing it
    (:class:`~.diskcache.RegionCache`; ``None``: computed)."""
    key = (json.dumps(scene.to_dict() if data is None else data, sort_keys=True), cfg)
    w = _CACHE.get(key)
    if w is not None:
        _CACHE.move_to_end(key)
        return w
    w = World(scene, cfg, disk_cache=disk_cache)
    _CACHE[key] = w
    if len(_CACHE) > CACHE_SIZE:
        _CACHE.popitem(last=False)
    return w


def clear_cache() -> None:
    """Forget every cached world."""
    _CACHE.clear()

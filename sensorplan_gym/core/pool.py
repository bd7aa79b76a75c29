"""Where sub-environments get their worlds: one fixed scene, or a seeded pool of procedural
scenes (``scene="random"``).

A :class:`ScenePool` of ``size`` scenes is deterministic in ``seed``: scene ``k`` is drawn by
:func:`geometry.generate.random_scene` from ``numpy.random.default_rng([seed, k])`` (re-drawn
from the same stream while it cannot host an episode) -- or, with ``family=``, by
:meth:`geometry.families.SceneFamily.sample_dict` from the same stream -- so every process, every
sub-environment and every run sees the same scene ``k``.  Scenes are built on first use and
kept (pools are shared between environments of a process with the same arguments), so after
the first draws a reset only picks an index: nothing is generated on the hot path.  Disjoint
seeds give disjoint splits (e.g. train and test).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from typing import Any

import numpy as np

from geometry import Scene
from geometry.families import SceneFamily
from geometry.generate import random_scene

from .cache import get_world
from .world import World, WorldConfig

__all__ = ["FixedScene", "ScenePool"]

Start = tuple[float, float, float]
#: ``(world, rng) -> (start pose, problem or None)``
Check = Callable[[World, np.random.Generator], tuple[Start | None, str | None]]


class FixedScene:
    """Every episode in the same world (no random draw)."""

    def __init__(self, world: World, start: Start) -> None:
        self.world, self.start = world, start

    def draw(self, rng: np.random.Generator) -> tuple[World, Start]:
        return self.world, self.start


class ScenePool:
    """``size`` procedural scenes, deterministic in ``seed`` (see the module docstring)."""

    def __init__(
        self,
        cfg: WorldConfig,
        check: Check,
        *,
        size: int = 64,
        seed: int = 0,
        scene_kwargs: dict | None = None,
        max_tries: int = 25,
        family: SceneFamily | None = None,
    ) -> None:
        if not isinstance(size, (int, np.integer)) or size < 1:
            raise ValueError(f"scene_pool_size must be a positive integer, got {size!r}")
        if not isinstance(seed, (int, np.integer)) or seed < 0:
            raise ValueError(f"scene_pool_seed must be a non-negative integer, got {seed!r}")
        self.cfg, self.check = cfg, check
        self.size, self.seed = int(size), int(seed)
        self.scene_kwargs = dict(scene_kwargs or {})
        if family is not None and not isinstance(family, SceneFamily):
            raise TypeError(f"family must be a geometry.families.SceneFamily, got {family!r}")
        if family is not None and self.scene_kwargs:
            raise ValueError("give random_scene_kwargs or a scene family, not both")
        self.family = family
        self.max_tries = int(max_tries)
        self.entries: dict[int, tuple[World, Start]] = {}

    def __getstate__(self) -> dict[str, Any]:
        return self.__dict__.copy()

    def get(self, k: int) -> tuple[World, Start]:
        """Scene ``k`` (built on first use)."""
        e = self.entries.get(k)
        if e is None:
            rng = np.random.default_rng([self.seed, k])
            last = None
            for _ in range(self.max_tries):
                if self.family is not None:
                    d = self.family.sample_dict(rng)
                else:
                    d = random_scene(rng, **self.scene_kwargs)
                world = get_world(Scene.from_dict(d), self.cfg, d)
                start, last = self.check(world, rng)
                if last is None:
                    e = self.entries[k] = (world, start)
                    break
            else:
                raise RuntimeError(
                    f"scene='random': no usable scene in {self.max_tries} draws for pool "
                    f"entry {k} (seed {self.seed}): {last}; relax the configuration or raise "
                    "max_scene_tries"
                )
        return e

    def draw(self, rng: np.random.Generator) -> tuple[World, Start]:
        """A uniformly drawn scene of the pool (one integer from ``rng``)."""
        return self.get(int(rng.integers(self.size)))

    def build(self) -> ScenePool:
        """Build every scene now (e.g. before timing or training)."""
        for k in range(self.size):
            self.get(k)
        return self


_POOLS: dict[str, ScenePool] = {}


def shared_pool(cfg: WorldConfig, check: Check, kind: str, **kw: Any) -> ScenePool:
    """The process-wide pool for these arguments (``kind`` names the validity check)."""
    key = json.dumps([repr(cfg), kind, {k: kw[k] for k in sorted(kw)}], default=repr)
    p = _POOLS.get(key)
    if p is None:
        p = _POOLS[key] = ScenePool(cfg, check, **kw)
    return p


__all__ += ["shared_pool"]

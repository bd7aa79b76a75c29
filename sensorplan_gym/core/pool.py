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

Building a pool of polygonal-G/H scenes under the partial model is dominated by the exact swept
region (paper 5.2, about 0.5-3.5 s per scene), so two things make large pools affordable:

* :meth:`ScenePool.build` with ``jobs=k`` builds the missing scenes in ``k`` worker processes
  (the same scene ``k`` as a serial build: each worker draws it from the same stream);
* the regions go to an on-disk cache (:mod:`.diskcache`, on by default;
  ``SENSORPLAN_GYM_CACHE=off`` or ``disk_cache=False`` switches it off), so building the same
  pool again -- in this process or the next -- reads them back instead of computing them.
"""

from __future__ import annotations

import json
import multiprocessing
import os
import pickle
import warnings
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from typing import Any

import numpy as np

from geometry import Scene
from geometry.families import SceneFamily
from geometry.generate import random_scene

from .cache import get_world
from .diskcache import RegionCache, resolve_cache
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
        disk_cache: bool | str | os.PathLike[str] | RegionCache | None = None,
    ) -> None:
        """``disk_cache``: where regions are looked up and stored (:mod:`.diskcache`):
        ``None`` (default) the folder from the environment (off with
        ``SENSORPLAN_GYM_CACHE=off``), ``False`` no disk cache, a folder path, or a
        :class:`~.diskcache.RegionCache`."""
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
        self.disk_cache = resolve_cache(disk_cache)
        self.entries: dict[int, tuple[World, Start]] = {}

    def __getstate__(self) -> dict[str, Any]:
        return self.__dict__.copy()

    def spec(self) -> ScenePool:
        """A copy of this pool without its built scenes (what worker processes receive)."""
        p = object.__new__(ScenePool)
        p.__dict__.update(self.__dict__)
        p.entries = {}
        return p

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
                world = get_world(Scene.from_dict(d), self.cfg, d, disk_cache=self.disk_cache)
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

    def build(self, jobs: int = 1) -> ScenePool:
        """Build every scene not built yet, now (e.g. before timing or training), in ``jobs``
        processes: ``1`` in this one; ``k > 1`` in ``k`` worker processes
        (:class:`concurrent.futures.ProcessPoolExecutor` with the platform's default start
        method; a script that calls this at top level needs the usual
        ``if __name__ == "__main__":`` guard where that method is ``spawn`` or
        ``forkserver``).  The worlds are the same as a serial build's (each worker draws
        scene ``k`` from the same stream) and are sent back pickled.  With ``jobs > 1`` the
        pool's ``check`` must be picklable (a module-level function or a
        :func:`functools.partial` of one, not a lambda).  In a daemonic process (a worker of
        gymnasium's ``AsyncVectorEnv``), which may not start processes, the build is serial
        (with a ``RuntimeWarning``).  Returns the pool."""
        check_jobs(jobs)
        todo = [k for k in range(self.size) if k not in self.entries]
        jobs = min(int(jobs), len(todo))
        if jobs > 1 and multiprocessing.current_process().daemon:
            warnings.warn(
                f"ScenePool.build(jobs={jobs}) in a daemonic process (e.g. a worker of "
                "gymnasium's AsyncVectorEnv), which cannot start worker processes: building "
                "serially",
                RuntimeWarning,
                stacklevel=2,
            )
            jobs = 1
        if jobs <= 1:
            for k in todo:
                self.get(k)
            return self
        try:
            payload = pickle.dumps(self.spec())
        except Exception as e:
            raise TypeError(
                f"build(jobs={jobs}) sends the pool to worker processes, but it cannot be "
                f"pickled ({e}); use a module-level check function (not a lambda) or jobs=1"
            ) from e
        with ProcessPoolExecutor(
            max_workers=jobs,
            mp_context=multiprocessing.get_context(),
            initializer=_worker_init,
            initargs=(payload,),
        ) as ex:
            for k, (entry, hits, misses) in zip(todo, ex.map(_worker_get, todo), strict=True):
                self.entries[k] = entry
                if self.disk_cache is not None:
                    self.disk_cache.hits += hits
                    self.disk_cache.misses += misses
        return self


def check_jobs(jobs: Any) -> int:
    """``jobs`` as an int, or a ``ValueError`` saying why it is not a positive integer."""
    if isinstance(jobs, bool) or not isinstance(jobs, (int, np.integer)) or jobs < 1:
        raise ValueError(f"jobs must be a positive integer (processes), got {jobs!r}")
    return int(jobs)


#: the pool a worker process of :meth:`ScenePool.build` builds scenes of
_WORKER_POOL: ScenePool | None = None


def _worker_init(payload: bytes) -> None:
    global _WORKER_POOL
    _WORKER_POOL = pickle.loads(payload)


def _worker_get(k: int) -> tuple[tuple[World, Start], int, int]:
    """Scene ``k`` of the worker's pool, and the disk-cache hits and misses it took."""
    pool = _WORKER_POOL
    assert pool is not None, "worker not initialised"
    c = pool.disk_cache
    h0, m0 = (c.hits, c.misses) if c is not None else (0, 0)
    e = pool.get(k)
    pool.entries.pop(k, None)  # sent back; the worker need not keep it
    h1, m1 = (c.hits, c.misses) if c is not None else (0, 0)
    return e, h1 - h0, m1 - m0


_POOLS: dict[str, ScenePool] = {}


def shared_pool(cfg: WorldConfig, check: Check, kind: str, **kw: Any) -> ScenePool:
    """The process-wide pool for these arguments (``kind`` names the validity check)."""
    key = json.dumps([repr(cfg), kind, {k: kw[k] for k in sorted(kw)}], default=repr)
    p = _POOLS.get(key)
    if p is None:
        p = _POOLS[key] = ScenePool(cfg, check, **kw)
    return p


__all__ += ["check_jobs", "shared_pool"]

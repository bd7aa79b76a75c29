"""Scene pools of polygonal G/H under the partial model: the parallel build
(``ScenePool.build(jobs=k)``, ``scene_pool_jobs=``) and the on-disk region cache
(:mod:`sensorplan_gym.core.diskcache`)."""

from __future__ import annotations

import functools

import gymnasium as gym
import numpy as np
import pytest
import shapely

import sensorplan_gym  # noqa: F401
import sensorplan_gym.core.world as world_mod
from geometry import Scene
from geometry.generate import random_scene
from sensorplan_gym.core.cache import clear_cache
from sensorplan_gym.core.diskcache import RegionCache, default_cache_dir, resolve_cache
from sensorplan_gym.core.pool import ScenePool
from sensorplan_gym.core.world import World, WorldConfig
from sensorplan_gym.envs.base import _check

#: small polygonal-G/H scenes (one obstacle, a triangle target): ~0.3 s per partial region
SMALL = {"goal": "polygon", "failure": "polygon", "n_obstacles": 1, "target_edges": 3}
PARTIAL = WorldConfig(model="partial")
CHECK = functools.partial(_check, needs_start=True)


def _pool(**kw) -> ScenePool:
    clear_cache()  # no world from an earlier build in memory (nor in forked workers)
    return ScenePool(PARTIAL, CHECK, size=4, seed=3, scene_kwargs=SMALL, **kw)


def _same_entries(a: ScenePool, b: ScenePool) -> None:
    assert sorted(a.entries) == sorted(b.entries) == list(range(a.size))
    for k in range(a.size):
        (wa, sa), (wb, sb) = a.entries[k], b.entries[k]
        assert wa.scene.to_dict() == wb.scene.to_dict(), k
        # bit-for-bit the same exact region
        assert shapely.to_wkb(wa.region) == shapely.to_wkb(wb.region), k
        assert not wa.region.is_empty
        assert sa == sb, k
        assert np.array_equal(wa.region_segs, wb.region_segs)


def test_parallel_env_pool_is_the_serial_pool(tmp_path):
    """``scene_pool_jobs=2`` builds the whole pool at construction in two processes, with the
    same scenes, regions and starts as a serial build (regions cached on disk, then read
    back by a fresh serial build)."""
    clear_cache()
    env = gym.make(
        "sensorplan/Recognize-v0",
        scene="random",
        model="partial",
        random_scene_kwargs=SMALL,
        scene_pool_size=4,
        scene_pool_seed=11,
        scene_pool_jobs=2,
        scene_pool_cache=tmp_path,
    )
    par = env.unwrapped.batch.source
    assert sorted(par.entries) == [0, 1, 2, 3]
    assert par.disk_cache.misses >= 4  # computed (in the workers: counts come back)
    env.reset(seed=0)
    serial = par.spec()
    serial.disk_cache = None
    clear_cache()
    _same_entries(par, serial.build(jobs=1))
    cached = par.spec()
    cached.disk_cache = RegionCache(tmp_path)
    clear_cache()
    _same_entries(par, cached.build())
    assert cached.disk_cache.hits >= 4 and cached.disk_cache.misses == 0


def test_disk_cache_round_trips_and_a_changed_scene_misses(tmp_path, monkeypatch):
    cache = RegionCache(tmp_path, min_seconds=0)
    d = random_scene(np.random.default_rng(5), **SMALL)
    w1 = World(Scene.from_dict(d), PARTIAL, disk_cache=cache)
    assert (cache.hits, cache.misses) == (0, 1)
    assert len(list(tmp_path.rglob("*.wkb"))) == 1

    # a hit does not compute: the geometry is not even called
    def boom(*a, **k):
        raise AssertionError("region computed despite a cached copy")

    monkeypatch.setattr(world_mod, "recognizable_region", boom)
    w2 = World(Scene.from_dict(d), PARTIAL, disk_cache=cache)
    assert cache.hits == 1
    assert shapely.to_wkb(w2.region) == shapely.to_wkb(w1.region)
    # a changed scene, or a changed configuration, is another key: computed, not read
    moved = dict(d, obstacles=[[[x + 1e-3, y] for x, y in ob] for ob in d["obstacles"]])
    with pytest.raises(AssertionError, match="despite a cached copy"):
        World(Scene.from_dict(moved), PARTIAL, disk_cache=cache)
    with pytest.raises(AssertionError, match="despite a cached copy"):
        World(Scene.from_dict(d), WorldConfig(model="partial", eps_pos=0.01), disk_cache=cache)
    assert RegionCache.key(d, model="partial") != RegionCache.key(moved, model="partial")
    monkeypatch.undo()
    # an unreadable file is a miss and is overwritten
    (f,) = tmp_path.rglob("*.wkb")
    f.write_bytes(b"not wkb")
    w3 = World(Scene.from_dict(d), PARTIAL, disk_cache=cache)
    assert shapely.to_wkb(w3.region) == shapely.to_wkb(w1.region)
    assert shapely.from_wkb(f.read_bytes()).equals_exact(w1.region, 0)


def test_cheap_regions_are_not_stored(tmp_path):
    cache = RegionCache(tmp_path, min_seconds=3600)
    d = random_scene(np.random.default_rng(5), **SMALL)
    World(Scene.from_dict(d), PARTIAL, disk_cache=cache)
    assert cache.misses == 1 and not list(tmp_path.rglob("*.wkb"))


def test_cache_location_and_opt_out(tmp_path, monkeypatch):
    monkeypatch.setenv("SENSORPLAN_GYM_CACHE", "off")
    assert default_cache_dir() is None and resolve_cache(None) is None
    monkeypatch.setenv("SENSORPLAN_GYM_CACHE", str(tmp_path / "c"))
    assert resolve_cache(None).directory == tmp_path / "c"
    monkeypatch.delenv("SENSORPLAN_GYM_CACHE")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert default_cache_dir() == tmp_path / "sensorplan-gym"
    assert resolve_cache(False) is None
    assert resolve_cache(tmp_path / "x").directory == tmp_path / "x"
    with pytest.raises(TypeError, match="disk_cache must be"):
        resolve_cache(3)
    with pytest.raises(ValueError, match="empty path"):
        resolve_cache("")
    with pytest.raises(ValueError, match="min_seconds"):
        RegionCache(tmp_path, min_seconds=-1)


@pytest.mark.parametrize("jobs", [0, -1, 1.5, True, "2", None])
def test_bad_jobs_is_a_clear_error(jobs):
    pool = ScenePool(WorldConfig(), CHECK, size=2, disk_cache=False)
    with pytest.raises(ValueError, match="jobs must be a positive integer"):
        pool.build(jobs=jobs)
    assert not pool.entries
    if jobs is None:  # the envs' default: scenes built on first use
        return
    with pytest.raises(ValueError, match="jobs must be a positive integer"):
        gym.make("sensorplan/Navigate-v0", scene="random", scene_pool_size=2, scene_pool_jobs=jobs)


def test_pool_kwargs_need_a_random_scene():
    with pytest.raises(ValueError, match="need scene='random'"):
        gym.make("sensorplan/Navigate-v0", scene="lab", scene_pool_jobs=2)
    with pytest.raises(ValueError, match="need scene='random'"):
        gym.make("sensorplan/Navigate-v0", scene="lab", scene_pool_cache=False)


def test_unpicklable_check_with_jobs_is_a_clear_error():
    pool = ScenePool(WorldConfig(), lambda w, r: _check(w, r, True), size=2, disk_cache=False)
    with pytest.raises(TypeError, match="cannot be pickled"):
        pool.build(jobs=2)
    assert pool.build(jobs=1).entries.keys() == {0, 1}


def test_a_daemonic_process_builds_serially(monkeypatch):
    """Workers of gymnasium's AsyncVectorEnv are daemonic and may not start processes."""
    import multiprocessing

    monkeypatch.setattr(multiprocessing.current_process(), "daemon", True)
    pool = ScenePool(WorldConfig(), CHECK, size=2, disk_cache=False)
    with pytest.warns(RuntimeWarning, match="building serially"):
        pool.build(jobs=2)
    assert pool.entries.keys() == {0, 1}

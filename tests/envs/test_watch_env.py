"""The watch task (issue 11): PettingZoo API, determinism, pickling, the exact "sees A"
reward against an independent CGAL visibility oracle, rendering, bad input."""

from __future__ import annotations

import math
import pickle

import gymnasium as gym
import numpy as np
import pytest
import shapely

from sensorplan_gym import watch_v0
from sensorplan_gym.core.world import BUNDLED_SCENES
from sensorplan_gym.multiagent.world import WatchConfig, WatchWorld

pz = None
try:
    import pettingzoo as pz  # noqa: F811
except ImportError:  # the "multi" extra is not installed
    pass
needs_pz = pytest.mark.skipif(pz is None, reason="pettingzoo (extra 'multi') not installed")


def _rollout(env, seed: int, n_steps: int | None = None, action_seed: int = 0):
    """Obs/reward/termination/info trace of an episode under seeded random actions."""
    rng = np.random.default_rng(action_seed)
    obs, infos = env.reset(seed=seed)
    trace = [(obs, infos)]
    k = 0
    while env.agents and (n_steps is None or k < n_steps):
        acts = {a: rng.uniform(-1, 1, 4).astype(np.float32) for a in env.agents}
        trace.append(env.step(acts))
        k += 1
    return trace


def _same(a, b) -> bool:
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, np.ndarray):
        return a.dtype == b.dtype and np.array_equal(a, b)
    return a == b


@needs_pz
@pytest.mark.parametrize("scene,n", [("lab", 1), ("edr", 2), ("corridor", 3)])
def test_parallel_api(scene, n):
    from pettingzoo.test import parallel_api_test

    parallel_api_test(watch_v0.parallel_env(scene=scene, n_watchers=n, max_steps=40, move_steps=20))


@needs_pz
def test_aec_api_and_seed():
    from pettingzoo.test import api_test, parallel_seed_test, seed_test

    api_test(watch_v0.env(scene="lab", n_watchers=2, max_steps=30, move_steps=15), num_cycles=100)
    parallel_seed_test(
        lambda: watch_v0.parallel_env(scene="warehouse", n_watchers=2, max_steps=30, move_steps=15),
        num_cycles=100,
    )
    seed_test(lambda: watch_v0.env(scene="edr", n_watchers=2, max_steps=30, move_steps=15), 100)


def test_determinism_per_seed_and_seeds_differ():
    env = watch_v0.parallel_env(scene="lab", n_watchers=2)
    a = _rollout(env, seed=3)
    b = _rollout(watch_v0.parallel_env(scene="lab", n_watchers=2), seed=3)
    assert _same(a, b)
    c = _rollout(env, seed=4)
    assert not _same(a[0][0], c[0][0])
    assert len(a) == env.max_steps + 1  # the fixed horizon


def test_pickle_mid_episode_continues_identically():
    env = watch_v0.parallel_env(scene="edr", n_watchers=2, noise=0.01, render_mode="rgb_array")
    _rollout(env, seed=5, n_steps=20)
    env.render()  # a drawn figure must not break pickling
    clone = pickle.loads(pickle.dumps(env))
    rng1, rng2 = np.random.default_rng(9), np.random.default_rng(9)
    while env.agents:
        acts1 = {a: rng1.uniform(-1, 1, 4) for a in env.agents}
        acts2 = {a: rng2.uniform(-1, 1, 4) for a in clone.agents}
        assert _same(env.step(acts1), clone.step(acts2))
    assert not clone.agents


def test_episode_structure_and_outcome_hidden():
    env = watch_v0.parallel_env(scene="lab", n_watchers=2, p_fail=0.5)
    outcomes = set()
    for seed in range(12):
        obs, infos = env.reset(seed=seed)
        assert all("a_ends_in" not in i and "is_success" not in i for i in infos.values())
        # the observation is a function of what the watchers may know: flipping the hidden
        # outcome changes none of it
        before = {a: env._observe(i) for i, a in enumerate(env.agents)}
        true = env.traj.outcome
        env.traj.outcome = "H" if true == "G" else "G"
        after = {a: env._observe(i) for i, a in enumerate(env.agents)}
        env.traj.outcome = true
        assert _same(before, after)
        outcomes.add(true)
        # A ends in G or H, as the EDR plan guarantees, and it rests there after move_steps
        end = env.traj.at(env.move_steps)
        region = env.world.goal_geom if true == "G" else env.world.failure_geom
        assert region.distance(shapely.Point(end)) < 1e-9
        # every configuration of A on the way keeps its hull in the free space
        for q in env.traj.pos:
            hull = shapely.Polygon(env.world.hull + q)
            assert env.world.free_space.buffer(1e-9).covers(hull)
    assert outcomes == {"G", "H"}


def test_declarations_and_rewards():
    env = watch_v0.parallel_env(scene="lab", n_watchers=2, see_reward=0.01)
    obs, _ = env.reset(seed=1)
    truth = env.traj.outcome
    wrong = "H" if truth == "G" else "G"
    code = {"G": -1.0, "H": 1.0}
    acts = {
        "watcher_0": np.array([0, 0, 0, code[truth]], dtype=np.float32),
        "watcher_1": np.array([0, 0, 0, code[wrong]], dtype=np.float32),
    }
    obs, rew, term, trunc, info = env.step(acts)
    see = [0.01 * info[a]["sees"] for a in env.agents]
    assert rew["watcher_0"] == pytest.approx(1.0 + see[0])
    assert rew["watcher_1"] == pytest.approx(-1.0 + see[1])
    assert obs["watcher_0"][8 + 4 * 16 + 2] == code[truth]  # own declaration is observed
    # later declarations are ignored; nobody is rewarded again for declaring
    while env.agents:
        obs, rew, term, trunc, info = env.step(
            {a: np.array([0, 0, 0, code[wrong]], dtype=np.float32) for a in env.agents}
        )
        for a in rew:
            assert rew[a] == pytest.approx(0.01 * info[a]["sees"])
    assert info["watcher_0"]["is_success"] and not info["watcher_1"]["is_success"]
    assert all(term.values()) and not any(trunc.values())
    # an undeclared watcher pays -1 at the horizon; team mode shares one reward
    env = watch_v0.parallel_env(scene="lab", n_watchers=2, reward="team", max_steps=3, move_steps=2)
    env.reset(seed=2)
    for _ in range(3):
        obs, rew, term, trunc, info = env.step({a: np.zeros(4) for a in env.agents})
        assert rew["watcher_0"] == rew["watcher_1"]
    anyone = any(i["sees"] for i in info.values())
    assert rew["watcher_0"] == pytest.approx(0.01 * anyone - 1.0)


def test_bad_input():
    with pytest.raises(ValueError, match="n_watchers"):
        watch_v0.parallel_env(n_watchers=0)
    with pytest.raises(ValueError, match="move_steps"):
        watch_v0.parallel_env(max_steps=10, move_steps=10)
    with pytest.raises(ValueError, match="reward"):
        watch_v0.parallel_env(reward="selfish")
    with pytest.raises(ValueError, match="model"):
        watch_v0.parallel_env(model="weak")
    with pytest.raises(ValueError, match="p_fail"):
        watch_v0.parallel_env(p_fail=1.5)
    with pytest.raises(ValueError, match="unknown scene"):
        watch_v0.parallel_env(scene="nowhere")
    env = watch_v0.parallel_env(n_watchers=2)
    env.reset(seed=0)
    with pytest.raises(ValueError, match="no action for live agent 'watcher_1'"):
        env.step({"watcher_0": np.zeros(4)})
    with pytest.raises(ValueError, match="shape"):
        env.step({"watcher_0": np.zeros(3), "watcher_1": np.zeros(4)})
    with pytest.raises(ValueError, match="NaN"):
        env.step({"watcher_0": np.full(4, np.nan), "watcher_1": np.zeros(4)})


def test_gym_id_single_watcher():
    from gymnasium.utils.env_checker import check_env

    env = gym.make("sensorplan_gym:sensorplan/Watch-v0", scene="edr")
    check_env(env.unwrapped, skip_render_check=True)
    obs, info = env.reset(seed=0)
    assert obs.shape == env.observation_space.shape == (8 + 4 * 16 + 3,)
    done, n = False, 0
    while not done:
        obs, r, term, trunc, info = env.step(env.action_space.sample())
        done, n = term or trunc, n + 1
    assert n == 100 and term and "visible_fraction" in info
    with pytest.raises(ValueError, match="exactly one watcher"):
        gym.make("sensorplan_gym:sensorplan/Watch-v0", n_watchers=2)


def test_rgb_array_frames():
    env = watch_v0.parallel_env(scene="edr", n_watchers=2, render_mode="rgb_array")
    env.reset(seed=0)
    f0 = env.render()
    assert f0.shape == (480, 480, 3) and f0.dtype == np.uint8
    for _ in range(5):
        env.step({a: np.array([1, 0, 0.3, 0], dtype=np.float32) for a in env.agents})
    f1 = env.render()
    assert f1.shape == f0.shape and not np.array_equal(f0, f1)  # A and the watchers moved
    assert watch_v0.parallel_env(scene="lab").render() is None  # no render_mode


# ---- the exact "sees A" predicate against an independent CGAL oracle ---------------------


def _independent_sees(oracle, world, pose, q, tol):
    """Sees-A from CGAL's V(p) and plain shapely: ``True``/``False``, or ``None`` when the
    answer changes within ``tol`` (A grown or shrunk by tol, the aim turned by tol/dist)."""
    from tests.oracle import sees_completely, sees_partially

    x, y, psi = pose
    A = shapely.Polygon(world.target + q)
    if A.distance(shapely.Point(x, y)) <= tol:
        return None
    V = oracle.visibility((x, y))
    answers = set()
    for grow in (-tol, tol):
        Ag = A.buffer(grow, join_style="mitre")
        d = np.hypot(*(np.asarray(Ag.exterior.coords) - (x, y)).T)
        for turn in (-1, 1):
            p2 = psi + turn * tol / max(float(d.min()), tol)
            if world.fov < 2 * math.pi - 1e-12:
                R = 10 * world.diameter
                ang = p2 + np.linspace(-world.fov / 2, world.fov / 2, 64)
                wedge = shapely.Polygon(
                    [(x, y), *zip(x + R * np.cos(ang), y + R * np.sin(ang), strict=True)]
                )
            else:
                wedge = None
            if world.model == "complete":
                ok = sees_completely(oracle, (x, y), Ag, vis=V)
                if wedge is not None:
                    ok = ok and shapely.difference(Ag, wedge).area <= 1e-12
                ok = ok and float(d.max()) <= world.max_range
            else:
                part = shapely.intersection(Ag, V)
                if wedge is not None:
                    part = shapely.intersection(part, wedge)
                ok = sees_partially(oracle, (x, y), part, vis=V) and (
                    part.distance(shapely.Point(x, y)) <= world.max_range
                )
            answers.add(bool(ok))
    return answers.pop() if len(answers) == 1 else None


@pytest.mark.parametrize("model", ["complete", "partial"])
@pytest.mark.parametrize("scene", BUNDLED_SCENES)
def test_sees_matches_cgal(scene, model):
    pytest.importorskip("pyvispoly")
    from tests.oracle import VisOracle

    env = watch_v0.parallel_env(scene=scene, n_watchers=1, model=model)
    rng = np.random.default_rng(11)
    oracle = VisOracle(env.world.scene)
    counts = {True: 0, False: 0, None: 0}
    tol = 1e-6 * env.world.diameter
    configs = [(None, None), (150.0, None), (300.0, 0.4 * env.world.diameter)]
    for fov, rng_max in configs:
        w = WatchWorld(
            env.world.scene,
            WatchConfig(
                model=model,
                fov=None if fov is None else math.radians(fov),
                max_range=rng_max,
            ),
        )
        for _ep in range(2):
            env.reset(seed=int(rng.integers(1 << 30)))
            for t in range(0, env.move_steps + 1, 7):
                q = env.traj.at(t)
                for _ in range(4):
                    x, y, _ = env._draw_pose(rng, [], avoid_a=False)
                    # aim at A half the time, so that both answers occur under a narrow view
                    c = (w.target + q).mean(axis=0)
                    psi = (
                        math.atan2(c[1] - y, c[0] - x) + rng.normal(0, 0.3)
                        if rng.random() < 0.5
                        else rng.uniform(-math.pi, math.pi)
                    )
                    ref = _independent_sees(oracle, w, (x, y, psi), q, tol)
                    counts[ref] += 1
                    if ref is not None:
                        assert w.sees((x, y, psi), q) == ref, (scene, model, fov, (x, y, psi), q)
    assert counts[True] >= 20 and counts[False] >= 20, counts
    assert counts[None] <= 0.05 * (counts[True] + counts[False]), counts


@pytest.mark.parametrize("scene", ["lab", "edr"])
def test_sees_matches_region_functions(scene):
    """Full view, unlimited range: sees-A is membership of p in the paper's region for A at
    its current configuration (``complete_region`` / ``partial_region`` with target_at)."""
    from geometry import complete_region, partial_region

    rng = np.random.default_rng(2)
    for model, fn in (("complete", complete_region), ("partial", partial_region)):
        env = watch_v0.parallel_env(scene=scene, model=model, fov_deg=360, max_range=math.inf)
        env.reset(seed=7)
        w = env.world
        n = {True: 0, False: 0}
        for t in (0, 20, 50):
            q = env.traj.at(t)
            R = fn(w.scene, target_at=(float(q[0]), float(q[1]), 0.0))
            for _ in range(60):
                x, y, _ = env._draw_pose(rng, [], avoid_a=False)
                if R.boundary.distance(shapely.Point(x, y)) < 1e-6 * w.diameter:
                    continue
                inside = bool(R.contains(shapely.Point(x, y)))
                assert w.sees((x, y, rng.uniform(-3, 3)), q) == inside, (model, t, x, y)
                n[inside] += 1
        assert n[True] > 10 and n[False] > 10, n

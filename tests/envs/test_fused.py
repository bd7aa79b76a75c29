"""The fused compiled step (``sensorplan_gym.core.fused``) and the compiled resets
(``sensorplan_gym.core.targets``):

* the compiled region test answers exactly as shapely's ``contains_xy`` on the exact region
  (boundary points outside) on every bundled scene and a fuzzed pool -- random points,
  vertices, points on edges and next to them;
* its orientation predicate is exact (a rational-arithmetic oracle on nearly collinear
  triples);
* whole episodes through the compiled kernels equal the numpy path bitwise (in-process, the
  ``fused`` switch) and the numpy fallback without numba (a subprocess with
  ``SENSORPLAN_NO_NUMBA=1``), noise and uncertainties on, for every env.
"""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys

import gymnasium as gym
import numpy as np
import pytest
import shapely

import sensorplan_gym  # noqa: F401
from sensorplan_gym.core import fused
from sensorplan_gym.core.cache import get_world
from sensorplan_gym.core.segments import boundary_segments
from sensorplan_gym.core.world import BUNDLED_SCENES, WorldConfig, load_scene

needs_numba = pytest.mark.skipif(not fused.FUSED, reason="numba not installed (the 'fast' extra)")
NOISY = {"noise": 0.05, "eps_pos": 0.05, "eps_aim": 0.02}


def _probe_points(geom, lo, hi, rng, n=4000) -> np.ndarray:
    """Random points over the box, every vertex, points on every edge (interpolated, so
    some land exactly on it and some a rounding off it) and points 1e-12 from the edges."""
    pts = [rng.uniform(np.asarray(lo) - 0.1, np.asarray(hi) + 0.1, (n, 2))]
    segs = boundary_segments(geom)
    if len(segs):
        a, b = segs[:, None, :2], segs[:, None, 2:]
        t = rng.random((len(segs), 20))
        t[:, :3] = (0.0, 0.5, 0.25)  # exact midpoints and quarter points
        on = (a + t[..., None] * (b - a)).reshape(-1, 2)
        pts += [segs[:, :2], on, on + rng.normal(0.0, 1e-12, on.shape)]
        # horizontal and vertical probes through the vertices (ray-crossing corner cases)
        v = segs[:, :2]
        pts += [v + [1e-9, 0.0], v - [1e-9, 0.0], v + [0.0, 1e-9], v - [0.0, 1e-9]]
    return np.concatenate(pts)


def _compiled_contains(geom, pts: np.ndarray) -> np.ndarray:
    segs = boundary_segments(geom)
    R = np.ascontiguousarray(segs.T[:, None, :]) if len(segs) else np.full((4, 1, 1), 1e15)
    out = np.empty(len(pts), dtype=bool)
    x, y = np.ascontiguousarray(pts[:, 0]), np.ascontiguousarray(pts[:, 1])
    fused.region_test(x, y, R, np.zeros(len(pts), dtype=np.intp), out)
    return out


CONFIGS = [
    WorldConfig(),
    WorldConfig(model="partial", motion="stationary"),
    WorldConfig(fov=2.0, eps_pos=0.05, eps_aim=0.02),
    WorldConfig(motion="rotating"),
]


@needs_numba
@pytest.mark.parametrize("scene", BUNDLED_SCENES)
def test_region_test_is_shapely_contains_on_bundled_scenes(scene):
    rng = np.random.default_rng(len(scene))
    checked = 0
    for cfg in CONFIGS:
        try:
            w = get_world(load_scene(scene), cfg)
        except NotImplementedError:
            continue
        for geom in (w.region, w.robot_space):
            pts = _probe_points(geom, w.lo, w.hi, rng)
            ref = shapely.contains_xy(geom, pts[:, 0], pts[:, 1])
            got = _compiled_contains(geom, pts)
            assert np.array_equal(got, ref), (scene, cfg, np.flatnonzero(got != ref)[:5])
            assert ref.any() and not ref.all()
            checked += 1
    assert checked >= 6


@needs_numba
def test_region_test_is_shapely_contains_on_a_fuzzed_pool():
    """Regions of procedural scenes, and random polygons with holes (multi-part, collinear
    and axis-parallel edges), probed on and around their boundaries."""
    from sensorplan_gym.core.pool import ScenePool
    from sensorplan_gym.envs.base import _check

    pool = ScenePool(WorldConfig(), lambda w, r: _check(w, r, True), size=12, seed=7).build()
    geoms = [pool.get(k)[0].region for k in range(pool.size)]
    rng = np.random.default_rng(3)
    for _ in range(25):
        pts = rng.uniform(0, 10, (8, 2))
        blob = shapely.MultiPoint(pts).buffer(rng.uniform(0.5, 2.0), quad_segs=3)
        box = shapely.box(*rng.uniform(2, 4, 2), *rng.uniform(6, 8, 2))
        hole = shapely.box(*rng.uniform(4, 4.5, 2), *rng.uniform(5, 5.5, 2))
        geoms.append(shapely.union(blob, box).difference(hole))
    for g in geoms:
        shapely.prepare(g)
        lo, hi = np.array(g.bounds[:2]), np.array(g.bounds[2:])
        pts = _probe_points(g, lo, hi, rng, n=2000)
        ref = shapely.contains_xy(g, pts[:, 0], pts[:, 1])
        assert np.array_equal(_compiled_contains(g, pts), ref)
    empty = _compiled_contains(shapely.Polygon(), rng.uniform(0, 1, (50, 2)))
    assert not empty.any()


@needs_numba
def test_orientation_is_exact_on_nearly_collinear_triples():
    rng = np.random.default_rng(0)
    got = exp = zero = 0
    for _ in range(3000):
        p1, p2 = rng.uniform(-10, 10, (2, 2))
        t = rng.choice([0.5, 0.25, rng.random(), 2.0, -1.0])
        q = p1 + t * (p2 - p1)  # on the line, up to rounding
        if rng.random() < 0.3:
            q = q + rng.choice([-1, 1]) * np.spacing(q) * rng.integers(0, 3, 2)
        args = (*p1, *p2, *q)
        s = fused.orient_sign(*args)
        e = fused._py_orient_exact(*(float(v) for v in args))
        got += s == e
        exp += 1
        zero += e == 0
    assert got == exp and zero > 50


def _episodes(env_id: str, steps: int, fused_on: bool, n: int = 3, **kw):
    """Observations, rewards, flags and infos of a batch of ``n`` driven by fixed random
    actions (Recognize declares now and then), resets included."""
    venv = gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point", **kw)
    venv.unwrapped.batch.fused = fused_on
    obs, info = venv.reset(seed=21)
    rng = np.random.default_rng(5)
    out = [obs.tobytes(), repr(sorted((k, np.asarray(v).tolist()) for k, v in info.items()))]
    for _ in range(steps):
        if kw.get("action_type") == "discrete":
            a = rng.integers(0, venv.single_action_space.n, n)
            a[rng.random(n) > 0.04] %= 7  # declare now and then
        else:
            a = rng.uniform(-1, 1, venv.action_space.shape).astype(np.float32)
            if a.shape[1] == 4:
                a[:, 3] = np.where(rng.random(n) < 0.04, np.sign(a[:, 3]), 0.0)
        obs, r, te, tr, info = venv.step(a)
        out += [obs.tobytes(), r.tobytes(), te.tobytes(), tr.tobytes()]
        out.append(repr(sorted((k, np.asarray(v).tolist()) for k, v in info.items())))
    return out


CASES = [
    ("sensorplan/Navigate-v0", {}),
    ("sensorplan/Navigate-v0", {**NOISY, "fov_deg": 120, "map_ranges": True}),
    ("sensorplan/Navigate-v0", {**NOISY, "max_range": 2.5}),  # beams that hit nothing
    ("sensorplan/Navigate-v0", {"scene": "edr", "shaping": 1.0, "speed_limit": "disc"}),
    ("sensorplan/Recognize-v0", {**NOISY, "map_evidence": True, "sensor_fov": True}),
    ("sensorplan/Recognize-v0", {"motion": "rotating", "random_start": True, "shaping": 0.5}),
    ("sensorplan/Recognize-v0", {"scene": "random", "scene_pool_size": 4, **NOISY}),
    ("sensorplan/Recognize-v0", {"model": "partial", "motion": "stationary"}),
    ("sensorplan/Placement-v0", {**NOISY, "fov_deg": 90}),
    ("sensorplan/Placement-v0", {"scene": "random", "scene_pool_size": 3, **NOISY}),
    # a disc robot: the drive stays numpy (the capsule sweep), the rest compiled
    ("sensorplan/Recognize-v0", {"robot_radius": 0.1, **NOISY, "action_type": "discrete"}),
]


@needs_numba
@pytest.mark.parametrize("env_id,kw", CASES)
def test_compiled_step_equals_numpy_path(env_id, kw):
    steps = 240 if "Placement" not in env_id else 20
    a = _episodes(env_id, steps, True, **kw)
    b = _episodes(env_id, steps, False, **kw)
    assert len(a) == len(b)
    bad = [k for k, (u, v) in enumerate(zip(a, b, strict=True)) if u != v]
    assert not bad, f"first difference at record {bad[0]}"


def _digest(env_id: str, kw: dict, steps: int) -> str:
    h = hashlib.sha256()
    for rec in _episodes(env_id, steps, fused.FUSED, **kw):
        h.update(rec if isinstance(rec, bytes) else rec.encode())
    return h.hexdigest()


@needs_numba
def test_numpy_fallback_without_numba_gives_the_same_episodes():
    """The whole package without numba (the numpy kernels, the pure-Python target
    placement) reproduces the compiled episodes bit for bit."""
    cases = [CASES[1], CASES[2], CASES[4], CASES[5], CASES[8], CASES[10]]
    steps = 120
    code = (
        "import json, sys; from tests.envs.test_fused import _digest; "
        "cases = json.loads(sys.argv[1]); "
        "print(json.dumps([_digest(e, k, int(sys.argv[2])) for e, k in cases]))"
    )
    env = dict(os.environ, SENSORPLAN_NO_NUMBA="1")
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    out = subprocess.run(
        [sys.executable, "-c", code, json.dumps(cases), str(steps)],
        env=env,
        cwd=root,
        capture_output=True,
        text=True,
        check=True,
    )
    fallback = json.loads(out.stdout.strip().splitlines()[-1])
    assert fallback == [_digest(e, k, steps) for e, k in cases]


@pytest.mark.parametrize("env_id", ["sensorplan/Navigate-v0", "sensorplan/Recognize-v0"])
def test_sub_env_equals_single_env_on_a_scene_pool(env_id):
    """Worlds copied from per-world snapshots (a pool of 3 scenes, many resets) give each
    sub-environment exactly the single env's episodes (NEXT_STEP autoresets)."""
    n = 3
    kw = dict(scene="random", scene_pool_size=3, max_steps=25, **NOISY)
    venv = gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point", **kw)
    singles = [gym.make(env_id, **kw) for _ in range(n)]
    obs, _ = venv.reset(seed=4)
    for i, e in enumerate(singles):
        assert np.array_equal(obs[i], e.reset(seed=4 + i)[0])
    rng = np.random.default_rng(2)
    done = [False] * n
    ends = 0
    for _ in range(150):
        a = rng.uniform(-1, 1, venv.action_space.shape).astype(np.float32)
        if a.shape[1] == 4:
            a[:, 3] = np.where(rng.random(n) < 0.1, np.sign(a[:, 3]), 0.0)
        obs, rew, term, trunc, _ = venv.step(a)
        for i, e in enumerate(singles):
            if done[i]:
                o, r, te, tr = (*e.reset()[:1], 0.0, False, False)
            else:
                o, r, te, tr, _ = e.step(a[i])
            assert np.array_equal(o, obs[i]) and (r, te, tr) == (rew[i], term[i], trunc[i])
            done[i] = te or tr
            ends += done[i]
    worlds = {id(w) for w in venv.unwrapped.batch.worlds}
    assert ends >= 9 and len(venv.unwrapped.batch._snap.keep) >= 2 and worlds

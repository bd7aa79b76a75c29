"""The watch task on the batched core (issue 23): copy ``e`` of a batch equals
``watch_v0.parallel_env`` seeded ``s + e`` (whole episodes, noise and narrow views on); the
numpy fallback answers bitwise as the compiled kernels; the compiled "sees A" filter agrees
with the exact shapely predicate wherever it answers; the casts from inside A; the vector
env's API."""

from __future__ import annotations

import hashlib
import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest
import shapely

from sensorplan_gym import watch_v0
from sensorplan_gym.core.kernels import HAVE_NUMBA
from sensorplan_gym.core.sensor import Segments, cast_batch
from sensorplan_gym.multiagent import WatchBatch
from sensorplan_gym.multiagent import kernels as wk

CONFIGS = [
    dict(scene="edr", n_watchers=2, noise=0.05, fov_deg=120, max_range=6.0),
    dict(scene="lab", n_watchers=3, reward="team", noise=0.02),
    dict(scene="corridor", n_watchers=1, robot_radius=0.15, fov_deg=200),
    dict(scene="warehouse", n_watchers=2, model="partial", max_steps=30, move_steps=15),
]


def _acts(rng, n):
    a = rng.uniform(-1, 1, (n, 4)).astype(np.float32)
    a[:, 3] = np.where(rng.random(n) < 0.02, np.sign(a[:, 3]), 0.0)  # declare rarely
    return a


@pytest.mark.parametrize("cfg", CONFIGS, ids=lambda c: f"{c['scene']}-{c['n_watchers']}")
def test_copy_of_batch_equals_parallel_env(cfg):
    """Copy e of the vector env seeded s equals the parallel env seeded s + e, step for step
    over two whole episodes each (the second after the vector env's autoreset)."""
    E, A = 3, cfg["n_watchers"]
    venv = watch_v0.vector_env(E, **cfg)
    singles = [watch_v0.parallel_env(**cfg) for _ in range(E)]
    obs, info = venv.reset(seed=21)
    for e, env in enumerate(singles):
        o, inf = env.reset(seed=21 + e)
        for a, name in enumerate(env.possible_agents):
            assert np.array_equal(o[name], obs[e * A + a])
            assert inf[name]["sees"] == info["sees"][e * A + a]
    H = singles[0].max_steps
    rng = np.random.default_rng(0)
    finals = 0
    for step in range(2 * H + 1):
        act = _acts(rng, E * A)
        obs, rew, term, trunc, info = venv.step(act)
        assert not trunc.any()
        for e, env in enumerate(singles):
            rows = slice(e * A, (e + 1) * A)
            if not env.agents:  # the vector env reset this copy (NEXT_STEP)
                o, _ = env.reset()
                assert not term[rows].any() and (rew[rows] == 0).all()
                for a, name in enumerate(env.possible_agents):
                    assert np.array_equal(o[name], obs[e * A + a])
                continue
            o, r, te, tr, inf = env.step({n: act[e * A + a] for a, n in enumerate(env.agents)})
            for a, name in enumerate(env.possible_agents):
                i = e * A + a
                assert np.array_equal(o[name], obs[i]), (step, e, a)
                assert r[name] == rew[i]
                assert te[name] == term[i]
                assert inf[name]["sees"] == info["sees"][i]
                assert inf[name]["collided"] == info["collided"][i]
                assert inf[name]["pose"] == venv.batch.pose(i)
                if te[name]:
                    finals += 1
                    assert info["_is_success"][i]
                    assert inf[name]["is_success"] == info["is_success"][i]
                    assert inf[name]["visible_fraction"] == info["visible_fraction"][i]
    assert finals == 2 * E * A


def _run_batch(cfg, fused: bool, steps: int):
    b = WatchBatch(2, **cfg)
    b.fused = fused
    idx = np.arange(2)
    for e in range(2):
        b.seed_env(e, 5 + e)
    b.reset_envs(idx)
    rng = np.random.default_rng(3)
    trace = [(b.observe(idx), b.P.copy(), b.sees.copy())]
    for _ in range(steps):
        act = b.check_actions(_acts(rng, b.n), b.n)
        rew, done, _ = b.step_envs(act, idx)
        trace.append((b.observe(idx), b.P.copy(), b.sees.copy(), rew, b.scan_dist.copy(),
                      b.scan_normal.copy(), b.map_dist.copy(), b.collided.copy()))  # fmt: skip
        if done.any():
            b.reset_envs(idx[done])
    return trace, b


@pytest.mark.skipif(not HAVE_NUMBA, reason="numba not installed: only the numpy path exists")
@pytest.mark.parametrize("cfg", CONFIGS[:3], ids=lambda c: c["scene"])
def test_numpy_fallback_is_bitwise_equal(cfg):
    steps = 130
    fast, bf = _run_batch(cfg, True, steps)
    slow, bs = _run_batch(cfg, False, steps)
    assert len(fast) == len(slow)
    for k, (x, y) in enumerate(zip(fast, slow, strict=True)):
        for u, v in zip(x, y, strict=True):
            assert u.dtype == v.dtype and np.array_equal(u, v), k
    # the filter answered most "sees A" questions itself (numpy asks shapely every time)
    assert bf.n_exact_sees < 0.2 * bs.n_exact_sees


def _digest(cfg: dict, steps: int) -> str:
    """A hash of every observation, reward, pose and "sees" of a vector env run."""
    venv = watch_v0.vector_env(2, **cfg)
    h = hashlib.sha256()
    obs, _ = venv.reset(seed=8)
    h.update(obs.tobytes())
    rng = np.random.default_rng(1)
    for _ in range(steps):
        obs, rew, term, _, info = venv.step(_acts(rng, venv.num_envs))
        for a in (obs, rew, term, info["sees"], venv.batch.P):
            h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


@pytest.mark.skipif(not HAVE_NUMBA, reason="numba not installed: only the numpy path exists")
def test_without_numba_the_same_episodes():
    """The whole package without numba (SENSORPLAN_NO_NUMBA=1: numpy kernels, shapely for
    every visibility question) reproduces the compiled episodes bit for bit."""
    cases, steps = CONFIGS[:2], 110
    code = (
        "import json, sys; from tests.envs.test_watch_batch import _digest; "
        "print(json.dumps([_digest(c, int(sys.argv[2])) for c in json.loads(sys.argv[1])]))"
    )
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    out = subprocess.run(
        [sys.executable, "-c", code, json.dumps(cases), str(steps)],
        env=dict(os.environ, SENSORPLAN_NO_NUMBA="1"),
        cwd=root,
        capture_output=True,
        text=True,
        check=True,
    )
    assert json.loads(out.stdout.strip().splitlines()[-1]) == [_digest(c, steps) for c in cases]


@pytest.mark.skipif(not HAVE_NUMBA, reason="the compiled filter needs numba")
@pytest.mark.parametrize("scene", ["lab", "edr", "corridor", "warehouse"])
def test_sees_filter_agrees_with_exact_predicate(scene):
    """Wherever the compiled filter answers, it answers as WatchWorld.sees (shapely, exact);
    it leaves only a few cases to the predicate."""
    rng = np.random.default_rng(4)
    counts = {wk.SEES_NO: 0, wk.SEES_YES: 0, wk.UNSURE: 0}
    for fov, mr in ((None, None), (100.0, None), (360.0, 5.0), (220.0, 8.0)):
        b = WatchBatch(1, scene, fov_deg=fov, max_range=mr)
        w = b.world
        b.reset_envs(np.zeros(1, dtype=np.int64))
        for _ in range(6):
            t = int(rng.integers(0, b.move_steps + 1))
            q = b.trajs[0].at(t)
            b.Q[0] = q
            b._set_a(np.zeros(1, dtype=np.int64))
            for _ in range(40):
                x, y, _ = b.draw_pose(rng, [], None)
                c = (w.target + q).mean(axis=0)
                psi = (
                    math.atan2(c[1] - y, c[0] - x) + rng.normal(0, 0.4)
                    if rng.random() < 0.6
                    else rng.uniform(-math.pi, math.pi)
                )
                inside = bool(shapely.contains_xy(shapely.Polygon(w.target + q), x, y))
                code = wk.sees_filter(x, y, psi, inside, q[0], q[1], b._tgt, b._hull, b.SS,
                                      b.prm, b._HP)  # fmt: skip
                counts[code] += 1
                if code != wk.UNSURE:
                    assert (code == wk.SEES_YES) == w.sees((x, y, psi), q), (scene, fov, mr)
    assert counts[wk.SEES_YES] >= 30 and counts[wk.SEES_NO] >= 30, counts
    assert counts[wk.UNSURE] <= 0.02 * sum(counts.values()), counts


@pytest.mark.parametrize("fused", [True, False])
def test_cast_from_inside_a_matches_unculled_cast(fused):
    """A watcher that A has moved over reads A's edges from inside (as an unculled cast
    against the map's and A's edges does), and the map's prediction ignores A."""
    if fused and not HAVE_NUMBA:
        pytest.skip("numba not installed")
    b = WatchBatch(1, "lab", n_watchers=2)
    b.fused = fused
    idx = np.zeros(1, dtype=np.int64)
    b.seed_env(0, 1)
    b.reset_envs(idx)
    q = b.Q[0]
    P = b.world.target_at(q)
    c = P.mean(axis=0)
    b.P[:, 0] = (c[0], c[1], 0.3)  # inside A
    b._move_sense(idx, None)
    assert b.inside[0] and not b.inside[1] and not b.sees[0]
    segs = np.concatenate([P, np.roll(P, -1, axis=0)], axis=1)
    allsegs = b.world.seg_set + Segments(segs)
    for i in range(2):
        x, y, psi = b.P[:, i]
        ang = (b.sensor.offsets + psi)[None, :]
        d, nrm, hit = cast_batch(np.array([x]), np.array([y]), ang, allsegs, b.world.reach)
        np.testing.assert_allclose(b.scan_dist[i], d[0], rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(b.scan_normal[i], nrm[0], atol=1e-12)
        assert np.array_equal(b.scan_hit[i], hit[0])
        dm, _, _ = cast_batch(np.array([x]), np.array([y]), ang, b.world.seg_set, b.world.reach)
        np.testing.assert_allclose(b.map_dist[i], dm[0], rtol=1e-12, atol=1e-12)
    assert (b.scan_dist[0] < 0.1 * b.world.diameter).all()  # A's own edges, from inside


def test_vector_env_api():
    from gymnasium.vector import AutoresetMode

    venv = watch_v0.vector_env(4, scene="edr", n_watchers=2, max_steps=6, move_steps=3)
    assert venv.num_envs == 8 and venv.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    assert venv.observation_space.shape == (8, 8 + 4 * 16 + 3 + 2)
    obs, info = venv.reset(seed=[1, 2, 3, 4])
    assert obs.shape == venv.observation_space.shape and obs.dtype == np.float32
    assert venv.observation_space.contains(obs)
    single = watch_v0.parallel_env(scene="edr", n_watchers=2, max_steps=6, move_steps=3)
    o, _ = single.reset(seed=3)
    assert np.array_equal(o["watcher_1"], obs[5])
    for k in range(6):
        obs, rew, term, trunc, info = venv.step(np.zeros((8, 4), dtype=np.float32))
        assert term.all() == (k == 5)
    assert (rew == rew[0] + 0 * rew).shape == (8,) and "_is_success" in info
    assert info["_is_success"].all() and not info["is_success"].any()  # nobody declared
    obs, rew, term, trunc, info = venv.step(np.zeros((8, 4)))  # the autoreset step
    assert not term.any() and (rew == 0).all() and (obs[:, 8 + 4 * 16] == 0).all()
    before = venv.batch.t.copy()
    venv.reset(options={"reset_mask": np.array([True, False, False, False])})
    assert venv.batch.t[0] == 0 and (venv.batch.t[1:] == before[1:]).all()
    with pytest.raises(ValueError, match="NaN"):
        venv.step(np.full((8, 4), np.nan))
    with pytest.raises(ValueError, match="shape"):
        venv.step(np.zeros((7, 4)))
    with pytest.raises(ValueError, match="reset_mask"):
        venv.reset(options={"reset_mask": np.ones(8, dtype=bool)})
    with pytest.raises(ValueError, match="n_envs"):
        watch_v0.vector_env(0)


@pytest.mark.skipif(not HAVE_NUMBA, reason="the compiled visibility test needs numba")
@pytest.mark.parametrize("scene", ["lab", "edr", "warehouse"])
def test_planner_visibility_agrees_with_covers(scene):
    """A's planner asks the compiled exact test whether the segment from a point to each
    vertex of its domain lies in the domain: where it answers, shapely's covers agrees."""
    b = WatchBatch(1, scene)
    b.seed_env(0, 0)
    b.reset_envs(np.zeros(1, dtype=np.int64))
    w = b.world
    rng = np.random.default_rng(1)
    counts = np.zeros(3, dtype=int)
    for key, g in w._graphs.items():
        n = len(g.nodes)
        E, pin, pout, amb = g._edges
        for k in range(25):
            # free points, and (harder) the domain's own vertices
            a = w.sample_free_config(rng) if k % 5 else g.nodes[rng.integers(n)].copy()
            out = np.empty(n, dtype=np.int64)
            wk.visible_from(float(a[0]), float(a[1]), g.nodes, E, pin, pout, amb, out)
            segs = shapely.linestrings(np.stack([np.repeat(a[None], n, 0), g.nodes], axis=1))
            ref = shapely.covers(g.domain, segs)
            sure = out != wk.UNSURE
            assert np.array_equal(ref[sure], out[sure] == 1), (scene, key, a)
            counts += np.bincount(out, minlength=3)
    assert counts[0] > 100 and counts[1] > 100 and counts[2] < 0.1 * counts.sum(), counts


def test_canonical_csr_is_coo_tocsr():
    from scipy.sparse import coo_matrix

    from sensorplan_gym.multiagent.world import _canonical_csr

    rng = np.random.default_rng(0)
    n = 40
    pairs = np.unique(rng.integers(0, n, (300, 2)), axis=0)
    pairs = pairs[pairs[:, 0] != pairs[:, 1]]
    perm = rng.permutation(len(pairs))
    r, c = pairs[perm, 0], pairs[perm, 1]
    d = rng.random(len(r))
    want = coo_matrix((d, (r, c)), shape=(n, n)).tocsr()
    got = _canonical_csr(r, c, d, n)
    for name in ("indptr", "indices", "data"):
        assert np.array_equal(getattr(want, name), getattr(got, name)), name

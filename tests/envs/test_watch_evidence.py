"""watch_v0(evidence=True) (issue 22 item 4): the per-watcher beam evidence of where A rests,
against an independent brute force (point in polygon by ray crossing, segment against every
polygon edge), and in the env: layout, timing, and that it points at A's true end region."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from agents.planning.watch_oracle import WatchOracle
from sensorplan_gym import watch_v0
from sensorplan_gym.multiagent.evidence import N_EVIDENCE, BeamEvidence, beam_evidence


def _inside(poly: np.ndarray, x: float, y: float) -> bool:
    """Even-odd ray crossing (one ring, no holes)."""
    n, c = len(poly), False
    for i in range(n):
        (x1, y1), (x2, y2) = poly[i], poly[(i + 1) % n]
        if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * (x2 - x1) / (y2 - y1):
            c = not c
    return c


def _cross(p, q, a, b) -> bool:
    def orient(u, v, w):
        return np.sign((v[0] - u[0]) * (w[1] - u[1]) - (v[1] - u[1]) * (w[0] - u[0]))

    return orient(p, q, a) != orient(p, q, b) and orient(a, b, p) != orient(a, b, q)


def _brute(polys, pose, ang, meas, pred, tol):
    hit, look = np.zeros(2, bool), np.zeros(2, bool)
    x, y = pose[:2]
    for j, k in enumerate("GH"):
        ring = polys[k]
        for a, m, p in zip(ang, meas, pred, strict=True):
            d = np.array([np.cos(a), np.sin(a)])
            if m < p - tol and _inside(ring, *(np.array([x, y]) + m * d)):
                hit[j] = True
            q = np.array([x, y]) + p * d
            if _inside(ring, x, y) or _inside(ring, *q):
                look[j] = True
            if any(_cross((x, y), q, ring[i], ring[(i + 1) % len(ring)]) for i in range(len(ring))):
                look[j] = True
    return hit, look


def test_beam_evidence_matches_a_brute_force():
    rng = np.random.default_rng(3)
    polys = {
        "G": np.array([[1.0, 1.0], [3.0, 1.2], [2.6, 3.0], [1.2, 2.5]]),
        "H": np.array([[5.0, 4.0], [7.0, 4.0], [6.0, 6.5]]),
    }
    swept = {k: shapely.Polygon(v) for k, v in polys.items()}
    agree = {"hit": [0, 0], "look": [0, 0]}
    for _ in range(200):
        pose = (rng.uniform(-1, 8), rng.uniform(-1, 8), rng.uniform(-np.pi, np.pi))
        ang = pose[2] + np.linspace(-1.0, 1.0, 7)
        pred = rng.uniform(0.5, 9.0, 7)
        meas = np.where(rng.random(7) < 0.5, pred * rng.uniform(0.1, 1.0, 7), pred)
        hit, look = beam_evidence(swept, pose, ang, meas, pred, 1e-6)
        bh, bl = _brute(polys, pose, ang, meas, pred, 1e-6)
        assert np.array_equal(hit, bh) and np.array_equal(look, bl), (pose, hit, bh, look, bl)
        agree["hit"][int(hit.any())] += 1
        agree["look"][int(look.any())] += 1
    # both outcomes occur (the comparison is not vacuous)
    assert min(agree["hit"]) > 10 and min(agree["look"]) > 10, agree


def test_beam_evidence_bad_input_and_features():
    sq = shapely.box(0, 0, 1, 1)
    with pytest.raises(ValueError, match="same length"):
        beam_evidence({"G": sq, "H": sq}, (0, 0, 0), np.zeros(3), np.zeros(2), np.zeros(3), 0.0)
    ev = BeamEvidence({"G": sq, "H": shapely.box(5, 5, 6, 6)}, 2, 1e-3)
    assert np.array_equal(ev.features(0), np.zeros(4))
    # a beam from (-1, 0.5) along +x that stops at x = 0.5 (inside G), map predicts 10
    for _ in range(2):
        ev.update(1, (-1.0, 0.5, 0.0), np.array([0.0]), np.array([1.5]), np.array([10.0]))
    f = ev.features(1)
    assert f[0] == pytest.approx(0.75) and f[1] == 0.0  # two hits in G, none in H
    assert f[2] == pytest.approx(1 - 0.5**0.5) and f[3] == 0.0  # looked at G twice
    assert np.array_equal(ev.features(0), np.zeros(4))
    ev.reset()
    assert np.array_equal(ev.features(1), np.zeros(4))


def test_env_evidence_layout_and_bad_input():
    with pytest.raises(ValueError, match="evidence"):
        watch_v0.parallel_env(scene="lab", evidence="yes")
    plain = watch_v0.parallel_env(scene="lab", n_watchers=2)
    ev = watch_v0.parallel_env(scene="lab", n_watchers=2, evidence=True)
    k = plain.observation_space("watcher_0").shape[0]
    assert ev.observation_space("watcher_0").shape == (k + N_EVIDENCE,)
    o1, _ = plain.reset(seed=5)
    o2, _ = ev.reset(seed=5)
    rng = np.random.default_rng(0)
    for _ in range(30):  # the common part is unchanged; nothing is counted before move_steps
        for a in o1:
            assert np.array_equal(o1[a], o2[a][:k])
            assert np.array_equal(o2[a][k:], np.zeros(N_EVIDENCE, np.float32))
            assert ev.observation_space(a).contains(o2[a])
        acts = {a: rng.uniform(-1, 1, 4).astype(np.float32) for a in plain.agents}
        o1, *_ = plain.step(acts)
        o2, *_ = ev.step(acts)


@pytest.mark.parametrize("seed", [1_000_000, 1_000_001, 1_000_002, 1_000_003])
def test_env_evidence_points_at_where_A_rests(seed):
    """The oracle watchers on lab: by the horizon no watcher has seen A where it is not,
    and some watcher has seen it where it is (the oracle covers G and H)."""
    env = watch_v0.parallel_env(scene="lab", n_watchers=2, evidence=True)
    oracle = WatchOracle(env)
    obs, _ = env.reset(seed=seed)
    oracle.reset()
    while env.agents:
        obs, _, _, _, info = env.step(oracle.act(obs))
    where = env.traj.outcome
    right, wrong = ("GH".index(where), 1 - "GH".index(where))
    hits = env.evidence.hits
    assert (hits[:, wrong] == 0).all(), (where, hits)
    assert hits[:, right].max() > 0, (where, hits)
    feats = np.stack([obs[a][-N_EVIDENCE:] for a in obs])
    np.testing.assert_allclose(feats[:, :2], 1 - 0.5**hits, rtol=1e-6)

"""Native vector envs (``vector_entry_point``): sub-env i of a batch equals a single env seeded
the same way, step for step over whole episodes; the Gymnasium 1.x vector API (spaces,
NEXT_STEP autoreset, seeding, info masks, reset masks, render, pickling); the scene pool."""

from __future__ import annotations

import pickle

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

import sensorplan_gym  # noqa: F401
from sensorplan_gym.registration import ENV_IDS

IDS = sorted(ENV_IDS)
NOISY = {"noise": 0.05, "eps_pos": 0.05, "eps_aim": 0.02}


def _vec(env_id, n=3, **kw):
    return gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point", **kw)


def _actions(space, rng, n):
    a = rng.uniform(-1, 1, (n, *space.shape)).astype(np.float32)
    if a.shape[1] == 4:  # Recognize: declare rarely, so episodes run for a while
        a[:, 3] = np.where(rng.random(n) < 0.03, np.sign(a[:, 3]), 0.0)
    return a


def _same_info(single: dict, vec: dict, i: int) -> None:
    for k, v in single.items():
        assert vec["_" + k][i], k
        w = vec[k][i]
        if isinstance(v, tuple):
            assert np.array_equal(np.asarray(v), w), k
        else:
            assert v == w, (k, v, w)


@pytest.mark.parametrize("obs_type", ["vector", "grid"])
@pytest.mark.parametrize("env_id", IDS)
def test_sub_env_equals_single_env(env_id, obs_type):
    n, steps = 3, 260 if "Placement" not in env_id else 12
    kw = dict(obs_type=obs_type, **NOISY)
    venv = _vec(env_id, n, **kw)
    singles = [gym.make(env_id, **kw) for _ in range(n)]
    obs, info = venv.reset(seed=11)
    for i, e in enumerate(singles):
        o, inf = e.reset(seed=11 + i)
        assert np.array_equal(o, obs[i])
        _same_info(inf, info, i)
    rng = np.random.default_rng(0)
    done = [False] * n
    episodes = 0
    for _ in range(steps):
        a = _actions(venv.single_action_space, rng, n)
        obs, rew, term, trunc, info = venv.step(a)
        for i, e in enumerate(singles):
            if done[i]:  # NEXT_STEP autoreset: this step reset sub-env i
                o, inf = e.reset()
                r, te, tr = 0.0, False, False
            else:
                o, r, te, tr, inf = e.step(a[i])
            assert np.array_equal(o, obs[i])
            assert (r, te, tr) == (rew[i], term[i], trunc[i])
            _same_info(inf, info, i)
            done[i] = te or tr
            episodes += done[i]
    assert episodes >= n  # whole episodes were compared, not just their starts


@pytest.mark.parametrize("env_id", IDS)
def test_vector_api(env_id):
    n = 4
    venv = _vec(env_id, n)
    assert isinstance(venv, gym.vector.VectorEnv)
    assert venv.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    assert venv.num_envs == n
    single = gym.make(env_id)
    assert venv.single_observation_space == single.observation_space
    assert venv.single_action_space == single.action_space
    assert venv.observation_space.shape == (n, *single.observation_space.shape)
    assert venv.action_space.shape == (n, *single.action_space.shape)
    obs, info = venv.reset(seed=3)
    assert obs in venv.observation_space
    assert info["_is_success"].all() and info["is_success"].shape == (n,)
    # same seed -> same observations; sub-envs differ from each other where randomness matters
    again, _ = _vec(env_id, n).reset(seed=3)
    assert np.array_equal(obs, again)
    venv.action_space.seed(0)
    for _ in range(5):
        obs, rew, term, trunc, info = venv.step(venv.action_space.sample())
        assert obs in venv.observation_space
        assert rew.shape == term.shape == trunc.shape == (n,)
        assert rew.dtype == np.float64 and term.dtype == bool and trunc.dtype == bool
        for k in [k for k in info if not k.startswith("_")]:
            assert info["_" + k].shape == (n,) and info[k].shape[0] == n
    with pytest.raises(ValueError, match="shape"):
        venv.step(np.zeros((n + 1, *venv.single_action_space.shape)))
    with pytest.raises(ValueError, match="NaN"):
        venv.step(np.full(venv.action_space.shape, np.nan))
    venv.close()


def test_autoreset_next_step_and_masks():
    venv = _vec("sensorplan/Recognize-v0", 3)
    venv.reset(seed=0)
    a = np.zeros((3, 4), dtype=np.float32)
    a[0, 3] = -1.0  # sub-env 0 declares G now
    _, rew, term, trunc, info = venv.step(a)
    assert term.tolist() == [True, False, False]
    assert info["_target_in"].tolist() == [True, False, False]
    assert info["target_in"][0] in ("G", "H") and info["declared"][0] == "G"
    assert rew[0] == pytest.approx(-0.01 + (1.0 if info["target_in"][0] == "G" else -1.0))
    # the next step resets sub-env 0 (its action is ignored): reward 0, not done
    a[0, 3] = 1.0
    _, rew, term, trunc, info = venv.step(a)
    assert rew[0] == 0.0 and not term[0] and not trunc[0]
    assert info["declared"][0] is None and info["_declared"].all()
    # timeouts apply the documented penalty under make_vec too
    venv = _vec("sensorplan/Recognize-v0", 2, max_steps=3)
    venv.reset(seed=0)
    z = np.zeros((2, 4), dtype=np.float32)
    for _ in range(2):
        _, rew, term, trunc, _ = venv.step(z)
        assert not trunc.any()
    _, rew, term, trunc, info = venv.step(z)
    assert trunc.all() and not term.any()
    assert rew == pytest.approx([-1.01, -1.01])
    assert info["_target_in"].all()


def test_reset_seeds_and_mask():
    venv = _vec("sensorplan/Navigate-v0", 3, random_start=True)
    obs, _ = venv.reset(seed=[5, 6, 7])
    by_int, _ = _vec("sensorplan/Navigate-v0", 3, random_start=True).reset(seed=5)
    assert np.array_equal(obs, by_int)
    assert not np.array_equal(obs[0], obs[1])
    single, _ = gym.make("sensorplan/Navigate-v0", random_start=True).reset(seed=6)
    assert np.array_equal(single, obs[1])
    stepped = venv.step(np.ones((3, 3), dtype=np.float32))[0]
    moved, info = venv.reset(options={"reset_mask": np.array([False, True, False])})
    assert np.array_equal(moved[[0, 2]], stepped[[0, 2]])  # untouched
    e = gym.make("sensorplan/Navigate-v0", random_start=True)
    e.reset(seed=6)
    e.step(np.ones(3, dtype=np.float32))
    assert np.array_equal(moved[1], e.reset()[0])  # reset, its generator running on
    assert info["_pose"].tolist() == [False, True, False]
    with pytest.raises(ValueError, match="seeds"):
        venv.reset(seed=[1, 2])
    with pytest.raises(ValueError, match="reset_mask"):
        venv.reset(options={"reset_mask": [True]})


def test_render_and_pickle():
    venv = _vec("sensorplan/Recognize-v0", 2, render_mode="rgb_array")
    venv.reset(seed=0)
    frame = venv.render()
    assert frame.ndim == 3 and frame.shape[2] == 3 and frame.std() > 0
    clone = pickle.loads(pickle.dumps(venv))
    a = np.zeros((2, 4), dtype=np.float32)
    a[:, 0] = 1.0
    o1 = venv.step(a)[0]
    o2 = clone.step(a)[0]
    assert np.array_equal(o1, o2)


def test_random_scene_pool_deterministic_and_shared():
    kw = dict(scene="random", scene_pool_size=4, scene_pool_seed=1)
    venv = _vec("sensorplan/Navigate-v0", 6, **kw)
    venv.reset(seed=0)
    names = {w.scene.to_dict()["bounds"].__repr__() for w in venv.unwrapped.batch.worlds}
    assert 1 < len(names) <= 4  # drawn from the pool of 4
    b = _vec("sensorplan/Navigate-v0", 6, **kw)
    b.reset(seed=0)
    pairs = zip(venv.unwrapped.batch.worlds, b.unwrapped.batch.worlds, strict=True)
    assert all(w is v for w, v in pairs)
    other = _vec("sensorplan/Navigate-v0", 6, scene="random", scene_pool_size=4, scene_pool_seed=2)
    other.reset(seed=0)
    mine = {id(w) for w in venv.unwrapped.batch.worlds}
    assert mine.isdisjoint({id(w) for w in other.unwrapped.batch.worlds})
    with pytest.raises(ValueError, match="scene_pool_size"):
        _vec("sensorplan/Navigate-v0", 2, scene="random", scene_pool_size=0)


def test_batched_queries_match_each_world_in_a_mixed_pool():
    """Rows of different worlds (hulls of different sizes, a partial field of view): the
    batched recognizability test equals each world's own test at the same poses."""
    venv = _vec("sensorplan/Navigate-v0", 8, scene="random", scene_pool_size=8, fov_deg=120)
    venv.reset(seed=0)
    b = venv.unwrapped.batch
    for _ in range(3):  # reload rows with other worlds
        venv.reset(options={"reset_mask": np.arange(8) % 2 == 0})
    assert len({id(w) for w in b.worlds}) > 2
    assert len({w.batch_rows()["hulls"].shape[1] for w in b.worlds}) > 1
    rng = np.random.default_rng(1)
    idx = np.arange(8)
    agree = hits = 0
    for _ in range(60):
        for i, w in enumerate(b.worlds):
            p = w.region.representative_point() if rng.random() < 0.5 else None
            b.x[i] = p.x if p else rng.uniform(w.lo[0], w.hi[0])
            b.y[i] = p.y if p else rng.uniform(w.lo[1], w.hi[1])
            b.psi[i] = rng.uniform(-np.pi, np.pi)
        rec = b.query(idx)[0]
        for i, w in enumerate(b.worlds):
            agree += rec[i] == w.recognizing(b.x[i], b.y[i], b.psi[i])
            hits += rec[i]
    assert agree == 60 * 8 and hits > 0


def test_rows_survive_a_larger_world():
    """Loading a world with more hull vertices enlarges the padded arrays without touching
    the other rows (each keeps its own hulls, padded by repeating its last vertex)."""
    from sensorplan_gym.core.cache import get_world
    from sensorplan_gym.core.sim import BatchSim
    from sensorplan_gym.core.world import WorldConfig, load_scene

    small = get_world(load_scene("corridor"), WorldConfig(fov=2.0))
    big = get_world(load_scene("lab"), WorldConfig(fov=2.0))
    k_small = small.batch_rows()["hulls"].shape[1]
    assert big.batch_rows()["hulls"].shape[1] > k_small
    b = BatchSim(2, 8, 0.0, 0.0)
    b.load_world(0, small)
    b.load_world(1, small)
    b.load_world(1, big)
    h = b.hulls[0]
    assert np.array_equal(h[:, :k_small], small.batch_rows()["hulls"])
    assert (h[:, k_small:] == h[:, k_small - 1 : k_small]).all()
    assert np.array_equal(b.hulls[1], big.batch_rows()["hulls"])

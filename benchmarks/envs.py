"""Environment speed against CartPole-v1 measured in the same run.

    python -m benchmarks.envs [--quick] [--train]

Writes a markdown table to ``benchmarks/results/envs.md`` (and prints it).

* **single env**: ``gym.make(id)`` with its standard wrappers, random actions drawn up front,
  resets included when an episode ends; CartPole-v1 the same way.
* **batched**: ``gym.make_vec(id, num_envs=256, vectorization_mode="vector_entry_point")``,
  env-steps per second (256 per vector step; NEXT_STEP autoresets included); CartPole-v1's
  own ``CartPoleVectorEnv`` with 256 envs the same way.  Ratios to both anchors.
* For Recognize-v0 the decide component is set to 0 ("continue") so that episodes are not
  cut to a step or two by random declarations; the declaring variant is shown too.
* **numpy**: the batched core with ``SENSORPLAN_NO_NUMBA=1`` (the numpy fallback of the
  compiled inner loops, in a subprocess).
* ``--train``: ``sensorplan train`` PPO on Navigate-v0 with the shipped config
  (``agents/configs/ppo.yaml``, same hyperparameters) on the batched path and on SB3's
  DummyVecEnv of single envs; env steps per second of wall clock, updates included.

Every figure is the median of ``--repeats`` timed chunks; ratios are to CartPole-v1 single
env measured in the same run (the 2-core machine is shared and noisy: compare ratios).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import gymnasium as gym
import numpy as np

import sensorplan_gym  # noqa: F401

IDS = ["sensorplan/Placement-v0", "sensorplan/Navigate-v0", "sensorplan/Recognize-v0"]
N_BATCH = 256


def _no_declare(a: np.ndarray) -> np.ndarray:
    if a.shape[-1] == 4:
        a[..., 3] = 0.0
    return a


def single_sps(env_id: str, steps: int, repeats: int, declare: bool = False, **kw) -> float:
    """Median steps/s of one env (resets included)."""
    env = gym.make(env_id, **kw)
    env.reset(seed=0)
    env.action_space.seed(0)
    acts = [env.action_space.sample() for _ in range(steps)]
    if not declare and isinstance(env.action_space, gym.spaces.Box):
        acts = [_no_declare(a) for a in acts]
    rates = []
    for chunk in np.array_split(np.arange(steps), repeats):
        t = time.perf_counter()
        for k in chunk:
            _, _, te, tr, _ = env.step(acts[k])
            if te or tr:
                env.reset()
        rates.append(len(chunk) / (time.perf_counter() - t))
    env.close()
    return float(np.median(rates))


def batched_sps(
    env_id: str, vsteps: int, repeats: int, num_envs: int = N_BATCH, declare=False, **kw
) -> float:
    """Median env-steps/s of the native vector env (``vector_entry_point``)."""
    venv = gym.make_vec(env_id, num_envs=num_envs, vectorization_mode="vector_entry_point", **kw)
    venv.reset(seed=0)
    venv.action_space.seed(0)
    acts = [venv.action_space.sample() for _ in range(vsteps)]
    if not declare and isinstance(venv.single_action_space, gym.spaces.Box):
        acts = [_no_declare(a) for a in acts]
    for a in acts[:5]:  # warm-up (compiles, fills caches)
        venv.step(a)
    rates = []
    for chunk in np.array_split(np.arange(vsteps), repeats):
        t = time.perf_counter()
        for k in chunk:
            venv.step(acts[k])
        rates.append(len(chunk) * num_envs / (time.perf_counter() - t))
    venv.close()
    return float(np.median(rates))


def numpy_fallback(env_id: str, vsteps: int, repeats: int, **kw) -> float:
    """:func:`batched_sps` in a subprocess with ``SENSORPLAN_NO_NUMBA=1``."""
    code = (
        "import json, benchmarks.envs as b; "
        f"print(json.dumps(b.batched_sps({env_id!r}, {vsteps}, {repeats}, **{kw!r})))"
    )
    env = dict(os.environ, SENSORPLAN_NO_NUMBA="1")
    out = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
    )
    return float(json.loads(out.stdout.strip().splitlines()[-1]))


def train_sps(vec_env: str, timesteps: int, n_envs: int | None = None, n_steps=None) -> float:
    """Env steps per wall-clock second of ``sensorplan train`` PPO on Navigate-v0 with the
    shipped config (``n_envs``/``n_steps`` overridden when given; the rollout size and every
    learning hyperparameter otherwise unchanged).  Imports and torch's lazy set-up are paid
    by a short warm-up run first."""
    import yaml

    from agents.train import load_hyperparams, train

    hp = load_hyperparams("ppo", "sensorplan/Navigate-v0")
    if n_envs is not None:
        hp["n_envs"], hp["n_steps"] = n_envs, n_steps
    with tempfile.TemporaryDirectory() as d:
        cfg = Path(d) / "ppo.yaml"
        cfg.write_text(yaml.safe_dump({"sensorplan/Navigate-v0": hp}))
        kw = dict(
            seed=0,
            vec_env=vec_env,
            config=cfg,
            eval_freq=10**9,
            verbose=0,
            progress_bar=False,
            tensorboard=False,
        )
        train("sensorplan/Navigate-v0", "ppo", timesteps=64, out=Path(d) / "warm", **kw)
        t = time.perf_counter()
        rec = train("sensorplan/Navigate-v0", "ppo", timesteps=timesteps, out=Path(d) / "o", **kw)
        dt = time.perf_counter() - t
    return rec["timesteps"] / dt


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer steps (smoke run)")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--train", action="store_true", help="also time PPO training")
    ap.add_argument("--train-steps", type=int, default=20_480)
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "envs.md"))
    args = ap.parse_args(argv)
    n = 500 if args.quick else 5000
    nv = 10 if args.quick else 60
    r = args.repeats

    cart = single_sps("CartPole-v1", 4 * n, r)
    cart_vec = batched_sps("CartPole-v1", 4 * nv, r)
    rows = []
    for env_id in IDS:
        s = single_sps(env_id, n, r)
        b = batched_sps(env_id, nv, r)
        g = batched_sps(env_id, max(nv // 4, 3), r, obs_type="grid")
        npy = numpy_fallback(env_id, max(nv // 4, 3), r)
        rows.append((env_id, s, b, g, npy))
    rec_decl = batched_sps("sensorplan/Recognize-v0", nv, r, declare=True)
    rec_decl_rand = batched_sps("sensorplan/Recognize-v0", nv, r, declare=True, scene="random")
    nav_rand = batched_sps("sensorplan/Navigate-v0", nv, r, scene="random")

    def ratio(v: float) -> str:
        return f"{v / cart:.2f}x"

    lines = [
        "# Environment speed",
        "",
        f"Machine: {os.cpu_count()} cores, {platform.python_implementation()} "
        f"{platform.python_version()}, numpy {np.__version__}, gymnasium {gym.__version__}.  "
        f"Command: `python -m benchmarks.envs{' --train' if args.train else ''}`.  "
        f"Medians of {r} chunks; load average at the end: {os.getloadavg()[0]:.1f}.",
        "",
        f"| env (random actions) | single env steps/s | ratio to CartPole | batched x{N_BATCH} "
        "env-steps/s | ratio to CartPole | ratio to CartPoleVectorEnv | batched grid obs "
        "| batched, numpy fallback |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
        f"| CartPole-v1 (anchor) | {cart:,.0f} | 1.00x | {cart_vec:,.0f} (CartPoleVectorEnv) | "
        f"{ratio(cart_vec)} | 1.00x | | |",
    ]
    for env_id, s, b, g, npy in rows:
        lines.append(
            f"| {env_id} | {s:,.0f} | {ratio(s)} | {b:,.0f} | {ratio(b)} | "
            f"{b / cart_vec:.3f}x | {g:,.0f} | {npy:,.0f} |"
        )
    lines += [
        "",
        f"Batched Recognize-v0 with fully random actions (2/3 of the steps declare, so most "
        f"steps are autoresets): {rec_decl:,.0f} env-steps/s ({ratio(rec_decl)}); on "
        f'`scene="random"` (a pool of 64 scenes, a new scene at most resets): '
        f"{rec_decl_rand:,.0f} env-steps/s ({ratio(rec_decl_rand)}).  "
        f'Batched Navigate-v0 on `scene="random"`: {nav_rand:,.0f} '
        f"env-steps/s ({ratio(nav_rand)}).",
    ]
    if args.train:
        ts = args.train_steps
        rates = {
            (v, ne): train_sps(v, ts, *(() if ne is None else (ne, 2048 // ne)))
            for v in ("batched", "dummy")
            for ne in (None, 64)
        }
        lines += [
            "",
            f"`sensorplan train` PPO on Navigate-v0, {ts:,} steps, 1 torch thread, wall clock "
            "with updates (rollout of 2,048 steps, batch 128, 10 epochs, as shipped):",
            "",
            "| vectorisation | shipped: 2 envs x 1,024 steps | 64 envs x 32 steps |",
            "| --- | ---: | ---: |",
        ]
        for v, name in (("batched", "batched core (default)"), ("dummy", "SB3 DummyVecEnv")):
            lines.append(f"| {name} | {rates[(v, None)]:,.0f} | {rates[(v, 64)]:,.0f} |")
    text = "\n".join(lines) + "\n"
    print(text)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(text)


if __name__ == "__main__":
    main()

"""Environment speed against CartPole-v1 measured in the same run.

    python -m benchmarks.envs [--quick] [--train]

Prints the table and writes the data (``envs.json``) and the page fragment (``envs.md``) to
``--out`` (default ``runs/benchmarks/envs/``), or with ``--update-results`` to the tracked
``benchmarks/results/envs.json`` and ``docs/results/envs.md``.

* **single env**: ``gym.make(id)`` with its standard wrappers, random actions drawn up front,
  resets included when an episode ends; CartPole-v1 the same way.
* **batched**: ``gym.make_vec(id, num_envs=256, vectorization_mode="vector_entry_point")``,
  env-steps per second (256 per vector step; NEXT_STEP autoresets included); CartPole-v1's
  own ``CartPoleVectorEnv`` with 256 envs the same way.
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
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

import sensorplan_gym  # noqa: F401

from . import _results

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

    from agents.learning.train import load_hyperparams, train

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
    ap = argparse.ArgumentParser(
        prog="python -m benchmarks.envs", description=__doc__.splitlines()[0]
    )
    ap.add_argument("--quick", action="store_true", help="fewer steps (smoke run)")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--train", action="store_true", help="also time PPO training")
    ap.add_argument("--train-steps", type=int, default=20_480)
    _results.add_output_args(ap, "envs")
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
    nav_rand = batched_sps("sensorplan/Navigate-v0", nv, r, scene="random")

    data: dict[str, Any] = {
        "command": _results.command("benchmarks.envs", argv),
        "machine": {**_results.machine(), "gymnasium": gym.__version__},
        "repeats": r,
        "n_batch": N_BATCH,
        "cartpole": cart,
        "cartpole_vector": cart_vec,
        "rows": [
            {"env": e, "single": s_, "batched": b, "batched_grid": g, "batched_numpy": npy}
            for e, s_, b, g, npy in rows
        ],
        "recognize_declaring": rec_decl,
        "navigate_random_scenes": nav_rand,
        "train": None,
    }
    if args.train:
        ts = args.train_steps
        rates = {
            (v, ne): train_sps(v, ts, *(() if ne is None else (ne, 2048 // ne)))
            for v in ("batched", "dummy")
            for ne in (None, 64)
        }
        data["train"] = {
            "steps": ts,
            "rows": [
                {"vec_env": v, "shipped": rates[(v, None)], "envs64": rates[(v, 64)]}
                for v in ("batched", "dummy")
            ],
        }
    print(render(data))
    _results.write("envs", data, args.out, args.update_results)


def render(data: dict[str, Any]) -> str:
    """The page fragment: env steps/s against CartPole-v1, and training throughput."""
    cart = data["cartpole"]

    def ratio(v: float) -> str:
        return f"{v / cart:.2f}x"

    nb = data["n_batch"]
    lines = [
        f"| env (random actions) | single env steps/s | ratio to CartPole | batched x{nb} "
        "env-steps/s | ratio | batched grid obs | batched, numpy fallback |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: |",
        f"| CartPole-v1 (anchor) | {cart:,.0f} | 1.00x | {data['cartpole_vector']:,.0f} "
        f"(CartPoleVectorEnv) | {ratio(data['cartpole_vector'])} | | |",
    ]
    for r in data["rows"]:
        lines.append(
            f"| {r['env']} | {r['single']:,.0f} | {ratio(r['single'])} | {r['batched']:,.0f} | "
            f"{ratio(r['batched'])} | {r['batched_grid']:,.0f} | {r['batched_numpy']:,.0f} |"
        )
    rd, nr = data["recognize_declaring"], data["navigate_random_scenes"]
    lines += [
        "",
        f"Batched Recognize-v0 with fully random actions (2/3 of the steps declare, so most "
        f"steps are autoresets): {rd:,.0f} env-steps/s ({ratio(rd)}).  "
        f'Batched Navigate-v0 on `scene="random"` (a pool of 64 scenes): {nr:,.0f} '
        f"env-steps/s ({ratio(nr)}).",
    ]
    if data.get("train"):
        t = data["train"]
        names = {"batched": "batched core (default)", "dummy": "SB3 DummyVecEnv"}
        lines += [
            "",
            f"`sensorplan train` PPO on Navigate-v0, {t['steps']:,} steps, 1 torch thread, "
            "env-steps per second of wall clock with updates (rollout of 2,048 steps, batch "
            "128, 10 epochs, as shipped):",
            "",
            "| vectorisation | shipped: 2 envs x 1,024 steps | 64 envs x 32 steps |",
            "| --- | ---: | ---: |",
        ]
        for row in t["rows"]:
            lines.append(
                f"| {names[row['vec_env']]} | {row['shipped']:,.0f} | {row['envs64']:,.0f} |"
            )
    m = data["machine"]
    lines += [
        "",
        f"`{data['command']}`: medians of {data['repeats']} chunks; {m['cpus']} CPUs, Python "
        f"{m['python']}, numpy {m['numpy']}, gymnasium {m['gymnasium']}, load average "
        f"{m['load_average']}.",
    ]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()

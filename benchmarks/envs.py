"""Environment speed against CartPole-v1 measured in the same run.

    python -m benchmarks.envs [--quick] [--train]

Prints the table and writes the data (``envs.json``) and the page fragment (``envs.md``) to
``--out`` (default ``runs/benchmarks/envs/``), or with ``--update-results`` to the tracked
``benchmarks/results/envs.json`` and ``docs/results/envs.md``.

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

Every figure is the median of ``--repeats`` timed chunks (about 0.1 s each).  Ratios are to
CartPole-v1 (single env, or ``CartPoleVectorEnv``) measured in the same run, chunk by chunk:
an env's chunks alternate with the anchor's and the ratio quoted is the median of the
per-pair ratios, so a shared, noisy machine slows both sides of each ratio alike (compare
ratios, not rates).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

import sensorplan_gym  # noqa: F401

from . import _results

IDS = ["sensorplan/Placement-v0", "sensorplan/Navigate-v0", "sensorplan/Recognize-v0"]
N_BATCH = 256
#: the length of one timed chunk in the paired (anchor, env) measurements, seconds
CHUNK_SECONDS = 0.1


def _no_declare(a: np.ndarray) -> np.ndarray:
    if a.shape[-1] == 4:
        a[..., 3] = 0.0
    return a


def single_runner(env_id: str, chunk: int, declare: bool = False, **kw) -> Callable[[], float]:
    """A function timing ``chunk`` more steps of one ``gym.make`` env (random actions drawn
    up front, resets included): steps/s."""
    env = gym.make(env_id, **kw)
    env.reset(seed=0)
    env.action_space.seed(0)
    acts = [env.action_space.sample() for _ in range(max(chunk, 1000))]
    if not declare and isinstance(env.action_space, gym.spaces.Box):
        acts = [_no_declare(a) for a in acts]
    pos = [0]

    def run(calls: int | None = None) -> float:
        calls = chunk if calls is None else calls
        t = time.perf_counter()
        for _ in range(calls):
            _, _, te, tr, _ = env.step(acts[pos[0] % len(acts)])
            pos[0] += 1
            if te or tr:
                env.reset()
        return calls / (time.perf_counter() - t)

    return run


def batched_runner(
    env_id: str,
    chunk: int,
    num_envs: int = N_BATCH,
    declare: bool = False,
    warmup: int = 5,
    **kw,
) -> Callable[[], float]:
    """A function timing ``chunk`` more steps of the native vector env
    (``vector_entry_point``, NEXT_STEP autoresets included): env-steps/s.  ``warmup`` steps
    are taken first (compiles, fills caches: on a scene pool, the first use of each
    scene)."""
    venv = gym.make_vec(env_id, num_envs=num_envs, vectorization_mode="vector_entry_point", **kw)
    venv.reset(seed=0)
    venv.action_space.seed(0)
    acts = [venv.action_space.sample() for _ in range(max(chunk, 50))]
    if not declare and isinstance(venv.single_action_space, gym.spaces.Box):
        acts = [_no_declare(a) for a in acts]
    for k in range(warmup):
        venv.step(acts[k % len(acts)])
    pos = [0]

    def run(calls: int | None = None) -> float:
        calls = chunk if calls is None else calls
        t = time.perf_counter()
        for _ in range(calls):
            venv.step(acts[pos[0] % len(acts)])
            pos[0] += 1
        return calls * num_envs / (time.perf_counter() - t)

    return run


def _calls_for(run: Callable[..., float], seconds: float) -> int:
    """How many calls of ``run`` take about ``seconds``."""
    k = 1
    while True:
        t = time.perf_counter()
        run(k)
        dt = time.perf_counter() - t
        if dt >= seconds / 4:
            return max(1, round(k * seconds / dt))
        k *= 4


def paired(
    anchor: Callable[..., float],
    other: Callable[..., float],
    repeats: int,
    log: list | None = None,
    seconds: float = CHUNK_SECONDS,
):
    """Alternate chunks of ``anchor`` and ``other``, each about ``seconds`` long (so both
    see the same load): the median rates and the median of the per-pair ratios ``other /
    anchor``; the anchor's rates are appended to ``log``."""
    ka, ko = _calls_for(anchor, seconds), _calls_for(other, seconds)
    ra, ro = [], []
    for _ in range(repeats):
        ra.append(anchor(ka))
        ro.append(other(ko))
    if log is not None:
        log.extend(ra)
    ratios = np.array(ro) / np.array(ra)
    return float(np.median(ra)), float(np.median(ro)), float(np.median(ratios))


def single_sps(env_id: str, steps: int, repeats: int, declare: bool = False, **kw) -> float:
    """Median steps/s of one env (resets included) over ``repeats`` chunks."""
    run = single_runner(env_id, max(steps // repeats, 1), declare, **kw)
    return float(np.median([run() for _ in range(repeats)]))


def batched_sps(
    env_id: str, vsteps: int, repeats: int, num_envs: int = N_BATCH, declare=False, **kw
) -> float:
    """Median env-steps/s of the native vector env over ``repeats`` chunks."""
    run = batched_runner(env_id, max(vsteps // repeats, 1), num_envs, declare, **kw)
    return float(np.median([run() for _ in range(repeats)]))


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

    cs = max(4 * n // r, 1)  # CartPole chunks: about as long as the env's
    cart1 = single_runner("CartPole-v1", cs)
    cartv = batched_runner("CartPole-v1", max(4 * nv // r, 1))
    rows = []
    c_log: list[float] = []  # every anchor chunk, for the anchor's own row
    v_log: list[float] = []
    for env_id in IDS:
        _, s, rs = paired(cart1, single_runner(env_id, max(n // r, 1)), r, c_log)
        brun = batched_runner(env_id, max(nv // r, 1))
        _, b, rv = paired(cartv, brun, r, v_log)
        _, _, rb = paired(cart1, brun, r, c_log)
        g = batched_sps(env_id, max(nv // 4, 3), r, obs_type="grid")
        npy = numpy_fallback(env_id, max(nv // 4, 3), r)
        rows.append((env_id, s, rs, b, rb, rv, g, npy))
    extra = {
        name: paired(cart1, batched_runner(env_id, max(nv // r, 1), **kw), r, c_log)
        for name, env_id, kw in (
            ("rec_decl", "sensorplan/Recognize-v0", {"declare": True}),
            (
                "rec_decl_rand",
                "sensorplan/Recognize-v0",
                {"declare": True, "scene": "random", "warmup": 30},
            ),
            ("nav_rand", "sensorplan/Navigate-v0", {"scene": "random", "warmup": 30}),
        )
    }
    cart = float(np.median(c_log))
    cart_vec = float(np.median(v_log))

    data: dict[str, Any] = {
        "command": _results.command("benchmarks.envs", argv),
        "machine": {**_results.machine(), "gymnasium": gym.__version__},
        "repeats": r,
        "chunk_seconds": CHUNK_SECONDS,
        "n_batch": N_BATCH,
        "cartpole": cart,
        "cartpole_vector": cart_vec,
        "rows": [
            {
                "env": e,
                "single": s_,
                "ratio_single": rs,
                "batched": b,
                "ratio_batched": rb,
                "ratio_vector": rv,
                "batched_grid": g,
                "batched_numpy": npy,
            }
            for e, s_, rs, b, rb, rv, g, npy in rows
        ],
        "extra": {k: {"rate": v[1], "ratio": v[2]} for k, v in extra.items()},
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
    """The page fragment: env steps/s against CartPole-v1 and CartPoleVectorEnv (each
    ratio the median of paired chunk ratios), and training throughput."""
    cart = data["cartpole"]
    nb = data["n_batch"]
    lines = [
        f"| env (random actions) | single env steps/s | ratio to CartPole | batched x{nb} "
        "env-steps/s | ratio to CartPole | ratio to CartPoleVectorEnv | batched grid obs "
        "| batched, numpy fallback |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
        f"| CartPole-v1 (anchor) | {cart:,.0f} | 1.00x | {data['cartpole_vector']:,.0f} "
        f"(CartPoleVectorEnv) | {data['cartpole_vector'] / cart:.2f}x | 1.00x | | |",
    ]
    for r in data["rows"]:
        lines.append(
            f"| {r['env']} | {r['single']:,.0f} | {r['ratio_single']:.2f}x | "
            f"{r['batched']:,.0f} | {r['ratio_batched']:.2f}x | {r['ratio_vector']:.3f}x | "
            f"{r['batched_grid']:,.0f} | {r['batched_numpy']:,.0f} |"
        )

    def ex(name: str) -> str:
        x = data["extra"][name]
        return f"{x['rate']:,.0f} env-steps/s ({x['ratio']:.2f}x)"

    lines += [
        "",
        "Batched Recognize-v0 with fully random actions (2/3 of the steps declare, so most "
        f'steps are autoresets): {ex("rec_decl")}; on `scene="random"` (a pool of 64 '
        f"scenes, a new scene at most resets): {ex('rec_decl_rand')}.  Batched Navigate-v0 "
        f'on `scene="random"`: {ex("nav_rand")}.  Ratios to CartPole-v1 single.',
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
        f"`{data['command']}`: medians of {data['repeats']} chunks of about "
        f"{data['chunk_seconds']} s, each ratio the median of the ratios of chunks timed "
        f"alternately with the anchor's; {m['cpus']} CPUs, Python "
        f"{m['python']}, numpy {m['numpy']}, gymnasium {m['gymnasium']}, load average "
        f"{m['load_average']}.",
    ]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()

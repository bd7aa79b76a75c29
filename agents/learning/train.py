"""Train stable-baselines3 baselines on the sensorplan environments.

``sensorplan train --env ID --algo ALGO --timesteps N --seed S --n-envs K
[--env-kwargs JSON] [--config FILE] [--out DIR]``

Hyperparameters live in versioned YAML files, one per algorithm, with a section per env id
(the rl-baselines3-zoo layout): ``agents/configs/<algo>.yaml``.  A section holds the SB3
constructor arguments plus these keys:

``n_timesteps``, ``n_envs``, ``policy`` (default ``MlpPolicy``), ``env_kwargs`` (passed to
``gym.make``), ``eval_freq`` (environment steps between evaluations, all envs together),
``n_eval_episodes``; ``policy_kwargs.activation_fn`` is a name (``tanh``, ``relu``, ...);
``action_noise: {type: normal|ornstein-uhlenbeck, sigma: s}`` for off-policy algorithms;
``frame_stack: k`` (SB3's ``VecFrameStack``: the policy sees the last ``k`` observations,
a memory for partially observable tasks); ``normalize: true`` or ``{norm_obs: ..,
norm_reward: ..}`` (SB3's ``VecNormalize``; its statistics are saved beside each model as
``<model>_vecnormalize.pkl`` and :func:`agents.learning.policies.load_policy` applies them);
``eval_env_kwargs`` (merged over ``env_kwargs`` for the periodic evaluations that select
``best_model``: e.g. ``{scene_pool_seed: 2}`` selects on a validation pool of procedural
scenes, disjoint from the training pool (seed 0) and the benchmark's test pool (seed 1)).

Command-line values override the file (``--env-kwargs`` is merged over ``env_kwargs``).
``--config FILE`` reads another file of the same layout, or a section on its own, or the
resolved ``*.yaml`` that training writes beside a model (so a run can be repeated exactly).

Outputs in ``--out`` (default ``runs/<algo>_<env>_s<seed>``):
``best_model.zip`` (best periodic evaluation: highest success rate, then highest mean
return) and ``best_model.yaml`` (the resolved config: algo, env id, env kwargs,
hyperparameters, seed, timesteps, versions, wall time), ``final_model.zip`` / ``.yaml``,
``evaluations.npz`` and, when ``tensorboard`` is installed, TensorBoard logs in ``tb/``.

Seeds: the training envs are seeded ``seed .. seed + n_envs - 1``, the periodic-evaluation
env ``seed + 10_000``; :mod:`agents.evaluation.evaluate` uses ``1_000_000 + seed`` onwards, so the
three never overlap for seeds below 10_000.
"""

from __future__ import annotations

import copy
import importlib.util
import json
import math
import multiprocessing
import os
import platform
import shutil
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import yaml

import sensorplan_gym

from ..checks import check_writable_dir
from .policies import ALGOS, algo_class, make_env

__all__ = [
    "CONFIG_DIR",
    "EVAL_SEED_OFFSET",
    "default_out",
    "load_hyperparams",
    "package_version",
    "train",
]

CONFIG_DIR = Path(__file__).resolve().parent.parent / "configs"
#: how the training envs are vectorised (see :func:`train`)
VEC_ENVS = ("batched", "auto", "dummy", "subproc")
#: offset between the training seed and the periodic-evaluation env's seed
EVAL_SEED_OFFSET = 10_000
_META_KEYS = (
    "n_timesteps",
    "n_envs",
    "policy",
    "env_kwargs",
    "eval_freq",
    "n_eval_episodes",
    "vec_env",
    "frame_stack",
    "normalize",
)


def package_version() -> str:
    """The ``sensorplan-gym`` version of the code that runs (``sensorplan_gym.__version__``,
    the one place it is written; an editable install's metadata can lag behind it)."""
    return sensorplan_gym.__version__


def _short(env_id: str) -> str:
    return env_id.split("/")[-1].split("-v")[0].lower()


def default_out(algo: str, env_id: str, seed: int) -> Path:
    return Path("runs") / f"{algo}_{_short(env_id)}_s{seed}"


def load_hyperparams(algo: str, env_id: str, config: str | Path | None = None) -> dict:
    """The hyperparameter section for ``env_id`` from ``config`` (default
    ``agents/configs/<algo>.yaml``).  A file without that section is taken as one section
    itself; a resolved run config (with ``hyperparams``) gives its hyperparameters; a
    ``default`` section serves env ids without their own."""
    path = Path(config) if config is not None else CONFIG_DIR / f"{algo}.yaml"
    if not path.is_file():
        raise FileNotFoundError(f"no hyperparameter file {path}")
    with open(path) as f:
        data = yaml.safe_load(f) or {}
    if not isinstance(data, dict):
        raise ValueError(f"{path}: expected a mapping, got {type(data).__name__}")
    if "hyperparams" in data and "env_id" in data:  # a resolved run config
        if data.get("algo") not in (None, algo):
            raise ValueError(f"{path} was written for algo {data['algo']!r}, not {algo!r}")
        section = dict(data["hyperparams"])
        section.setdefault("env_kwargs", data.get("env_kwargs") or {})
        section.setdefault("n_envs", data.get("n_envs", 1))
        section.setdefault("n_timesteps", data.get("timesteps"))
        # the meta keys that training records outside ``hyperparams``
        if (data.get("frame_stack") or 1) > 1:
            section.setdefault("frame_stack", data["frame_stack"])
        if data.get("normalize"):
            section.setdefault("normalize", data.get("normalize_kwargs") or True)
        if (data.get("eval") or {}).get("env_kwargs"):
            section.setdefault("eval_env_kwargs", data["eval"]["env_kwargs"])
        return section
    if env_id in data:
        return dict(data[env_id] or {})
    if "default" in data:
        return dict(data["default"] or {})
    if config is None:
        known = ", ".join(k for k in data if "/" in str(k)) or "none"
        raise KeyError(
            f"{path} has no section for {env_id!r} (sections: {known}); "
            "pass --config FILE with hyperparameters for it"
        )
    if any("/" in str(k) for k in data):  # a zoo-style file, just not for this env
        raise KeyError(f"{path} has no section for {env_id!r}")
    return dict(data)


def _activation(name: Any):
    import torch.nn as nn

    if not isinstance(name, str):
        return name
    table = {
        "tanh": nn.Tanh,
        "relu": nn.ReLU,
        "elu": nn.ELU,
        "leaky_relu": nn.LeakyReLU,
        "gelu": nn.GELU,
        "silu": nn.SiLU,
    }
    try:
        return table[name.lower().removeprefix("nn.")]
    except KeyError:
        raise ValueError(f"unknown activation_fn {name!r}; choose one of {sorted(table)}") from None


def _action_noise(spec: Any, action_space):
    if spec is None:
        return None
    from stable_baselines3.common.noise import NormalActionNoise, OrnsteinUhlenbeckActionNoise

    n = int(np.prod(action_space.shape))
    kind = str(spec.get("type", "normal")).lower()
    sigma = float(spec.get("sigma", 0.1)) * np.ones(n)
    if kind == "normal":
        return NormalActionNoise(np.zeros(n), sigma)
    if kind in ("ornstein-uhlenbeck", "ou"):
        return OrnsteinUhlenbeckActionNoise(np.zeros(n), sigma)
    raise ValueError(f"unknown action_noise type {kind!r} (normal or ornstein-uhlenbeck)")


def _subproc_ok() -> bool:
    return (os.cpu_count() or 1) > 1 and bool(multiprocessing.get_all_start_methods())


def _make_env_fn(env_id: str, env_kwargs: dict):
    def make():
        import gymnasium as gym

        import sensorplan_gym  # noqa: F401 - registers the ids in subprocesses

        return gym.make(env_id, **env_kwargs)

    return make


def check_algo_env(algo: str, env_id: str, env_kwargs: dict) -> None:
    """Fail early and clearly when the algorithm cannot handle the env's action space."""
    import gymnasium as gym

    import sensorplan_gym  # noqa: F401

    env = make_env(env_id, env_kwargs)
    try:
        space = env.action_space
    finally:
        env.close()
    if algo in ("dqn", "qrdqn") and not isinstance(space, gym.spaces.Discrete):
        raise ValueError(
            f"{algo.upper()} needs a Discrete action space, but {env_id} has {space} (continuous). "
            'Make the env with discrete actions (--env-kwargs \'{"action_type": '
            '"discrete"}\', as agents/configs/dqn.yaml does) or use ppo, a2c, sac or td3.'
        )
    if algo in ("sac", "td3") and not isinstance(space, gym.spaces.Box):
        raise ValueError(
            f"{algo.upper()} needs a continuous (Box) action space; {env_id} has {space} "
            "(drop action_type='discrete')"
        )


def _save_vecnormalize(model, model_path: Path) -> None:
    """Save the model's ``VecNormalize`` statistics (if it trains with one) beside it."""
    from .policies import vecnormalize_path

    vn = model.get_vec_normalize_env()
    if vn is not None:
        vn.save(str(vecnormalize_path(model_path)))


def _normalize_kwargs(spec: Any, gamma: Any) -> dict | None:
    """``VecNormalize`` keyword arguments for the ``normalize`` config key (``None``: off)."""
    if not spec:
        return None
    kw: dict[str, Any] = {} if spec is True else dict(spec)
    unknown = set(kw) - {"norm_obs", "norm_reward", "clip_obs", "clip_reward", "gamma"}
    if unknown:
        raise ValueError(f"normalize: unknown keys {sorted(unknown)}")
    if gamma is not None:
        kw.setdefault("gamma", float(gamma))
    return kw


def _eval_callback_cls():
    from stable_baselines3.common.callbacks import EvalCallback

    class BestSuccessEvalCallback(EvalCallback):
        """EvalCallback that keeps the model with the best success rate (ties: mean return)
        and writes its config beside it."""

        def __init__(self, *args, best_path: Path, write_config, **kwargs) -> None:
            super().__init__(*args, best_model_save_path=None, **kwargs)
            self.best_path = best_path
            self.write_config = write_config
            self.best_key = (-math.inf, -math.inf)
            self.best_info: dict | None = None

        def _on_step(self) -> bool:
            n = len(self.evaluations_results)
            cont = super()._on_step()
            if len(self.evaluations_results) > n:
                sr = float(np.mean(self._is_success_buffer)) if self._is_success_buffer else -1.0
                key = (sr, float(self.last_mean_reward))
                if key > self.best_key:
                    self.best_key = key
                    self.model.save(self.best_path)
                    _save_vecnormalize(self.model, self.best_path)
                    self.best_info = {
                        "timesteps": int(self.num_timesteps),
                        "success_rate": sr,
                        "mean_return": float(self.last_mean_reward),
                    }
                    self.write_config(self.best_path.with_suffix(".yaml"), self.best_info)
                    if self.verbose:
                        print(
                            f"new best model: success {sr:.3f}, return (with any shaping) "
                            f"{self.last_mean_reward:.3f} at {self.num_timesteps} steps"
                        )
            return cont

    return BestSuccessEvalCallback


def train(
    env_id: str,
    algo: str = "ppo",
    *,
    timesteps: int | None = None,
    seed: int = 0,
    n_envs: int | None = None,
    env_kwargs: dict | None = None,
    config: str | Path | None = None,
    out: str | Path | None = None,
    eval_freq: int | None = None,
    eval_episodes: int | None = None,
    vec_env: str | None = None,
    threads: int = 1,
    progress_bar: bool | None = None,
    tensorboard: bool | None = None,
    device: str = "cpu",
    verbose: int = 1,
    hp_overrides: dict | None = None,
    checkpoint_freq: int | None = None,
    resume: str | Path | None = None,
) -> dict:
    """Train ``algo`` on ``env_id``; returns the resolved config with the output paths.

    ``hp_overrides``: hyperparameters (and meta keys such as ``n_steps``) that replace the
    config's.  ``checkpoint_freq``: save ``checkpoints/<algo>_<steps>_steps.zip`` every that
    many env steps.  ``resume``: a saved model (zip) to continue training from (its step
    count carries on).

    ``vec_env``: ``"batched"`` (the default, also what ``"auto"`` means: all ``n_envs``
    sub-envs in one native vector env of the batched core, seen through
    :class:`agents.learning.vecenv.BatchedVecEnv`), ``"dummy"`` (SB3's DummyVecEnv of single
    envs, the previous path) or ``"subproc"`` (one process per env); ``None`` takes the config's
    ``vec_env``.  The three give sub-env ``i`` the same episodes (seed ``seed + i``).
    ``threads``: torch intra-op threads (default 1: on a small
    machine shared with the env workers, more threads make PPO's small-MLP updates
    many times *slower*).  ``progress_bar`` / ``tensorboard``:
    ``None`` turns them on when tqdm+rich / tensorboard are importable.
    """
    import gymnasium as gym
    import stable_baselines3
    import torch
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv

    import sensorplan_gym  # noqa: F401

    algo = algo.lower()
    if algo not in ALGOS:
        raise ValueError(f"unknown algorithm {algo!r}; choose one of {', '.join(ALGOS)}")
    if env_id not in gym.registry:
        raise ValueError(
            f"unknown env id {env_id!r}; sensorplan ids: {', '.join(sensorplan_gym.ENV_IDS)}"
        )
    hp = load_hyperparams(algo, env_id, config)
    hp.update(copy.deepcopy(hp_overrides or {}))
    resolved_env_kwargs = dict(hp.pop("env_kwargs", None) or {})
    resolved_env_kwargs.update(env_kwargs or {})
    check_algo_env(algo, env_id, resolved_env_kwargs)

    n_timesteps = int(timesteps if timesteps is not None else hp.pop("n_timesteps", 100_000))
    hp.pop("n_timesteps", None)
    n_envs = int(n_envs if n_envs is not None else hp.pop("n_envs", 1))
    hp.pop("n_envs", None)
    freq = int(eval_freq if eval_freq is not None else hp.pop("eval_freq", 10_000))
    hp.pop("eval_freq", None)
    n_eval = int(eval_episodes if eval_episodes is not None else hp.pop("n_eval_episodes", 10))
    hp.pop("n_eval_episodes", None)
    policy = hp.pop("policy", "MlpPolicy")
    cfg_vec = hp.pop("vec_env", "batched")
    vec_env = vec_env or cfg_vec
    if vec_env not in VEC_ENVS:
        raise ValueError(f"vec_env must be one of {', '.join(VEC_ENVS)}, got {vec_env!r}")
    if n_envs < 1 or n_timesteps < 1:
        raise ValueError("--n-envs and --timesteps must be positive")
    frame_stack = int(hp.pop("frame_stack", 1) or 1)
    if frame_stack < 1:
        raise ValueError(f"frame_stack must be a positive integer, got {frame_stack}")
    norm_kw = _normalize_kwargs(hp.pop("normalize", None), hp.get("gamma"))
    residual = hp.pop("residual", None)
    residual_scale = float(hp.pop("residual_scale", 0.5))
    if residual is not None and norm_kw is not None:
        raise ValueError("residual: the base controller reads raw observations; drop normalize")
    eval_kw = hp.pop("eval_env_kwargs", None) or {}
    if not isinstance(eval_kw, dict):
        raise ValueError(f"eval_env_kwargs must be a mapping of env kwargs, got {eval_kw!r}")
    hyperparams = copy.deepcopy(hp)  # as written in the YAML, for the record

    out = check_writable_dir(out if out is not None else default_out(algo, env_id, seed))
    if threads:
        torch.set_num_threads(int(threads))
    out.mkdir(parents=True, exist_ok=True)

    if vec_env == "auto":
        vec_env = "batched"
    make = _make_env_fn(env_id, resolved_env_kwargs)
    if vec_env == "batched":
        from stable_baselines3.common.vec_env import VecMonitor

        from .vecenv import BatchedVecEnv, make_batched_vec_env

        venv = VecMonitor(
            make_batched_vec_env(env_id, n_envs, seed=seed, env_kwargs=resolved_env_kwargs)
        )
        vec_name = BatchedVecEnv.__name__
    else:
        vec_cls = SubprocVecEnv if vec_env == "subproc" else DummyVecEnv
        venv = make_vec_env(make, n_envs=n_envs, seed=seed, vec_env_cls=vec_cls)
        vec_name = vec_cls.__name__
    # the periodic evaluations (best-model selection) may use other scenes, e.g. a validation
    # pool: eval_env_kwargs {"scene_pool_seed": 2}
    make_eval = _make_env_fn(env_id, {**resolved_env_kwargs, **eval_kw}) if eval_kw else make
    eval_env = make_vec_env(
        make_eval, n_envs=1, seed=seed + EVAL_SEED_OFFSET, vec_env_cls=DummyVecEnv
    )
    if norm_kw is not None:
        from stable_baselines3.common.vec_env import VecMonitor, VecNormalize

        if vec_env == "batched":  # wrapped like the training env, so the statistics sync
            eval_env.close()
            eval_env = DummyVecEnv([make_eval])
            eval_env.seed(seed + EVAL_SEED_OFFSET)
            eval_env = VecMonitor(eval_env)
        venv = VecNormalize(venv, **norm_kw)
        # the evaluation env uses the training statistics (EvalCallback syncs them), frozen
        eval_env = VecNormalize(
            eval_env,
            training=False,
            norm_reward=False,
            **{k: v for k, v in norm_kw.items() if k not in ("norm_reward",)},
        )
    if frame_stack > 1:
        from stable_baselines3.common.vec_env import VecFrameStack

        venv = VecFrameStack(venv, frame_stack)
        eval_env = VecFrameStack(eval_env, frame_stack)
    if residual is not None:  # the agent corrects a fixed controller (agents.learning.residual)
        from .residual import ResidualVecEnv

        venv = ResidualVecEnv(venv, str(residual), residual_scale)
        eval_env = ResidualVecEnv(eval_env, str(residual), residual_scale)

    kwargs = dict(hp)
    pk = dict(kwargs.pop("policy_kwargs", None) or {})
    if "activation_fn" in pk:
        pk["activation_fn"] = _activation(pk["activation_fn"])
    if pk:
        kwargs["policy_kwargs"] = pk
    if "action_noise" in kwargs:
        kwargs["action_noise"] = _action_noise(kwargs["action_noise"], venv.action_space)
    if tensorboard is None:
        tensorboard = importlib.util.find_spec("tensorboard") is not None
        if not tensorboard and verbose:
            print(
                "note: tensorboard is not installed, so no TensorBoard logs are written "
                "(pip install 'sensorplan-gym[rl]' installs it; --no-tensorboard hides this)",
                flush=True,
            )
    if tensorboard:
        kwargs["tensorboard_log"] = str(out / "tb")
    if progress_bar is None:
        progress_bar = all(importlib.util.find_spec(m) is not None for m in ("tqdm", "rich"))

    record: dict[str, Any] = {
        "algo": algo,
        "env_id": env_id,
        "env_kwargs": resolved_env_kwargs,
        "policy": policy,
        "frame_stack": frame_stack,
        **({"residual": str(residual), "residual_scale": residual_scale} if residual else {}),
        "normalize": norm_kw is not None,
        "normalize_kwargs": norm_kw,
        "hyperparams": hyperparams,
        "seed": int(seed),
        "timesteps": n_timesteps,
        "n_envs": n_envs,
        "vec_env": vec_env,
        "torch_threads": int(threads or torch.get_num_threads()),
        "eval": {
            "freq": freq,
            "episodes": n_eval,
            "seed": seed + EVAL_SEED_OFFSET,
            **({"env_kwargs": eval_kw} if eval_kw else {}),
        },
        "versions": {
            "sensorplan-gym": package_version(),
            "stable-baselines3": str(stable_baselines3.__version__),
            "torch": str(torch.__version__),
            "gymnasium": str(gym.__version__),
            "python": platform.python_version(),
        },
        "command": " ".join(
            [
                "sensorplan",
                "train",
                "--env",
                env_id,
                "--algo",
                algo,
                "--timesteps",
                str(n_timesteps),
                "--seed",
                str(seed),
                "--n-envs",
                str(n_envs),
            ]
            + (["--env-kwargs", json.dumps(env_kwargs)] if env_kwargs else [])
            + (["--config", str(config)] if config else [])
            + (
                ["--hp", *(f"{k}={json.dumps(v)}" for k, v in hp_overrides.items())]
                if hp_overrides
                else []
            )
            + (["--resume", str(resume)] if resume else [])
        ),
    }
    t0 = time.perf_counter()

    def write_config(path: Path, extra: dict | None = None) -> None:
        rec = dict(record)
        rec["wall_time_s"] = round(time.perf_counter() - t0, 1)
        if extra:
            rec["selected_at"] = extra
        with open(path, "w") as f:
            stamp = time.strftime("%Y-%m-%d")
            f.write(f"# resolved config written by sensorplan train ({stamp})\n")
            yaml.safe_dump(rec, f, sort_keys=False)

    if resume is not None:
        if not Path(resume).exists():
            raise FileNotFoundError(f"--resume: no saved model at {resume}")
        model = algo_class(algo).load(resume, env=venv, device=device)
        model.set_random_seed(seed)
        if norm_kw is not None:
            from .policies import vecnormalize_path

            stats = vecnormalize_path(resume)
            if stats.is_file():  # carry on with the saved statistics
                import pickle

                with open(stats, "rb") as f:
                    saved = pickle.load(f)
                venv_norm = model.get_vec_normalize_env()
                venv_norm.obs_rms, venv_norm.ret_rms = saved.obs_rms, saved.ret_rms
    else:
        model = algo_class(algo)(
            policy, venv, seed=seed, verbose=0 if verbose < 2 else 1, device=device, **kwargs
        )
    callback = _eval_callback_cls()(
        eval_env,
        best_path=out / "best_model.zip",
        write_config=write_config,
        n_eval_episodes=n_eval,
        eval_freq=max(freq // n_envs, 1),
        log_path=str(out),
        deterministic=True,
        verbose=verbose,
    )
    if verbose:
        print(
            f"training {algo.upper()} on {env_id} {resolved_env_kwargs} for {n_timesteps} steps, "
            f"seed {seed}, {n_envs} x {vec_name} -> {out}",
            flush=True,
        )
        if resolved_env_kwargs.get("shaping"):
            print(
                f"note: the returns printed while training (SB3's 'episode_reward', the best "
                f"model's 'return') include the reward shaping (shaping="
                f"{resolved_env_kwargs['shaping']}); `sensorplan evaluate` reports the "
                "task's return without shaping, so the two differ",
                flush=True,
            )
    try:
        warnings.filterwarnings("ignore", message="Training and eval env are not of the same type")
        callbacks: list = [callback]
        if checkpoint_freq:
            from stable_baselines3.common.callbacks import CheckpointCallback

            callbacks.append(
                CheckpointCallback(
                    max(int(checkpoint_freq) // n_envs, 1), str(out / "checkpoints"), algo
                )
            )
        model.learn(
            total_timesteps=n_timesteps,
            callback=callbacks,
            progress_bar=progress_bar,
            tb_log_name=f"{algo}_s{seed}",
            reset_num_timesteps=resume is None,
        )
    finally:
        venv.close()
    train_time = time.perf_counter() - t0
    record["train_time_s"] = round(train_time, 1)
    model.save(out / "final_model.zip")
    _save_vecnormalize(model, out / "final_model.zip")
    write_config(out / "final_model.yaml")
    if callback.best_info is None:  # no evaluation ran (short run): the final model is the best
        shutil.copyfile(out / "final_model.zip", out / "best_model.zip")
        _save_vecnormalize(model, out / "best_model.zip")
        write_config(
            out / "best_model.yaml",
            {"timesteps": int(model.num_timesteps), "success_rate": None, "mean_return": None},
        )
    else:
        # rewrite so the best model's config carries the total training time too
        write_config(out / "best_model.yaml", callback.best_info)
    eval_env.close()
    record.update(
        {
            "out": str(out),
            "best_model": str(out / "best_model.zip"),
            "final_model": str(out / "final_model.zip"),
            "best": callback.best_info,
        }
    )
    if verbose:
        print(
            f"done in {train_time:.1f} s; best model {out / 'best_model.zip'} "
            f"{callback.best_info or ''}",
            flush=True,
        )
    return record

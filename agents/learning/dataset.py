"""Oracle demonstrations as Minari datasets (the Farama standard for offline RL).

``sensorplan dataset record --env sensorplan/Recognize-v0 --episodes 100 \\
    --dataset-id sensorplan/recognize-lab-oracle-v0 [--env-kwargs JSON] [--seed S]``

:func:`record_dataset` plays ``episodes`` episodes of the exact planner
(:class:`agents.planning.oracle.OraclePolicy`) and writes them with
``minari.create_dataset_from_buffers`` (``minari.DataCollector`` would need jax) as a dataset
that ``minari.load_dataset(dataset_id)`` loads: per episode the observations
(``T + 1`` rows, the env's observation space), the oracle's actions (``T`` rows, the env's
action space), rewards, terminations and truncations.  The env spec (id and kwargs) is stored
with it, so ``dataset.recover_environment()`` rebuilds the env.  Episode ``k`` is reset with
seed ``seed + k``.

Datasets go where Minari keeps them (``~/.minari/datasets``, or ``$MINARI_DATASETS_PATH``);
``data_path`` / ``--data-path`` sets that folder for the call.  Needs the ``imitation`` extra
(``pip install 'sensorplan-gym[imitation]'``: minari with its HDF5 backend).
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import gymnasium as gym
import minari
import numpy as np
from minari.data_collector import EpisodeBuffer

import sensorplan_gym  # noqa: F401  (registers the env ids)

from ..planning.oracle import OraclePolicy

__all__ = ["dataset_root", "load_dataset", "record_dataset"]


@contextlib.contextmanager
def dataset_root(path: str | Path | None) -> Iterator[None]:
    """Within the block, Minari reads and writes datasets under ``path`` (``None``: leave
    Minari's default, ``$MINARI_DATASETS_PATH`` or ``~/.minari/datasets``)."""
    if path is None:
        yield
        return
    old = os.environ.get("MINARI_DATASETS_PATH")
    os.environ["MINARI_DATASETS_PATH"] = str(Path(path).resolve())
    try:
        yield
    finally:
        if old is None:
            os.environ.pop("MINARI_DATASETS_PATH", None)
        else:
            os.environ["MINARI_DATASETS_PATH"] = old


def _check_id(dataset_id: str) -> None:
    # Minari's ids are "[namespace/]name-v<version>"; say so before it fails deep inside
    name = dataset_id.rsplit("/", 1)[-1]
    head, sep, ver = name.rpartition("-v")
    if not (sep and head and ver.isdigit()):
        raise ValueError(
            f"dataset id {dataset_id!r} must look like 'namespace/name-v0' "
            "(Minari's format: a name, '-v' and a version number)"
        )


def record_dataset(
    env_id: str,
    dataset_id: str,
    episodes: int,
    *,
    env_kwargs: dict[str, Any] | None = None,
    seed: int = 0,
    data_path: str | Path | None = None,
    author: str | None = None,
    overwrite: bool = False,
) -> minari.MinariDataset:
    """Record ``episodes`` oracle episodes of ``env_id`` (``gym.make(env_id, **env_kwargs)``)
    as the Minari dataset ``dataset_id``; returns the dataset (as ``minari.load_dataset``
    returns it).  ``overwrite`` deletes an existing dataset of that id first; otherwise an
    existing id raises ``ValueError``."""
    if not isinstance(episodes, int) or episodes < 1:
        raise ValueError(f"episodes must be a positive integer, got {episodes!r}")
    _check_id(dataset_id)
    with dataset_root(data_path):
        if dataset_id in minari.list_local_datasets():
            if not overwrite:
                raise ValueError(
                    f"a dataset {dataset_id!r} exists already under {_root()}; "
                    "choose another id or overwrite it"
                )
            minari.delete_dataset(dataset_id)
        env = gym.make(env_id, **(env_kwargs or {}))
        oracle = OraclePolicy(env)
        buffers, successes = [], 0
        for k in range(episodes):
            obs, _ = env.reset(seed=seed + k)
            o, a, r, te, tr = [obs], [], [], [], []
            done = False
            while not done:
                action, _ = oracle.predict(obs)
                obs, reward, term, trunc, info = env.step(action)
                o.append(obs)
                a.append(np.asarray(action, dtype=env.action_space.dtype))
                r.append(float(reward))
                te.append(bool(term))
                tr.append(bool(trunc))
                done = term or trunc
            successes += bool(info.get("is_success"))
            buffers.append(
                EpisodeBuffer(
                    id=k,
                    seed=seed + k,
                    observations=np.stack(o),
                    actions=np.stack(a),
                    rewards=r,
                    terminations=te,
                    truncations=tr,
                )
            )
        ds = minari.create_dataset_from_buffers(
            dataset_id=dataset_id,
            buffer=buffers,
            env=env,
            eval_env=env.spec,
            algorithm_name="sensorplan oracle (agents.planning.oracle.OraclePolicy)",
            author=author or "sensorplan-gym",
            code_permalink="https://github.com/sensorplan-gym",
            description=(
                f"{episodes} episodes of the exact planner on {env_id} "
                f"with {env_kwargs or {}}, reset seeds {seed}..{seed + episodes - 1}; "
                f"{successes} successes"
            ),
            data_format="hdf5",
        )
        env.close()
        return ds


def load_dataset(dataset_id: str, data_path: str | Path | None = None) -> minari.MinariDataset:
    """``minari.load_dataset(dataset_id)`` reading from ``data_path`` (default: Minari's)."""
    with dataset_root(data_path):
        return minari.load_dataset(dataset_id)


def _root() -> str:
    return os.environ.get("MINARI_DATASETS_PATH") or str(Path("~/.minari/datasets").expanduser())


def transitions(dataset: minari.MinariDataset) -> tuple[np.ndarray, np.ndarray]:
    """All ``(observation, action)`` pairs of a dataset, stacked: ``(n, *obs_shape)`` and
    ``(n, *action_shape)`` (an episode's last observation, which has no action, is left
    out): what behaviour cloning trains on."""
    obs, act = [], []
    for ep in dataset.iterate_episodes():
        obs.append(np.asarray(ep.observations)[:-1])
        act.append(np.asarray(ep.actions))
    return np.concatenate(obs), np.concatenate(act)

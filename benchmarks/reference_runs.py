"""The cells of the reference grid and where their results go: one task per cell, run in this
process or as Ray tasks (a local Ray instance or an existing cluster), results written
atomically as each cell finishes.

A *cell* is one training run (an entry of :data:`benchmarks.reference.GRID` and one seed) or
one evaluation (a trained run, or a baseline policy, on every benchmark split).  The cell
functions (:func:`train_cell`, :func:`evaluate_cell`) take plain, picklable specs and return
plain data; they never write outside a temporary folder of their own, so that they run the same
on a Ray worker of another machine as in this process:

* :func:`train_cell` trains into a temporary folder and returns the run folder's files (the
  models, their resolved configs and normalization statistics: a few MB) as bytes;
* :func:`evaluate_cell` gets those files as bytes, runs
  :func:`agents.evaluation.benchmark.benchmark` on them and returns the per-split summary.

The driver (:func:`run_cells`) submits every cell, collects the results as they finish
(``ray.wait``) and hands each to a callback that writes it at once: run folders are written
into ``<run>.partial`` and renamed (:func:`install_run`), result files into a temporary file
and renamed (:func:`write_json`), so an interrupted grid leaves only finished cells and a
restart runs only the rest.

Ray is in the ``multi`` extra; importing this module does not import Ray.  On a cluster the
workers import this project from their own Python environment: install the same version of
sensorplan-gym (and its ``rl`` extra) on every node, or ship the source with
``--working-dir .`` (Ray's ``runtime_env``; the dependencies must still be installed there).
"""

from __future__ import annotations

import json
import os
import re
import shutil
import tempfile
import time
import traceback
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

__all__ = [
    "RUN_FILES",
    "evaluate_cell",
    "init_ray",
    "install_run",
    "read_run",
    "run_cells",
    "train_cell",
    "write_json",
]

#: the files of a run folder that a cell ships back (not tensorboard logs or checkpoints)
RUN_FILES = ("*.zip", "*.yaml", "*.pkl", "*.npz", "*.csv", "*.json")


# ---- files -------------------------------------------------------------------------------


def write_json(path: Path, data: Any) -> Path:
    """Write ``data`` as indented JSON to ``path`` atomically (a temporary file in the same
    folder, then renamed): a reader sees the old file or the whole new one, never a part."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            json.dump(data, f, indent=1, ensure_ascii=False)
            f.write("\n")
        os.chmod(tmp, 0o644)  # mkstemp makes it private; a result file is for everyone
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def read_run(folder: Path, model: str | None = None) -> dict[str, bytes]:
    """The files of a run folder (:data:`RUN_FILES`, top level only) as ``{name: bytes}``;
    ``model`` (e.g. ``"best_model"``): only that model's files (its zip, resolved config and
    normalization statistics), what an evaluation needs."""
    folder = Path(folder)
    return {
        p.name: p.read_bytes()
        for pattern in RUN_FILES
        for p in sorted(folder.glob(pattern))
        if p.is_file() and (model is None or p.stem == model or p.name.startswith(model + "_"))
    }


def install_run(out: Path, files: dict[str, bytes]) -> Path:
    """Write a trained run's ``files`` to the folder ``out`` atomically: into
    ``<out>.partial`` first, then renamed.  An unfinished folder at ``out`` (no
    ``final_model.zip``: a run killed before it finished, by the serial trainer of earlier
    versions) is replaced; a finished one is an error (the caller skips finished runs)."""
    out = Path(out)
    if "final_model.zip" not in files:
        raise ValueError(f"{out}: the run's files hold no final_model.zip: {sorted(files)}")
    if (out / "final_model.zip").is_file():
        raise FileExistsError(f"{out} is a finished run already; not overwritten")
    part = out.with_name(out.name + ".partial")
    if part.exists():
        shutil.rmtree(part)
    part.mkdir(parents=True)
    for name, data in files.items():
        (part / name).write_bytes(data)
    if out.exists():
        shutil.rmtree(out)
    os.replace(part, out)
    return out


# ---- the cells ---------------------------------------------------------------------------


def _config_path(config: str | None) -> str | None:
    """A grid entry's config as the worker can read it: the path as given when it exists
    there (a local worker, or ``--working-dir``), else the file of that name in the installed
    package's ``agents/configs``."""
    if config is None or Path(config).is_file():
        return config
    from agents.learning.train import CONFIG_DIR

    cand = Path(CONFIG_DIR) / Path(config).name
    if not cand.is_file():
        raise FileNotFoundError(f"config {config!r}: not found here nor as {cand}")
    return str(cand)


def train_cell(spec: dict[str, Any]) -> dict[str, Any]:
    """Train one grid cell; returns ``{"files": {name: bytes}, "train_time_s": float,
    "host": str}``.  ``spec``: ``env_id``, ``algo``, ``timesteps``, ``seed``, ``env_kwargs``,
    ``hp`` (hyperparameter overrides), ``config`` (a path or ``None``), ``threads`` (torch
    threads).  Trains exactly what ``sensorplan train`` with the same arguments trains."""
    import platform

    from agents.learning.train import train

    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="sensorplan-cell-") as tmp:
        out = Path(tmp) / "run"
        train(
            spec["env_id"],
            spec["algo"],
            timesteps=spec["timesteps"],
            seed=spec["seed"],
            env_kwargs=spec["env_kwargs"],
            config=_config_path(spec.get("config")),
            out=out,
            hp_overrides=spec.get("hp") or {},
            threads=int(spec.get("threads", 1)),
            tensorboard=False,
            progress_bar=False,
            verbose=0,
        )
        files = read_run(out)
    return {
        "files": files,
        "train_time_s": time.perf_counter() - t0,
        "host": platform.node(),
    }


def _split_summary(p: dict[str, Any], start_distance: Any) -> dict[str, Any]:
    return {
        "episodes": p["episodes"],
        "successes": p["successes"],
        "success_rate": p["success_rate"],
        "success_ci95": list(p["success_ci95"]),
        "mean_return": p["mean_return"],
        "mean_steps": p["mean_steps"],
        "mean_path_length": p["mean_path_length"],
        "start_distance": start_distance,
    }


def evaluate_cell(spec: dict[str, Any], files: dict[str, bytes] | None = None) -> dict[str, Any]:
    """Evaluate one policy on every benchmark split; returns ``{"splits": {split: summary},
    "benchmark": the full result of benchmark(), "host": str}`` where a summary holds the
    episodes, successes, success rate with its 95 % Wilson interval, mean return, steps, path
    length (scene units) and mean start distance (scene diameters) of that split.

    ``spec``: ``env_id``, ``env_kwargs`` (what the policy observes), ``episodes``,
    ``seed`` (evaluation seed), ``policy`` (``"oracle"``, ``"random"`` or ``"model"``: then
    ``files`` holds the run folder's files, and ``best_model.zip`` is evaluated)."""
    import platform

    from agents.evaluation.benchmark import benchmark

    with tempfile.TemporaryDirectory(prefix="sensorplan-cell-") as tmp:
        if spec["policy"] == "model":
            if not files or "best_model.zip" not in files:
                raise ValueError("evaluate_cell: a model cell needs the run's best_model.zip")
            run = Path(tmp) / "run"
            run.mkdir()
            for name, data in files.items():
                (run / name).write_bytes(data)
            policy = str(run / "best_model.zip")
        elif spec["policy"] in ("oracle", "random"):
            policy = spec["policy"]
        else:
            raise ValueError(f"evaluate_cell: unknown policy {spec['policy']!r}")
        res = benchmark(
            spec["env_id"],
            [policy],
            episodes=int(spec["episodes"]),
            seed=int(spec.get("seed", 0)),
            env_kwargs=dict(spec["env_kwargs"]),
            out=Path(tmp) / "benchmark",
            verbose=False,
        )
    splits = {
        name: _split_summary(r["policies"][0], r.get("start_distance"))
        for name, r in res["splits"].items()
    }
    for r in res["splits"].values():  # the temporary path means nothing to the driver
        for p in r["policies"]:
            p["spec"] = spec["policy"] if spec["policy"] != "model" else "best_model.zip"
    return {"splits": splits, "benchmark": res, "host": platform.node()}


# ---- running cells -----------------------------------------------------------------------


def init_ray(
    address: str | None = None,
    num_cpus: int | None = None,
    working_dir: str | None = None,
):
    """The ``ray`` module, initialised: connected to the cluster at ``address`` (``"auto"``,
    ``"ray://head:10001"``, ...) or a local instance with ``num_cpus`` CPUs (default all);
    ``working_dir``: shipped to the workers as Ray's ``runtime_env`` (for a cluster whose nodes
    do not have this version installed).  An initialised Ray is reused as it is."""
    try:
        import ray
    except ImportError as e:
        raise SystemExit(
            f"the Ray backend needs Ray ({e.name or 'ray'} is missing): pip install -e '.[multi]'"
        ) from None
    if not ray.is_initialized():
        kw: dict[str, Any] = {"log_to_driver": False}
        if working_dir:
            kw["runtime_env"] = {"working_dir": str(working_dir), "excludes": ["runs/", ".git/"]}
        if address:
            ray.init(address=address, **kw)
        else:
            ray.init(num_cpus=num_cpus, include_dashboard=False, **kw)
    return ray


def run_cells(
    fn: Callable[..., dict[str, Any]],
    cells: list[tuple[Any, tuple]],
    *,
    backend: str = "local",
    cpus_per_cell: float = 1,
    address: str | None = None,
    num_cpus: int | None = None,
    working_dir: str | None = None,
) -> Iterator[tuple[Any, dict[str, Any] | None, str | None]]:
    """Run ``fn(*args)`` for every ``(key, args)`` of ``cells``; yields ``(key, result,
    None)`` as each finishes (in order of completion), or ``(key, None, error text)`` when
    it raised -- the other cells go on.  ``backend``: ``"local"`` (one after the other, in
    this process) or ``"ray"`` (one Ray task per cell, each reserving ``cpus_per_cell`` CPUs;
    Ray runs as many at once as the CPUs allow)."""
    if backend == "local":
        for key, args in cells:
            try:
                yield key, fn(*args), None
            except Exception:  # noqa: BLE001 - reported per cell, the grid goes on
                yield key, None, traceback.format_exc()
        return
    if backend != "ray":
        raise ValueError(f"backend must be 'local' or 'ray', got {backend!r}")
    if not cells:
        return
    ray = init_ray(address, num_cpus, working_dir)
    # the cell functions travel with the tasks (by value): the workers need the installed
    # packages (agents, sensorplan_gym, geometry), not this benchmarks folder
    import importlib

    from ray import cloudpickle

    cloudpickle.register_pickle_by_value(importlib.import_module(fn.__module__))
    task = ray.remote(fn).options(num_cpus=cpus_per_cell)
    pending = {task.remote(*args): key for key, args in cells}
    while pending:
        done, _ = ray.wait(list(pending), num_returns=1)
        for ref in done:
            key = pending.pop(ref)
            try:
                yield key, ray.get(ref), None
            except Exception as e:  # noqa: BLE001 - a failed task: reported, the rest go on
                yield key, None, re.sub(r"\x1b\[[0-9;]*m", "", str(e))

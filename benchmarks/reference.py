"""The reference results of the learned baselines: train, evaluate and tabulate the grid.

The grid (:data:`GRID`) is algorithm x env entries, each trained with seeds 0-4 on the
procedural ``train`` pool.  Every training run and every evaluation is one *cell*; cells run
one after the other in this process (``--backend local``, the default) or as Ray tasks
(``--backend ray``): on a local Ray instance with all CPUs (``--num-cpus N`` to limit it) or
on an existing cluster (``--address auto`` / ``ray://head:10001``).  Each task reserves
``--cpus-per-cell`` CPUs (default 1; training uses that many torch threads) and Ray runs as
many as fit.  Results are written as each cell finishes, atomically, so an interrupted grid
(a crash, Ctrl-C, a lost node) is resumed by running the same command again: finished cells
are skipped, only the rest run.  ``BACKEND`` below stands for ``--backend ray [--address ADDR]
[--num-cpus N] [--cpus-per-cell C] [--working-dir DIR]``.

``python -m benchmarks.reference train [--only NAME ...] [--seeds 0 1 2 3 4] [BACKEND]``
    trains every entry x seed into ``runs/<name>_<env>_random[<variant>]_s<seed>/``; a run whose
    ``final_model.zip`` exists is skipped.  Each run is exactly the ``sensorplan train``
    command that ``--print`` shows.  Hours of CPU for the whole grid; one entry and seed
    takes minutes.  A Ray task trains in a temporary folder of its worker and ships the run's
    files (models, configs, normalization statistics: a few MB) back; the driver writes them
    to ``<run>.partial/`` and renames it, so a run folder with ``final_model.zip`` is always
    complete.
``python -m benchmarks.reference evaluate [--episodes 100] [--only ...] [--seeds ...] [BACKEND]``
    evaluates every finished run with ``sensorplan benchmark``
    (:func:`agents.evaluation.benchmark.benchmark`) on the splits ``train``, ``test``
    (held-out procedural scenes) and ``ood:<scene>`` (every bundled scene, never trained on),
    one cell per run, plus the baselines of each env (the oracle and uniform random actions;
    for discrete-action entries the random policy of the discrete set).  Each cell's result is
    one small JSON file under ``--results`` (default the tracked ``benchmarks/results/reference/``,
    see :mod:`benchmarks.reference_table`): ``<Env-v0>/<entry>/seed<k>.json`` and
    ``<Env-v0>/oracle.json`` ...; a cell whose file exists is skipped (``--again`` evaluates
    it again; delete one file to evaluate just that cell again).  The full benchmark output
    (per-episode lists) of each cell goes to ``runs/reference/`` (not tracked).
``python -m benchmarks.reference report [--results DIR] [--update-results]``
    the markdown table per env, computed from the per-run result files alone (so it is
    regenerated from a checkout, without ``runs/``): success per split, the interquartile
    mean over training seeds with its stratified-bootstrap 95 % interval
    (:mod:`agents.evaluation.stats`), the normalized score ``(agent - random) / (oracle -
    random)`` on the test split and, for Navigate, the mean path length over the oracle's.
    The table's data (``reference.json``) and the page fragment (``reference.md``) go to
    ``--out`` (default ``runs/benchmarks/reference/``), or with ``--update-results`` to the
    tracked ``benchmarks/results/reference.json`` and ``docs/results/reference.md``.  With
    no result file it says so and writes nothing.

``python -m benchmarks.reference import OLD [--results DIR]``
    per-run result files from the evaluations that earlier versions of this module wrote
    under ``runs/reference/`` (``<Env-v0>[-discrete]/benchmark.json`` and
    ``models-<entry>/benchmark.json``), for a machine that still has them.

On a cluster the workers run the cell functions (shipped with the tasks) against the
``sensorplan_gym`` / ``agents`` / ``geometry`` packages of their own Python environment:
install the same version of sensorplan-gym with the ``rl`` extra on every node, or pass
``--working-dir .`` to ship this checkout as Ray's ``runtime_env`` (its dependencies must still
be installed there).  The driver keeps the run folders and result files; the workers need no
shared file system.

The rows of runs trained before per-run results were kept (everything in the table up to this
version) come from ``<Env-v0>/<entry>/aggregate.json``: the earlier table's row, migrated as
it was (:func:`benchmarks.reference_table.migrate_table`).  Once an entry has a
``seed<k>.json``, its row is computed from its per-run files only.

Discrete-action agents (DQN) play the envs with ``action_type="discrete"``, where the
analytic oracle does not run: their normalized score uses the oracle's success from the
continuous env (1.00 on every split) and the random policy of the discrete action set.
"""

from __future__ import annotations

import argparse
import json
import shlex
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from . import _results
from . import reference_runs as runs
from . import reference_table as table

NAV = "sensorplan/Navigate-v0"
REC = "sensorplan/Recognize-v0"
PLACE = "sensorplan/Placement-v0"
RUNS = Path("runs")
#: the full benchmark output of each evaluated cell (not tracked)
OUT = RUNS / "reference"
ROOT = _results.ROOT
#: the per-run result files the table is made from (tracked)
RESULTS = ROOT / "benchmarks" / "results" / "reference"
SEEDS = (0, 1, 2, 3, 4)

#: training env kwargs per env: the procedural train pool at the benchmark's difficulty
NAV_TRAIN = {"scene": "random", "min_start_distance": 0.35, "max_scene_tries": 200}
REC_TRAIN = {"scene": "random", "min_start_distance": 0.2, "max_scene_tries": 200}
PLACE_TRAIN = {"scene": "random"}
#: evaluation env kwargs per env (what the agents observe; no reward shaping)
REC_EVAL = {"map_ranges": True, "map_evidence": True, "declare_hold": 3, "random_start": True}
EVAL_KWARGS = {NAV: {}, REC: REC_EVAL, PLACE: {}}

_PPO_NAV_HP = {
    "n_envs": 64,
    "n_steps": 32,
    "policy_kwargs": {"net_arch": [128, 128], "activation_fn": "tanh"},
    "eval_freq": 100_000,
    "n_eval_episodes": 100,
}
_PPO_PLACE_HP = {
    "n_envs": 64,
    "n_steps": 16,
    "batch_size": 256,
    "n_epochs": 10,
    "policy_kwargs": {"net_arch": [256, 256], "activation_fn": "tanh"},
    "eval_freq": 100_000,
    "n_eval_episodes": 200,
}

_SAC_NAV_HP = {
    "n_envs": 8,
    "vec_env": "batched",
    "eval_freq": 50_000,
    "n_eval_episodes": 100,
    "policy_kwargs": {"net_arch": [128, 128]},
}


@dataclass(frozen=True)
class Entry:
    """One cell family of the grid: an agent trained on one env's procedural scenes."""

    name: str  # run-folder prefix, e.g. "ppo" -> runs/ppo_navigate_random_s0
    label: str  # the table's row label
    env_id: str
    algo: str
    timesteps: int
    env_kwargs: dict[str, Any]
    hp: dict[str, Any] = field(default_factory=dict)
    config: str | None = None
    discrete: bool = False
    #: a training-distribution variant, e.g. "notch" (run folder ..._randomnotch_s0)
    variant: str = ""

    @property
    def key(self) -> str:
        """The entry's name for ``--only``: ``ppo``, ``ppo-notch``, ..."""
        return self.name + (f"-{self.variant}" if self.variant else "")

    def out(self, seed: int) -> Path:
        env = self.env_id.split("/")[-1].split("-v")[0].lower()
        return RUNS / f"{self.name}_{env}_random{self.variant}_s{seed}"

    def command(self, seed: int) -> str:
        """The ``sensorplan train`` command of this entry and seed."""
        parts = [
            "sensorplan train --env",
            self.env_id,
            "--algo",
            self.algo,
            "--timesteps",
            str(self.timesteps),
            "--seed",
            str(seed),
        ]
        if self.config:
            parts += ["--config", self.config]
        parts += ["--env-kwargs", shlex.quote(json.dumps(self.env_kwargs))]
        if self.hp:
            parts += ["--hp", *(shlex.quote(f"{k}={json.dumps(v)}") for k, v in self.hp.items())]
        parts += ["--out", str(self.out(seed))]
        return " ".join(parts)


GRID: list[Entry] = [
    Entry("ppo", "PPO", NAV, "ppo", 800_000, {**NAV_TRAIN, "random_start": False}, _PPO_NAV_HP),
    Entry(
        "ppo",
        "PPO, L-shaped rooms in training",
        NAV,
        "ppo",
        800_000,
        {**NAV_TRAIN, "random_start": False, "random_scene_kwargs": {"notch_size": [0.3, 0.75]}},
        _PPO_NAV_HP,
        variant="notch",
    ),
    Entry("ppo", "PPO", REC, "ppo", 800_000, REC_TRAIN),
    Entry("ppo", "PPO", PLACE, "ppo", 300_000, {**PLACE_TRAIN, "shaping": 1.0}, _PPO_PLACE_HP),
    Entry(
        "ppo",
        "PPO, 4,096 training scenes",
        PLACE,
        "ppo",
        300_000,
        {**PLACE_TRAIN, "shaping": 1.0, "scene_pool_size": 4096},
        _PPO_PLACE_HP,
        variant="pool4096",
    ),
    Entry(
        "ppofs4",
        "PPO + 4 stacked frames (memory)",
        REC,
        "ppo",
        800_000,
        REC_TRAIN,
        config="agents/configs/ppo_framestack.yaml",
    ),
    Entry(
        "ppofs4",
        "PPO + 4 stacked frames (memory)",
        NAV,
        "ppo",
        800_000,
        {**NAV_TRAIN, "random_start": False},
        config="agents/configs/ppo_framestack.yaml",
    ),
    Entry(
        "dqn",
        "DQN (discrete actions)",
        PLACE,
        "dqn",
        200_000,
        {**PLACE_TRAIN, "action_type": "discrete"},
        {"eval_freq": 50_000, "n_eval_episodes": 200},
        discrete=True,
    ),
    Entry(
        "dqn",
        "DQN (discrete actions)",
        REC,
        "dqn",
        400_000,
        {**REC_TRAIN, "action_type": "discrete", "map_evidence": True, "random_start": True},
        {"eval_freq": 100_000, "n_eval_episodes": 100},
        discrete=True,
    ),
    Entry(
        "dqn",
        "DQN (discrete actions)",
        NAV,
        "dqn",
        400_000,
        {**NAV_TRAIN, "action_type": "discrete"},
        {"eval_freq": 100_000, "n_eval_episodes": 100},
        discrete=True,
    ),
    Entry(
        "sac",
        "SAC",
        PLACE,
        "sac",
        50_000,
        {**PLACE_TRAIN, "shaping": 1.0},
        {
            "n_envs": 8,
            "vec_env": "batched",
            "eval_freq": 10_000,
            "n_eval_episodes": 200,
            "policy_kwargs": {"net_arch": [256, 256]},
        },
    ),
    Entry("sac", "SAC", REC, "sac", 200_000, REC_TRAIN),
    Entry(
        "sac",
        "SAC, 1 gradient step per env step",
        REC,
        "sac",
        200_000,
        REC_TRAIN,
        {"gradient_steps": 8},
        variant="utd1",
    ),
    Entry(
        "sac",
        "SAC",
        NAV,
        "sac",
        200_000,
        NAV_TRAIN,
        _SAC_NAV_HP,
    ),
    Entry(
        "sac",
        "SAC, 1 gradient step per env step",
        NAV,
        "sac",
        200_000,
        NAV_TRAIN,
        {**_SAC_NAV_HP, "gradient_steps": 8},
        variant="utd1",
    ),
]


def _selected(only: list[str] | None) -> list[Entry]:
    if not only:
        return GRID
    keys = {f"{e.key}:{e.env_id.split('/')[-1]}" for e in GRID} | {e.key for e in GRID}
    bad = [o for o in only if o not in keys]
    if bad:
        raise SystemExit(f"unknown entries {bad}; choose from {sorted(keys)}")
    return [e for e in GRID if e.key in only or f"{e.key}:{e.env_id.split('/')[-1]}" in only]


def _backend(args: argparse.Namespace) -> dict[str, Any]:
    return {
        "backend": args.backend,
        "address": args.address,
        "num_cpus": args.num_cpus,
        "cpus_per_cell": args.cpus_per_cell,
        "working_dir": args.working_dir,
    }


def _train_spec(e: Entry, seed: int, threads: int) -> dict[str, Any]:
    return {
        "env_id": e.env_id,
        "algo": e.algo,
        "timesteps": e.timesteps,
        "seed": int(seed),
        "env_kwargs": e.env_kwargs,
        "hp": _hp(e),
        "config": e.config,
        "threads": threads,
    }


def _hp(e: Entry) -> dict[str, Any]:
    """The entry's hyperparameter overrides as ``sensorplan train --hp`` reads them."""
    from agents.cli import _hp_overrides

    return _hp_overrides([f"{k}={json.dumps(v)}" for k, v in e.hp.items()]) if e.hp else {}


def train_grid(
    entries: list[Entry], seeds: list[int], **backend: Any
) -> tuple[int, int, list[str]]:
    """Train every entry x seed whose final model is missing (the commands of ``--print``),
    one cell per run; ``backend``: the keywords of
    :func:`benchmarks.reference_runs.run_cells` (``backend="ray"``: one Ray task per run,
    ``cpus_per_cell`` CPUs each).  Each finished run is written to ``runs/<...>_s<seed>/`` as
    it finishes (atomically), so an interrupted grid restarts with the unfinished runs only.
    Returns ``(runs already finished, runs trained, failures)``."""
    done, todo = 0, []
    for e in entries:
        for s in seeds:
            if (e.out(s) / "final_model.zip").is_file():
                print(f"skip {e.out(s)} (trained)", flush=True)
                done += 1
            else:
                todo.append((e, s))
    threads = max(1, int(backend.get("cpus_per_cell") or 1))
    cells = [((e, s), (_train_spec(e, s, threads),)) for e, s in todo]
    for e, s in todo:
        print(e.command(s), flush=True)
    trained, failed = 0, []
    for (e, s), res, err in runs.run_cells(runs.train_cell, cells, **backend):
        if err is not None:
            failed.append(f"{e.out(s)}: {err}")
            print(f"FAILED {e.out(s)}:\n{err}", flush=True)
            continue
        runs.install_run(e.out(s), res["files"])
        trained += 1
        print(f"trained {e.out(s)} in {res['train_time_s']:.0f} s on {res['host']}", flush=True)
    return done, trained, failed


def _trained_seeds(e: Entry, seeds: list[int] | None) -> list[int]:
    """The seeds of ``e`` whose run finished (``final_model.zip`` and ``best_model.zip``)."""
    return [
        s
        for s in (seeds if seeds is not None else range(100))
        if (e.out(s) / "best_model.zip").is_file() and (e.out(s) / "final_model.zip").is_file()
    ]


def _eval_kwargs(env_id: str, discrete: bool) -> dict[str, Any]:
    return dict(EVAL_KWARGS[env_id], **({"action_type": "discrete"} if discrete else {}))


def evaluate_grid(
    episodes: int,
    seed: int = 0,
    envs: list[str] | None = None,
    only: list[Entry] | None = None,
    seeds: list[int] | None = None,
    again: bool = False,
    results: Path | None = None,
    **backend: Any,
) -> tuple[int, int, list[str]]:
    """Evaluate every finished run of the selected entries (``only``, or the whole grid;
    ``envs``: only these env ids; ``seeds``: only these training seeds) and the baselines of
    their envs (oracle and random, or the random policy of the discrete action set) with
    :func:`agents.evaluation.benchmark.benchmark` on every split, one cell per run and
    baseline; each result is written to its file under ``results`` (default the tracked
    :data:`RESULTS`) as it finishes.  A cell whose result file exists is skipped unless
    ``again``.  The full benchmark output of each cell goes to ``runs/reference/`` (not
    tracked).  Returns ``(finished runs found, cells evaluated, failures)``."""
    results = Path(results) if results is not None else RESULTS
    chosen = [e for e in (only if only is not None else GRID) if envs is None or e.env_id in envs]
    cells: list[tuple[tuple, tuple]] = []
    found = 0
    groups: list[tuple[str, bool]] = []
    for e in chosen:
        trained = _trained_seeds(e, seeds)
        found += len(trained)
        if trained and (e.env_id, e.discrete) not in groups:
            groups.append((e.env_id, e.discrete))
        for s in trained:
            f = table.run_file(results, e.env_id, e.key, s)
            if f.is_file() and not again:
                continue
            spec = {
                "env_id": e.env_id,
                "env_kwargs": _eval_kwargs(e.env_id, e.discrete),
                "episodes": episodes,
                "seed": seed,
                "policy": "model",
            }
            cells.append((("run", e, s, f, spec), (spec, runs.read_run(e.out(s), "best_model"))))
    for env_id, discrete in groups:
        for name in ("random-discrete",) if discrete else ("oracle", "random"):
            f = table.baseline_file(results, env_id, name)
            if f.is_file() and not again and "splits" in json.loads(f.read_text()):
                continue  # evaluated (a migrated baseline is evaluated again)
            spec = {
                "env_id": env_id,
                "env_kwargs": _eval_kwargs(env_id, discrete),
                "episodes": episodes,
                "seed": seed,
                "policy": name.split("-")[0],
            }
            cells.append((("baseline", name, discrete, f, spec), (spec, None)))
    evaluated, failed = 0, []
    for key, res, err in runs.run_cells(runs.evaluate_cell, cells, **backend):
        kind, f, spec = key[0], key[3], key[4]
        if err is not None:
            failed.append(f"{f}: {err}")
            print(f"FAILED {f}:\n{err}", flush=True)
            continue
        evaluation = {
            "episodes": spec["episodes"],
            "seed": spec["seed"],
            "env_kwargs": spec["env_kwargs"],
            "difficulty": res["benchmark"]["difficulty"],
            "deterministic": res["benchmark"]["deterministic"],
        }
        if kind == "run":
            e, s = key[1], key[2]
            cfg = _run_config(e.out(s))
            rec = {
                "entry": e.key,
                "label": e.label,
                "env_id": e.env_id,
                "discrete": e.discrete,
                "seed": s,
                "run": str(e.out(s)),
                "command": e.command(s),
                "timesteps": e.timesteps,
                "train_time_s": cfg.get("train_time_s"),
                "versions": cfg.get("versions"),
                "evaluation": evaluation,
                "splits": res["splits"],
            }
            detail = OUT / e.env_id.split("/")[-1] / e.key / f"seed{s}.benchmark.json"
        else:
            name, discrete = key[1], key[2]
            rec = {
                "policy": spec["policy"],
                "env_id": spec["env_id"],
                "discrete": discrete,
                "evaluation": evaluation,
                "splits": res["splits"],
            }
            detail = OUT / spec["env_id"].split("/")[-1] / f"{name}.benchmark.json"
        runs.write_json(f, rec)
        runs.write_json(detail, res["benchmark"])
        evaluated += 1
        print(f"evaluated -> {f} (on {res['host']})", flush=True)
    return found, evaluated, failed


def _run_config(run: Path) -> dict[str, Any]:
    """The resolved training config of a finished run (``final_model.yaml``)."""
    from agents.learning.policies import model_config

    return model_config(str(run / "final_model.zip")) or {}


def import_evaluations(old: Path, results: Path | None = None) -> list[Path]:
    """Per-run result files (under ``results``, default the tracked :data:`RESULTS`) from the
    evaluations of earlier versions of this module under ``old`` (their ``runs/reference/``:
    ``<Env-v0>[-discrete]/benchmark.json`` and ``.../models-<entry>[.k]/benchmark.json``, a
    newer file's result of a model replacing an older one's, as their report merged them).
    A model is matched to its grid entry and seed by its run folder's name; its training time
    is read from the run folder when it is there.  Returns the files written."""
    from agents.learning.policies import model_config

    results = Path(results) if results is not None else RESULTS
    written: list[Path] = []
    for env_id in (PLACE, REC, NAV):
        for discrete in (False, True):
            group = Path(old) / (env_id.split("/")[-1] + ("-discrete" if discrete else ""))
            extra = sorted(group.glob("models-*/benchmark.json"), key=lambda f: f.stat().st_mtime)
            files = [group / "benchmark.json"] if (group / "benchmark.json").is_file() else []
            per: dict[str, dict[str, Any]] = {}
            for f in files + extra:
                b = json.loads(f.read_text())
                evaluation = {k: b.get(k) for k in ("episodes", "seed", "difficulty")}
                evaluation["deterministic"] = b.get("deterministic", True)
                evaluation["env_kwargs"] = _eval_kwargs(env_id, discrete)
                for sp, r in b["splits"].items():
                    for p in r["policies"]:
                        d = per.setdefault(p["spec"], {"kind": p["kind"], "splits": {}})
                        d.update(evaluation=evaluation, source=str(f))
                        d["splits"][sp] = runs._split_summary(p, r.get("start_distance"))
            for spec, d in per.items():
                common = {"evaluation": d["evaluation"], "splits": d["splits"]}
                common["imported_from"] = d["source"]
                if d["kind"] in ("oracle", "random"):
                    name = "random-discrete" if discrete else d["kind"]
                    f = table.baseline_file(results, env_id, name)
                    rec = {"policy": d["kind"], "env_id": env_id, "discrete": discrete, **common}
                    written.append(runs.write_json(f, rec))
                    continue
                run = Path(spec).parent
                entry = next(
                    (
                        e
                        for e in GRID
                        if e.env_id == env_id
                        and e.discrete == discrete
                        and run.name.startswith(e.out(0).name[:-1])
                    ),
                    None,
                )
                seed = run.name.rpartition("_s")[2]
                if entry is None or not seed.isdigit():
                    raise SystemExit(f"{d['source']}: model {spec!r} is no run of the grid")
                cfg = model_config(spec) if Path(spec).is_file() else None
                rec = {
                    "entry": entry.key,
                    "label": entry.label,
                    "env_id": env_id,
                    "discrete": discrete,
                    "seed": int(seed),
                    "run": str(run),
                    "command": entry.command(int(seed)),
                    "timesteps": entry.timesteps,
                    "train_time_s": (cfg or {}).get("train_time_s"),
                    "versions": (cfg or {}).get("versions"),
                    **common,
                }
                f = table.run_file(results, env_id, entry.key, int(seed))
                written.append(runs.write_json(f, rec))
    return written


def report_data(results: Path | None = None) -> dict[str, Any]:
    """The tables' data from the per-run result files under ``results`` (default the tracked
    :data:`RESULTS`) alone: per env the splits and one row per baseline and per grid entry
    (:func:`benchmarks.reference_table.report_data`)."""
    return table.report_data(
        results if results is not None else RESULTS, GRID, envs=(PLACE, REC, NAV)
    )


def render(data: dict[str, Any]) -> str:
    """The markdown table per env of :func:`report_data`'s data."""
    return table.render(data)


def report(results: Path | None = None) -> str:
    """The markdown tables of the evaluated grid."""
    return render(report_data(results))


def _add_backend_args(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--backend",
        choices=("local", "ray"),
        default="local",
        help="local: the cells one after the other in this process; ray: one Ray task per "
        "cell (a local Ray instance, or the cluster at --address)",
    )
    p.add_argument(
        "--address", default=None, help="an existing Ray cluster (e.g. auto, ray://head:10001)"
    )
    p.add_argument(
        "--num-cpus", type=int, default=None, help="CPUs of a local Ray instance (default all)"
    )
    p.add_argument(
        "--cpus-per-cell",
        type=float,
        default=1,
        help="CPUs each Ray task reserves (training also uses that many torch threads)",
    )
    p.add_argument(
        "--working-dir",
        default=None,
        help="ship this folder to the Ray workers (runtime_env working_dir), for a cluster "
        "without this version installed",
    )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        prog="python -m benchmarks.reference",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = ap.add_subparsers(dest="cmd", required=True)
    t = sub.add_parser("train", help="train the grid (skips finished runs)")
    t.add_argument("--only", nargs="+", default=None, help="entries: NAME or NAME:Env-v0")
    t.add_argument("--seeds", nargs="+", type=int, default=list(SEEDS))
    t.add_argument("--print", action="store_true", help="print the commands, train nothing")
    _add_backend_args(t)
    ev = sub.add_parser("evaluate", help="benchmark every trained model on every split")
    ev.add_argument("--episodes", type=int, default=100)
    ev.add_argument("--envs", nargs="+", default=None, help="only these env ids")
    ev.add_argument(
        "--only", nargs="+", default=None, help="only these entries' models (NAME or NAME:Env-v0)"
    )
    ev.add_argument("--seeds", nargs="+", type=int, default=None, help="only these training seeds")
    ev.add_argument(
        "--again", action="store_true", help="evaluate again the cells that have results"
    )
    ev.add_argument("--new", action="store_true", help="only cells without results (the default)")
    ev.add_argument(
        "--results",
        type=Path,
        default=RESULTS,
        help=f"the per-run result files (default the tracked {RESULTS.relative_to(ROOT)})",
    )
    _add_backend_args(ev)
    rp = sub.add_parser("report", help="the markdown tables, from the per-run result files")
    rp.add_argument(
        "--results",
        type=Path,
        default=RESULTS,
        help=f"the per-run result files (default the tracked {RESULTS.relative_to(ROOT)})",
    )
    _results.add_output_args(rp, "reference")
    im = sub.add_parser(
        "import",
        help="per-run result files from the evaluations of earlier versions (runs/reference/)",
    )
    im.add_argument("old", type=Path, help="the runs/reference/ folder of an earlier version")
    im.add_argument("--results", type=Path, default=RESULTS)
    args = ap.parse_args(argv)
    if args.cmd == "import":
        written = import_evaluations(args.old, args.results)
        print(f"wrote {len(written)} result files under {args.results}")
        return 0 if written else 1
    if args.cmd == "train":
        entries = _selected(args.only)
        if args.print:
            for e in entries:
                for s in args.seeds:
                    print(e.command(s))
            return 0
        done, trained, failed = train_grid(entries, args.seeds, **_backend(args))
        print(f"{done} runs finished before, {trained} trained now, {len(failed)} failed")
        return 1 if failed else 0
    if args.cmd == "evaluate":
        found, evaluated, failed = evaluate_grid(
            args.episodes,
            envs=args.envs,
            only=_selected(args.only) if args.only else None,
            seeds=args.seeds,
            again=args.again,
            results=args.results,
            **_backend(args),
        )
        if not found:
            print(
                f"nothing to evaluate: no finished run of the selected grid entries under "
                f"{RUNS}/ (a run is finished when its final_model.zip exists); train them "
                f"with: python -m benchmarks.reference train"
            )
            return 1
        if not evaluated and not failed:
            print(
                f"nothing new to evaluate: all {found} finished runs of the selected entries "
                f"have results under {args.results}/ (--again evaluates them again)"
            )
        return 1 if failed else 0
    data = {"command": _results.command("benchmarks.reference", argv), **report_data(args.results)}
    if not data["envs"]:
        print(
            f"nothing to report: no result files under {args.results}/; evaluate the trained "
            f"models first with: python -m benchmarks.reference evaluate"
            + (" (the tracked results left as they are)" if args.update_results else ""),
            file=sys.stderr,
        )
        return 1
    print(render(data))
    _results.write("reference", data, args.out, args.update_results)
    return 0


if __name__ == "__main__":
    sys.exit(main())

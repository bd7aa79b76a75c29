"""The reference results of the learned baselines: train, benchmark and tabulate the grid.

``python -m benchmarks.reference train [--only NAME ...] [--seeds 0 1 2 3 4]``
    trains every entry of :data:`GRID` (algorithm x env, on the procedural ``train`` pool)
    for each seed, into ``runs/<name>_<env>_random_s<seed>``; a run whose
    ``final_model.zip`` exists is skipped.  Each run is exactly the ``sensorplan train``
    command that ``--print`` shows.  Hours of CPU for the whole grid; one entry and seed
    takes minutes (README lists them).
``python -m benchmarks.reference evaluate [--episodes 100]``
    runs ``sensorplan benchmark`` (:func:`agents.evaluation.benchmark.benchmark`) per env on the
    splits ``train``, ``test`` (held-out procedural scenes) and ``ood`` (every bundled scene,
    never trained on), with the oracle, the random policy and every trained model found; results
    in ``runs/reference/<env>[-discrete]/``.  ``--only NAME[:Env-v0] ...`` evaluates just those
    entries' models and ``--new`` just the models not evaluated yet (into
    ``<env>[-discrete]/models-<entry>/``; ``report`` merges them, a newer result of a model
    replacing an older one).
``python -m benchmarks.reference report [--update-results]``
    the markdown table per env: success per split, the interquartile mean over training seeds
    with its stratified-bootstrap 95 % interval (:mod:`agents.evaluation.stats`), the normalized
    score ``(agent - random) / (oracle - random)`` on the test split and, for Navigate, the mean
    path length over the oracle's.  The table's data (``reference.json``) and the page fragment
    (``reference.md``) go to ``--out`` (default ``runs/benchmarks/reference/``), or with
    ``--update-results`` to the tracked ``benchmarks/results/reference.json`` and
    ``docs/results/reference.md``.  With no evaluated model it says so and writes nothing.

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

import numpy as np

from . import _results

NAV = "sensorplan/Navigate-v0"
REC = "sensorplan/Recognize-v0"
PLACE = "sensorplan/Placement-v0"
RUNS = Path("runs")
OUT = RUNS / "reference"
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


def train_grid(entries: list[Entry], seeds: list[int]) -> None:
    """Train every entry x seed whose final model is missing (the commands of ``--print``)."""
    from agents.cli import _hp_overrides
    from agents.learning.train import train

    for e in entries:
        for s in seeds:
            if (e.out(s) / "final_model.zip").is_file():
                print(f"skip {e.out(s)} (trained)", flush=True)
                continue
            print(e.command(s), flush=True)
            hp = _hp_overrides([f"{k}={json.dumps(v)}" for k, v in e.hp.items()]) if e.hp else {}
            train(
                e.env_id,
                e.algo,
                timesteps=e.timesteps,
                seed=s,
                env_kwargs=e.env_kwargs,
                config=e.config,
                out=e.out(s),
                hp_overrides=hp,
                tensorboard=False,
                progress_bar=False,
            )


def _models(entries: list[Entry]) -> list[str]:
    """The best models of the finished runs (``final_model.zip`` written) of ``entries``."""
    return [
        str(e.out(s) / "best_model.zip")
        for e in entries
        for s in range(100)
        if (e.out(s) / "best_model.zip").is_file() and (e.out(s) / "final_model.zip").is_file()
    ]


def _group_dir(env_id: str, discrete: bool) -> Path:
    return OUT / (env_id.split("/")[-1] + ("-discrete" if discrete else ""))


def _result_files(env_id: str, discrete: bool) -> list[Path]:
    """The benchmark results of one env and action type, oldest first: the full evaluation
    (``<group>/benchmark.json``, with the baselines) and the incremental ones of
    ``evaluate --only`` (``<group>/models-<entry>/benchmark.json``)."""
    g = _group_dir(env_id, discrete)
    extra = sorted(g.glob("models-*/benchmark.json"), key=lambda f: f.stat().st_mtime)
    return ([g / "benchmark.json"] if (g / "benchmark.json").is_file() else []) + extra


def _evaluated(env_id: str, discrete: bool) -> set[str]:
    return {
        p["spec"]
        for f in _result_files(env_id, discrete)
        for r in json.loads(f.read_text())["splits"].values()
        for p in r["policies"]
    }


def evaluate_grid(
    episodes: int,
    seed: int = 0,
    envs: list[str] | None = None,
    only: list[Entry] | None = None,
    new: bool = False,
) -> tuple[int, int]:
    """``sensorplan benchmark`` per env (and per action type) with every trained model;
    ``envs``: only these env ids.  ``only``: only these entries' models, without the
    baselines, into ``<group>/models-<entry>/`` (:func:`report` merges them; a model's
    episodes do not depend on which other policies are evaluated with it); ``new``: only
    models not evaluated yet.  Returns ``(models found, models evaluated)``."""
    from agents.evaluation.benchmark import benchmark

    found = evaluated = 0
    for env_id in envs or (PLACE, REC, NAV):
        for discrete in (False, True):
            entries = [e for e in GRID if e.env_id == env_id and e.discrete == discrete]
            kw = dict(EVAL_KWARGS[env_id], **({"action_type": "discrete"} if discrete else {}))
            done = _evaluated(env_id, discrete) if new else set()
            if only is None and not new:
                models = _models(entries)
                found += len(models)
                evaluated += len(models)
                if models:
                    base = ["random"] if discrete else ["oracle", "random"]
                    benchmark(
                        env_id,
                        base + models,
                        episodes=episodes,
                        seed=seed,
                        env_kwargs=kw,
                        out=_group_dir(env_id, discrete),
                    )
                continue
            for e in entries:
                if only is not None and e not in only:
                    continue
                every = _models([e])
                models = [m for m in every if m not in done]
                found += len(every)
                evaluated += len(models)
                if models:
                    benchmark(
                        env_id,
                        models,
                        episodes=episodes,
                        seed=seed,
                        env_kwargs=kw,
                        out=_models_dir(_group_dir(env_id, discrete), e.key, new),
                    )
    return found, evaluated


def _models_dir(group: Path, key: str, new: bool) -> Path:
    """Where ``evaluate --only/--new`` writes one entry's models: ``models-<key>``; with
    ``new`` (only some of the entry's models) the first of ``models-<key>``,
    ``models-<key>.2``, ... without results, so that no earlier result is overwritten."""
    d, k = group / f"models-{key}", 1
    while new and (d / "benchmark.json").is_file():
        k += 1
        d = group / f"models-{key}.{k}"
    return d


def _cell(rates: list[float], seed: int = 0) -> dict[str, Any] | None:
    """The IQM over training seeds with its stratified-bootstrap 95 % interval (``n`` seeds);
    one seed: its value; none: ``None``."""
    from agents.evaluation.stats import iqm, stratified_bootstrap_ci

    if not rates:
        return None
    if len(rates) == 1:
        return {"n": 1, "est": float(rates[0])}
    est, lo, hi = stratified_bootstrap_ci(np.array([[r] for r in rates]), iqm, seed=seed)
    return {"n": len(rates), "est": float(est), "lo": float(lo), "hi": float(hi)}


def _fmt_cell(c: dict[str, Any] | None) -> str:
    if c is None:
        return "—"
    if c["n"] == 1:
        return f"{c['est']:.2f} (1 seed)"
    return f"{c['est']:.2f} [{c['lo']:.2f}, {c['hi']:.2f}]"


def report_data() -> dict[str, Any]:
    """The tables' data of the evaluated grid (``runs/reference``): per env the splits and one
    row per baseline and per grid entry."""
    from agents.learning.policies import model_config

    out: dict[str, Any] = {"envs": []}
    for env_id in (PLACE, REC, NAV):
        rows: dict[str, dict] = {}
        splits: list[str] = []
        base: dict[tuple[str, str], float] = {}
        path: dict[tuple[str, str], float] = {}
        for discrete in (False, True):
            merged: dict[str, dict] = {}  # split -> spec -> policy result (latest file wins)
            for f in _result_files(env_id, discrete):
                for sp, r in json.loads(f.read_text())["splits"].items():
                    if sp not in splits:
                        splits.append(sp)
                    for p in r["policies"]:
                        merged.setdefault(sp, {})[p["spec"]] = p
            for sp, by_spec in merged.items():
                for p in by_spec.values():
                    if p["kind"] in ("oracle", "random"):
                        key = p["kind"] + (" (discrete)" if discrete else "")
                        base[(key, sp)] = p["success_rate"]
                        path[(key, sp)] = p["mean_path_length"]
                        rows.setdefault(key, {"n": 1})
                        continue
                    entry = next(
                        (
                            e
                            for e in GRID
                            if e.env_id == env_id
                            and Path(p["spec"]).parent.name.startswith(e.out(0).name[:-1])
                        ),
                        None,
                    )
                    label = entry.label if entry else Path(p["spec"]).parent.name
                    row = rows.setdefault(label, {"n": 0, "discrete": discrete, "runs": set()})
                    if p["spec"] not in row["runs"]:
                        cfg = model_config(p["spec"]) or {}
                        row.setdefault("time", []).append(cfg.get("train_time_s"))
                    row["runs"].add(p["spec"])
                    row.setdefault(sp, []).append(p["success_rate"])
                    row.setdefault(f"path:{sp}", []).append(p["mean_path_length"])
        if not rows:
            continue
        table: dict[str, Any] = {"env": env_id.split("/")[-1], "splits": splits, "rows": []}
        for label, row in rows.items():
            if label in ("oracle", "random", "random (discrete)"):
                o = path.get(("oracle", "test"))
                p_ = path.get((label, "test"))
                table["rows"].append(
                    {
                        "label": label,
                        "baseline": True,
                        "success": {sp: base.get((label, sp)) for sp in splits},
                        "normalized": 1.0 if label == "oracle" else 0.0,
                        "path_ratio": p_ / o if o and p_ is not None else None,
                    }
                )
                continue
            rnd = "random (discrete)" if row["discrete"] else "random"
            times = [t for t in row.get("time", []) if t is not None]
            o, r0 = base.get(("oracle", "test"), 1.0), base.get((rnd, "test"))
            norm = None
            if r0 is not None and o > r0 and row.get("test"):
                norm = _cell([(x - r0) / (o - r0) for x in row["test"]])
            op = path.get(("oracle", "test"))
            ps = row.get("path:test", [])
            table["rows"].append(
                {
                    "label": label,
                    "baseline": False,
                    "seeds": len(row["runs"]),
                    "train_min": float(np.median(times) / 60) if times else None,
                    "success": {sp: _cell(row.get(sp, [])) for sp in splits},
                    "normalized": norm,
                    "path_ratio": float(np.median(ps) / op) if op and ps else None,
                }
            )
        out["envs"].append(table)
    return out


def render(data: dict[str, Any]) -> str:
    """The markdown table per env of :func:`report_data`'s data."""
    out = []
    for t in data["envs"]:
        nav = t["env"] == NAV.split("/")[-1]
        splits = t["splits"]
        head = ["agent", "seeds", "train time / seed", *splits, "normalized (test)"]
        if nav:
            head.append("path / oracle (test)")
        lines = [f"**{t['env']}**", "", "| " + " | ".join(head) + " |"]
        lines.append("| " + " | ".join(["---"] * len(head)) + " |")
        for r in t["rows"]:
            if r["baseline"]:
                cells = [r["label"], "—", "—"]
                cells += [
                    "nan" if r["success"].get(sp) is None else f"{r['success'][sp]:.2f}"
                    for sp in splits
                ]
                cells.append(f"{r['normalized']:.2f}")
                if nav:
                    cells.append("—" if r["path_ratio"] is None else f"{r['path_ratio']:.2f}")
            else:
                wall = "—" if r["train_min"] is None else f"{r['train_min']:.1f} min"
                cells = [r["label"], str(r["seeds"]), wall]
                cells += [_fmt_cell(r["success"].get(sp)) for sp in splits]
                cells.append(_fmt_cell(r["normalized"]))
                if nav:
                    pr = r["path_ratio"]
                    cells.append("—" if pr is None else f"{pr:.2f} (median of seeds)")
            lines.append("| " + " | ".join(cells) + " |")
        out.append("\n".join(lines))
    return "\n\n".join(out) + "\n"


def report() -> str:
    """The markdown tables of the evaluated grid."""
    return render(report_data())


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.reference", description=__doc__)
    sub = ap.add_subparsers(dest="cmd", required=True)
    t = sub.add_parser("train", help="train the grid (skips finished runs)")
    t.add_argument("--only", nargs="+", default=None, help="entries: NAME or NAME:Env-v0")
    t.add_argument("--seeds", nargs="+", type=int, default=list(SEEDS))
    t.add_argument("--print", action="store_true", help="print the commands, train nothing")
    ev = sub.add_parser("evaluate", help="benchmark every trained model on every split")
    ev.add_argument("--episodes", type=int, default=100)
    ev.add_argument("--envs", nargs="+", default=None, help="only these env ids")
    ev.add_argument(
        "--only", nargs="+", default=None, help="only these entries' models (NAME or NAME:Env-v0)"
    )
    ev.add_argument("--new", action="store_true", help="only models not evaluated yet")
    rp = sub.add_parser("report", help="the markdown tables")
    _results.add_output_args(rp, "reference")
    args = ap.parse_args(argv)
    if args.cmd == "train":
        entries = _selected(args.only)
        if args.print:
            for e in entries:
                for s in args.seeds:
                    print(e.command(s))
            return 0
        train_grid(entries, args.seeds)
    elif args.cmd == "evaluate":
        found, evaluated = evaluate_grid(
            args.episodes,
            envs=args.envs,
            only=_selected(args.only) if args.only else None,
            new=args.new,
        )
        if not found:
            print(
                f"nothing to evaluate: no finished run of the selected grid entries under "
                f"{RUNS}/ (a run is finished when its final_model.zip exists); train them "
                f"with: python -m benchmarks.reference train"
            )
            return 1
        if not evaluated:
            print(
                f"nothing new to evaluate: all {found} finished runs of the selected entries "
                f"have results under {OUT}/ (without --new every model is evaluated again)"
            )
    else:
        data = {"command": _results.command("benchmarks.reference", argv), **report_data()}
        if not data["envs"]:
            print(
                f"nothing to report: no benchmark results under {OUT}/; evaluate the trained "
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

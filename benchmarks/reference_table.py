"""The reference table from the tracked per-run results: where they live, how they are
aggregated, how the table is rendered.

Layout under the results folder (tracked: ``benchmarks/results/reference/``), one small JSON
file per evaluated cell:

* ``<Env-v0>/<entry>/seed<k>.json`` -- one trained run (grid entry ``<entry>``, e.g. ``ppo``,
  ``sac-utd1``; training seed ``k``) evaluated on every split: per split the episodes,
  successes, success rate with its Wilson interval, mean return, steps and path length; the
  training command, its wall time and the evaluation settings;
* ``<Env-v0>/oracle.json``, ``random.json``, ``random-discrete.json`` -- the baselines (the
  analytic oracle and uniform random actions, continuous and discrete action sets);
* ``<Env-v0>/<entry>/aggregate.json`` -- a row migrated from the table of earlier versions,
  whose per-run results were never kept (:func:`migrate_table`): used as it is, and only while
  the entry has no ``seed<k>.json`` of its own.

:func:`report_data` aggregates these files alone (the interquartile mean over training seeds
with its stratified-bootstrap 95 % interval, the normalized score, the path over the
oracle's) and :func:`render` turns that data into the markdown fragment.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Iterable
from pathlib import Path
from typing import Any, Protocol

import numpy as np

__all__ = [
    "BASELINES",
    "baseline_file",
    "migrate_table",
    "render",
    "report_data",
    "run_file",
]

#: baseline file stem -> (row label, discrete action set)
BASELINES = {
    "oracle": ("oracle", False),
    "random": ("random", False),
    "random-discrete": ("random (discrete)", True),
}


class EntryLike(Protocol):
    """What the table needs of a grid entry (:class:`benchmarks.reference.Entry`)."""

    key: str
    label: str
    env_id: str
    discrete: bool


def _env_name(env_id: str) -> str:
    return env_id.split("/")[-1]


def run_file(results: Path, env_id: str, key: str, seed: int) -> Path:
    """The per-run result file of entry ``key``, training seed ``seed``, on ``env_id``."""
    return Path(results) / _env_name(env_id) / key / f"seed{int(seed)}.json"


def baseline_file(results: Path, env_id: str, name: str) -> Path:
    """The result file of baseline ``name`` (a key of :data:`BASELINES`) on ``env_id``."""
    if name not in BASELINES:
        raise ValueError(f"unknown baseline {name!r}; one of {sorted(BASELINES)}")
    return Path(results) / _env_name(env_id) / f"{name}.json"


def _read(path: Path) -> dict[str, Any]:
    try:
        return json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError) as e:
        raise SystemExit(f"{path}: not a readable result file ({e})") from None


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


def _split_order(names: Iterable[str]) -> list[str]:
    """``train``, ``test``, then the other splits (``ood:<scene>``) alphabetically."""
    first = [s for s in ("train", "test") if s in names]
    return first + sorted(set(names) - set(first))


def _seed_files(folder: Path) -> list[Path]:
    files = [p for p in folder.glob("seed*.json") if p.stem[4:].isdigit()]
    return sorted(files, key=lambda p: int(p.stem[4:]))


def report_data(
    results: Path, entries: list[EntryLike], envs: Iterable[str] | None = None
) -> dict[str, Any]:
    """The table's data from the result files under ``results`` alone: per env (``envs``, by
    default the env ids of ``entries`` in their order) the splits and the rows -- the
    baselines, then one row per entry with results, continuous action sets first, entries in
    their order in ``entries``."""
    results = Path(results)
    out: dict[str, Any] = {"envs": []}
    env_ids = list(envs) if envs is not None else list(dict.fromkeys(e.env_id for e in entries))
    for env_id in env_ids:
        env_dir = results / _env_name(env_id)
        base: dict[str, dict[str, Any]] = {}
        for name, (label, _) in BASELINES.items():
            f = baseline_file(results, env_id, name)
            if f.is_file():
                base[label] = _read(f)
        runs: dict[str, list[dict[str, Any]]] = {}
        legacy: dict[str, dict[str, Any]] = {}
        for e in entries:
            if e.env_id != env_id:
                continue
            files = _seed_files(env_dir / e.key)
            if files:
                runs[e.key] = [_read(f) for f in files]
                if (env_dir / e.key / "aggregate.json").is_file():
                    print(
                        f"note: {env_dir / e.key}: per-run results replace the migrated "
                        f"aggregate.json in the table",
                        file=sys.stderr,
                    )
            elif (env_dir / e.key / "aggregate.json").is_file():
                legacy[e.key] = _read(env_dir / e.key / "aggregate.json")
        if not (runs or legacy):
            continue
        names: set[str] = set()
        for d in base.values():
            names |= set(d["splits"] if "splits" in d else d["success"])
        for d in legacy.values():
            names |= set(d["row"]["success"])
        for rs in runs.values():
            for r in rs:
                names |= set(r["splits"])
        splits = _split_order(names)

        def rate(d: dict[str, Any] | None, sp: str) -> float | None:
            if d is None:
                return None
            if "splits" in d:
                s = d["splits"].get(sp)
                return None if s is None else s["success_rate"]
            return d["success"].get(sp)

        def path(d: dict[str, Any] | None, sp: str) -> float | None:
            if d is None or "splits" not in d or sp not in d["splits"]:
                return None
            return d["splits"][sp]["mean_path_length"]

        oracle = base.get("oracle")
        o_path = path(oracle, "test")
        rows: list[dict[str, Any]] = []
        for discrete in (False, True):
            for label in ("oracle", "random") if not discrete else ("random (discrete)",):
                d = base.get(label)
                if d is None:
                    continue
                if "splits" in d:
                    p = path(d, "test")
                    ratio = p / o_path if o_path and p is not None else None
                else:  # migrated: the ratio as the earlier table had it
                    ratio = d.get("path_ratio")
                rows.append(
                    {
                        "label": label,
                        "baseline": True,
                        "success": {sp: rate(d, sp) for sp in splits},
                        "normalized": 1.0 if label == "oracle" else 0.0,
                        "path_ratio": ratio,
                    }
                )
            rnd = base.get("random (discrete)" if discrete else "random")
            o = rate(oracle, "test")
            o = 1.0 if o is None else o  # the oracle solves every split (checked in its row)
            r0 = rate(rnd, "test")
            for e in entries:
                if e.env_id != env_id or e.discrete != discrete:
                    continue
                if e.key in legacy:
                    rows.append(dict(legacy[e.key]["row"]))
                    continue
                if e.key not in runs:
                    continue
                rs = runs[e.key]
                times = [r["train_time_s"] for r in rs if r.get("train_time_s") is not None]
                test = [r["splits"]["test"]["success_rate"] for r in rs if "test" in r["splits"]]
                norm = None
                if r0 is not None and o > r0 and test:
                    norm = _cell([(x - r0) / (o - r0) for x in test])
                paths = [
                    r["splits"]["test"]["mean_path_length"] for r in rs if "test" in r["splits"]
                ]
                rows.append(
                    {
                        "label": e.label,
                        "baseline": False,
                        "seeds": len(rs),
                        "train_min": float(np.median(times) / 60) if times else None,
                        "success": {
                            sp: _cell(
                                [r["splits"][sp]["success_rate"] for r in rs if sp in r["splits"]]
                            )
                            for sp in splits
                        },
                        "normalized": norm,
                        "path_ratio": float(np.median(paths) / o_path)
                        if o_path and paths
                        else None,
                    }
                )
        out["envs"].append({"env": _env_name(env_id), "splits": splits, "rows": rows})
    return out


def _fmt_cell(c: dict[str, Any] | None) -> str:
    if c is None:
        return "—"
    if c["n"] == 1:
        return f"{c['est']:.2f} (1 seed)"
    return f"{c['est']:.2f} [{c['lo']:.2f}, {c['hi']:.2f}]"


def render(data: dict[str, Any]) -> str:
    """The markdown table per env of :func:`report_data`'s data."""
    out = []
    for t in data["envs"]:
        nav = t["env"] == "Navigate-v0"
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


def migrate_table(
    data: dict[str, Any], results: Path, entries: list[EntryLike], source: str
) -> list[Path]:
    """Split the table data of earlier versions (``benchmarks/results/reference.json``: one
    aggregated row per entry, the per-run results not kept) into the per-entry files of this
    layout: ``<Env-v0>/<entry>/aggregate.json`` per agent row (the row as it was) and
    ``<Env-v0>/<baseline>.json`` per baseline row (its success per split and path ratio).
    ``source`` names where the data came from (recorded in every file).  Returns the files
    written; a row whose label names no entry of that env is an error."""
    from .reference_runs import write_json

    written: list[Path] = []
    labels = {v[0]: k for k, v in BASELINES.items()}
    for t in data["envs"]:
        env_id = next((e.env_id for e in entries if _env_name(e.env_id) == t["env"]), None)
        if env_id is None:
            raise ValueError(f"{source}: env {t['env']!r} is not in the grid")
        discrete = False
        for r in t["rows"]:
            note = (
                f"migrated from {source}: the table row of earlier versions; the per-run "
                "results behind it were not kept"
            )
            if r["baseline"]:
                discrete = BASELINES[labels[r["label"]]][1]
                f = baseline_file(results, env_id, labels[r["label"]])
                rec = {
                    "policy": labels[r["label"]].split("-")[0],
                    "env_id": env_id,
                    "discrete": discrete,
                    "source": note,
                    "success": r["success"],
                    "path_ratio": r["path_ratio"],
                }
            else:
                match = [
                    e
                    for e in entries
                    if e.env_id == env_id and e.label == r["label"] and e.discrete == discrete
                ]
                if len(match) != 1:
                    raise ValueError(
                        f"{source}: row {r['label']!r} of {t['env']} matches {len(match)} "
                        "grid entries, not one"
                    )
                f = Path(results) / t["env"] / match[0].key / "aggregate.json"
                rec = {"entry": match[0].key, "env_id": env_id, "source": note, "row": r}
            written.append(write_json(f, rec))
    return written

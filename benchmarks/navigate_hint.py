"""Navigate-v0 on the ``hard`` level with the ``view_hint`` observation: learned policies, the
fixed hint rule and the oracle.

    python -m benchmarks.navigate_hint [--episodes 100] [--seed 0] [--models PATH ...]
        [--seed-models PATH ...]

``sensorplan benchmark --env sensorplan/Navigate-v0 --level hard --splits test ood real narrow``
(:func:`agents.evaluation.benchmark.benchmark`) of the shipped Navigate policies that read
``view_hint`` (``agents/pretrained/dagger_navigate_hint.zip``, DAgger from the hint rule, and
``ppo_navigate_hint.zip``, PPO), the one trained without it (``ppo_navigate_hard``), the hint
rule (:mod:`agents.planning.hint_rule`, no learning) and the oracle, every policy on the same
episode seeds from random starts.  Besides success it reports the mean path length over the
episodes that the policy and the oracle both solve, as a multiple of the oracle's (issue 22's
target: at most 1.3).  ``--seed-models``: more training seeds of the ``--models``' configs;
per config trained at several seeds, the IQM over its seeds.  Needs the ``rl`` extra.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path
from typing import Any

from . import _results

ENV = "sensorplan/Navigate-v0"
PRETRAINED = Path(__file__).resolve().parents[1] / "agents" / "pretrained"
MODELS = [
    PRETRAINED / "dagger_navigate_hint.zip",
    PRETRAINED / "ppo_navigate_hint.zip",
    PRETRAINED / "ppo_navigate_hard.zip",
]


def path_ratio(policy: dict[str, Any], oracle: dict[str, Any]) -> float | None:
    """Mean path length of ``policy`` over the episodes it and ``oracle`` both solve, over the
    oracle's mean on the same episodes (``None`` when they solve none in common); the results
    are :func:`agents.evaluation.evaluate.evaluate`'s per-policy dictionaries."""
    a, b = policy["per_episode"], oracle["per_episode"]
    both = [i for i, (x, y) in enumerate(zip(a["success"], b["success"], strict=True)) if x and y]
    if not both:
        return None
    num = sum(a["path_length"][i] for i in both)
    den = sum(b["path_length"][i] for i in both)
    return num / den if den > 0 else None


def main(
    argv: list[str] | None = None,
    *,
    env: str = ENV,
    name: str = "navigate_hint",
    models: list[Path] | None = None,
    rules: tuple[str, ...] = ("hint-rule",),
    doc: str = "",
) -> int:
    """Benchmark ``models`` (``--models``), the ``rules`` and the oracle on ``env``'s ``hard``
    level and write the data as ``name``."""
    from agents.evaluation.benchmark import benchmark
    from agents.learning.policies import policy_label

    ap = argparse.ArgumentParser(
        prog=f"python -m benchmarks.{name}", description=(doc or __doc__).split("\n\n")[0]
    )
    ap.add_argument("--episodes", type=int, default=100)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--models", type=Path, nargs="+", default=models or MODELS, help="model zips")
    ap.add_argument(
        "--seed-models",
        type=Path,
        nargs="*",
        default=[],
        help="more training seeds of the --models' configs (zips): per config trained at "
        "several seeds, the IQM over its seeds per split, and each seed's path ratio",
    )
    ap.add_argument(
        "--keep",
        nargs="+",
        default=[],
        metavar="POLICY",
        help=f"policies of the tracked benchmarks/results/{name}.json (as named there) whose "
        "rows are taken from it instead of played again, each with every training seed of its "
        "config; that run must have played the same --episodes and --seed",
    )
    _results.add_output_args(ap, name)
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    kept = _kept(name, args.keep, args.episodes, args.seed) if args.keep else None
    extra = [str(m) for m in args.seed_models]
    specs = [str(m) for m in args.models] + extra + [*rules, "oracle"]
    paths = env == ENV  # the path over the oracle's: Navigate's target
    with tempfile.TemporaryDirectory() as tmp:
        res = benchmark(
            env,
            specs,
            episodes=args.episodes,
            seed=args.seed,
            split_names=["test", "ood", "real", "narrow"],
            level="hard",
            out=tmp,
            verbose=False,
        )
    iqm = _results.iqm_rows(res)
    group = {(r["split"], n): r["config"] for r in iqm for n in r["policies"]}
    rows, seeds = [], []
    for split, r in res["splits"].items():
        oracle = next(p for p in r["policies"] if p["spec"] == "oracle")
        for p in r["policies"]:
            if (split, p["name"]) in group:  # one of the seeds of a config
                seeds.append(
                    {
                        "split": split,
                        "config": group[(split, p["name"])],
                        "policy": policy_label(p["spec"]),
                        "train_seed": p.get("train_seed"),
                        "success_rate": p["success_rate"],
                        "path_ratio": path_ratio(p, oracle) if paths else None,
                    }
                )
            if p["spec"] in extra:
                continue  # in the seeds' summary only
            rows.append(
                {
                    "split": split,
                    "policy": policy_label(p["spec"]),
                    "successes": p["successes"],
                    "episodes": p["episodes"],
                    "distinct": p["distinct_episodes"],
                    "ci95": list(p["success_ci95"]),
                    "path_ratio": path_ratio(p, oracle) if paths and p is not oracle else None,
                }
            )
    data: dict[str, Any] = {
        "command": _results.command(f"benchmarks.{name}", argv),
        "machine": _results.machine(),
        "policies": [policy_label(s) for s in specs if s not in extra],
        "rows": rows,
        "iqm": iqm,
        "seeds": seeds,
        "seconds": round(time.perf_counter() - t0, 1),
    }
    if kept is not None:
        data = _merge(data, kept)
    _results.write(name, data, args.out, args.update_results)
    print(render(data))
    return 0


def _kept(name: str, keep: list[str], episodes: int, seed: int) -> dict[str, Any]:
    """The part of the tracked data of ``name`` that ``--keep`` names: the policies' rows,
    their configs' IQM and seed rows, and where they come from.  Raises ``ValueError`` when
    that run played other episodes or lacks a policy."""
    old = _results.load(name)
    first = old["rows"][0]
    if first["episodes"] != episodes or _arg(old["command"], "--seed", "0") != str(seed):
        raise ValueError(
            f"--keep: benchmarks/results/{name}.json played {first['episodes']} episodes from "
            f"seed {_arg(old['command'], '--seed', '0')} (`{old['command']}`), this run "
            f"{episodes} from seed {seed}: run those policies again instead"
        )
    missing = [p for p in keep if p not in old["policies"]]
    if missing:
        raise ValueError(
            f"--keep: no policy {', '.join(missing)} in benchmarks/results/{name}.json "
            f"(it holds {', '.join(old['policies'])})"
        )
    configs = {r["config"] for r in old.get("iqm") or [] if set(r["policies"]) & set(keep)}
    source = {"command": old["command"], "seconds": old["seconds"]}
    earlier = old.get("kept") or {}
    if set(keep) <= set(earlier.get("policies") or []):  # kept there too: the run that played them
        source = {"command": earlier["command"], "seconds": earlier["seconds"]}
    return {
        "policies": list(keep),
        "order": old["policies"],
        "rows": [r for r in old["rows"] if r["policy"] in keep],
        "iqm": [r for r in old.get("iqm") or [] if r["config"] in configs],
        "seeds": [r for r in old.get("seeds") or [] if r["config"] in configs],
        "from": source,
    }


def _arg(command: str, flag: str, default: str) -> str:
    words = command.split()
    return words[words.index(flag) + 1] if flag in words[:-1] else default


def _merge(data: dict[str, Any], kept: dict[str, Any]) -> dict[str, Any]:
    """``data`` of this run with the ``kept`` policies' rows added, in the tracked run's order
    (a policy both played and kept, or a config of both, raises ``ValueError``)."""
    both = set(kept["policies"]) & set(data["policies"])
    clash = {r["config"] for r in kept["iqm"]} & {r["config"] for r in data["iqm"]}
    if both or clash:
        raise ValueError(
            f"--keep: {', '.join(sorted(both | clash))} both played in this run and kept"
        )
    order = [p for p in kept["order"] if p in kept["policies"] or p in data["policies"]]
    new = [p for p in data["policies"] if p not in order]
    tail = [p for p in order if p in ("hint-rule", "hint-rule-turn", "oracle")]
    order = [p for p in order if p not in tail] + new + tail
    rank = {p: i for i, p in enumerate(order)}
    splits = list(dict.fromkeys(r["split"] for r in data["rows"]))
    if {r["split"] for r in kept["rows"]} != set(splits):
        raise ValueError("--keep: the tracked run played other splits than this one")
    rows = sorted(
        data["rows"] + kept["rows"], key=lambda r: (splits.index(r["split"]), rank[r["policy"]])
    )
    return {
        **data,
        "policies": order,
        "rows": rows,
        "iqm": data["iqm"] + kept["iqm"],
        "seeds": data["seeds"] + kept["seeds"],
        "kept": {"policies": kept["policies"], **kept["from"]},
    }


def render(data: dict[str, Any]) -> str:
    """The page fragment: success [interval] and path / oracle per split and policy."""
    order = data["policies"]
    splits = list(dict.fromkeys(r["split"] for r in data["rows"]))
    by = {(r["split"], r["policy"]): r for r in data["rows"]}
    lines = [
        "| split | " + " | ".join(f"`{p}`" for p in order) + " |",
        "|---|" + "---|" * len(order),
    ]
    for s in splits:
        cells = []
        for p in order:
            r = by.get((s, p))
            cell = _results.success_cell(r)
            if r is not None and r["path_ratio"] is not None:
                cell += f", path {r['path_ratio']:.2f}×"
            cells.append(cell)
        lines.append(f"| {s} | " + " | ".join(cells) + " |")
    n = data["rows"][0]["episodes"]
    paths = any(r["path_ratio"] is not None for r in data["rows"])
    lines += [
        "",
        f"Success rate [95 % Wilson interval], {n} episodes per split from random starts "
        "(distinct scene-start pairs), deterministic policies, one training seed each"
        + (" (more seeds of the first: below)" if data.get("iqm") else "")
        + (
            "; path: the mean path length over the episodes the policy and the oracle both "
            "solve, over the oracle's."
            if paths
            else "."
        ),
        "",
        f"Measured with `{data['command']}` ({data['seconds']} s).",
    ]
    if data.get("kept"):
        k = data["kept"]
        lines[-1] += (
            f" The rows of {', '.join(f'`{p}`' for p in k['policies'])} (and their seeds) are "
            f"kept from the earlier run `{k['command']}` ({k['seconds']} s) on the same episodes."
        )
    for config in dict.fromkeys(r.get("config") for r in data.get("iqm") or []):
        lines += ["", *_seeds_table(data, config, splits, paths)]
    return "\n".join(lines) + "\n"


def _seeds_table(data: dict[str, Any], config: Any, splits: list[str], paths: bool) -> list[str]:
    """The IQM over the training seeds of one config per split, and each seed's success (and
    path ratio), named after the first of its policies in the main table."""
    iqm = {r["split"]: r for r in data["iqm"] if r.get("config") == config}
    per: dict[str, list[dict[str, Any]]] = {}
    for r in data["seeds"]:
        if r.get("config", config) == config:
            per.setdefault(r["split"], []).append(r)
    some = next(iter(iqm.values()))
    shown = [p for p in data["policies"] if any(r["policy"] == p for v in per.values() for r in v)]
    name = shown[0] if shown else str(config)
    lines = [
        f"`{name}`'s recipe over {some['runs']} training seeds "
        f"({', '.join(str(x) for x in some['train_seeds'])}): the IQM of the success rate "
        "[95 % stratified-bootstrap interval], each seed's success"
        + (" and path ratio:" if paths else ":"),
        "",
        "| split | IQM | per seed: success |" + (" per seed: path / oracle |" if paths else ""),
        "|---|---|---|" + ("---|" if paths else ""),
    ]
    for s in splits:
        if s not in iqm or len(per.get(s, [])) != iqm[s]["runs"]:
            continue
        a, rs = iqm[s], sorted(per[s], key=lambda r: str(r["train_seed"]))
        succ = " ".join(f"{r['success_rate']:.2f}" for r in rs)
        path = " ".join("–" if r["path_ratio"] is None else f"{r['path_ratio']:.2f}×" for r in rs)
        ci = f"[{a['ci95'][0]:.2f}, {a['ci95'][1]:.2f}]"
        lines.append(f"| {s} | {a['iqm']:.2f} {ci} | {succ} |" + (f" {path} |" if paths else ""))
    return lines


if __name__ == "__main__":
    raise SystemExit(main())

"""The shipped policies against the oracle and a random policy on the bundled ``lab`` scene.

    python -m benchmarks.policies [--episodes 200] [--seed 0]

``sensorplan evaluate`` (:func:`agents.evaluation.evaluate.evaluate`) of three cases, every
policy on the same episode seeds (1,000,000 + seed onwards, never used in training):

* Navigate-v0 on ``lab`` from the scene's fixed start: the oracle, the random policy and the
  two shipped PPO policies (``ppo_navigate_lab``, trained from the fixed start, and
  ``ppo_navigate_lab_random_start``);
* the same from seeded random starts (``random_start=True``);
* Recognize-v0 on ``lab`` from random starts with the observation the shipped EDR policy was
  trained with (``ppo_recognize_random``: 4 stacked frames, procedural scenes only, never
  ``lab``) -- the demo's step 5.

The data (``policies.json``) and the page fragment (``policies.md``) go to ``--out`` (default
``runs/benchmarks/policies/``), or with ``--update-results`` to the tracked
``benchmarks/results/policies.json`` and ``docs/results/policies.md``.  Needs the ``rl``
extra (the PPO policies).
"""

from __future__ import annotations

import argparse
import time
from typing import Any

from agents.demo import PRETRAINED, PRETRAINED_RECOGNIZE, RECOGNIZE_KWARGS
from agents.evaluation.evaluate import EVAL_SEED_BASE, evaluate

from . import _results

NAV = "sensorplan/Navigate-v0"
REC = "sensorplan/Recognize-v0"


def cases() -> list[dict[str, Any]]:
    """(title, env id, env kwargs, policies) of every case."""
    nav = ["oracle", "random", *(str(p) for p in PRETRAINED)]
    return [
        {
            "title": "Navigate-v0, lab, fixed start",
            "env": NAV,
            "kwargs": {"scene": "lab"},
            "policies": nav,
        },
        {
            "title": "Navigate-v0, lab, random starts",
            "env": NAV,
            "kwargs": {"scene": "lab", "random_start": True},
            "policies": nav,
        },
        {
            "title": "Recognize-v0, lab, random starts",
            "env": REC,
            "kwargs": dict(RECOGNIZE_KWARGS),
            "policies": ["oracle", "random", str(PRETRAINED_RECOGNIZE)],
        },
    ]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        prog="python -m benchmarks.policies", description=__doc__.split("\n\n")[0]
    )
    ap.add_argument("--episodes", type=int, default=200)
    ap.add_argument("--seed", type=int, default=0)
    _results.add_output_args(ap, "policies")
    args = ap.parse_args(argv)
    data: dict[str, Any] = {
        "command": _results.command("benchmarks.policies", argv),
        "machine": _results.machine(),
        "episodes": args.episodes,
        "seed": args.seed,
        "cases": [],
    }
    t0 = time.perf_counter()
    for c in cases():
        res = evaluate(
            c["env"],
            c["policies"],
            episodes=args.episodes,
            seed=args.seed,
            env_kwargs=c["kwargs"],
            out=False,
            plot=False,
            verbose=False,
        )
        data["cases"].append(
            {
                "title": c["title"],
                "env": c["env"],
                "env_kwargs": c["kwargs"],
                "independent_episodes": res.get("independent_episodes", True),
                "rows": [
                    {
                        "policy": p["name"],
                        "success_rate": p["success_rate"],
                        "ci95": list(p["success_ci95"]),
                        "mean_return": p["mean_return"],
                        "mean_steps": p["mean_steps"],
                        "mean_path_length": p["mean_path_length"],
                        "normalized_score": p.get("normalized_score"),
                    }
                    for p in res["policies"]
                ],
            }
        )
        print(render({**data, "cases": data["cases"][-1:]}), flush=True)
    data["seconds"] = round(time.perf_counter() - t0, 1)
    _results.write("policies", data, args.out, args.update_results)
    return 0


def render(data: dict[str, Any]) -> str:
    """The page fragment: one table per case."""
    out = []
    for c in data["cases"]:
        lines = [
            f"**{c['title']}**",
            "",
            "| policy | success | 95 % Wilson CI | return | steps | path (m) | normalized |",
            "| --- | ---: | --- | ---: | ---: | ---: | ---: |",
        ]
        for r in c["rows"]:
            ns = "" if r["normalized_score"] is None else f"{r['normalized_score']:.3f}"
            lo, hi = r["ci95"]
            lines.append(
                f"| {r['policy']} | {r['success_rate']:.3f} | [{lo:.3f}, {hi:.3f}] | "
                f"{r['mean_return']:.3f} | {r['mean_steps']:.1f} | "
                f"{r['mean_path_length']:.2f} | {ns} |"
            )
        if not c["independent_episodes"]:
            lines += [
                "",
                "Every episode starts from the scene's fixed start: a deterministic policy replays "
                "nearly one episode, so the Wilson interval is too narrow.",
            ]
        out.append("\n".join(lines))
    text = "\n\n".join(out)
    if "seconds" in data:
        m = data["machine"]
        text += (
            f"\n\n`{data['command']}`: {data['episodes']} episodes per policy and case, episode "
            f"seeds {EVAL_SEED_BASE + data['seed']:,} onwards; {data['seconds']:,.0f} s on "
            f"{m['cpus']} CPUs (load average {m['load_average']})."
        )
    return text + "\n"


if __name__ == "__main__":
    raise SystemExit(main())

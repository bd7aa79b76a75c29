"""The pixel policy of Placement-v0 against PPO and the oracle on the ``hard`` level.

    python -m benchmarks.pixel_placement [--episodes 100] [--seed 0] [--model PATH]

``sensorplan benchmark --env sensorplan/Placement-v0 --level hard --splits test ood real``
(:func:`agents.evaluation.benchmark.benchmark`) of the shipped pixel policy
(``agents/pretrained/pixel_placement_hard.pt``, :mod:`agents.learning.pixel_bc`), the
shipped PPO policy ``ppo_placement_random`` and the oracle, every policy on the same episode
seeds.  ``test`` is the held-out pool of the level (seed 1; the policies were trained on pools
of seed 0); ``ood`` and ``real`` the bundled and real maps, each one
scene with its own sensor, so that a deterministic policy plays one decision there.  The
policy's training record (labelling and fitting time, the share of training scenes with a
right pixel action) comes from the config beside the model.

A second table plays every scene once, by the exact labels of all its pixel actions
(:func:`agents.learning.pixel_bc.scene_data`): the 64 scenes of the test pool, the bundled and
the real maps, for the pixel policy and for :func:`agents.learning.pixel_bc.channel_rule`, a
fixed rule on the ``hull_views`` and ``aim_views`` channels (no learning), so that what the
learned net adds to those channels can be read off.  Needs the ``rl`` extra.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path
from typing import Any

from . import _results

ENV = "sensorplan/Placement-v0"
PRETRAINED = Path(__file__).resolve().parents[1] / "agents" / "pretrained"
MODEL = PRETRAINED / "pixel_placement_hard.pt"
PPO = PRETRAINED / "ppo_placement_random.zip"


def main(argv: list[str] | None = None) -> int:
    from agents.evaluation.benchmark import benchmark
    from agents.learning.policies import model_config

    ap = argparse.ArgumentParser(
        prog="python -m benchmarks.pixel_placement", description=__doc__.split("\n\n")[0]
    )
    ap.add_argument("--episodes", type=int, default=100)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--model", type=Path, default=MODEL, help="the pixel policy (.pt)")
    ap.add_argument(
        "--seed-models",
        type=Path,
        nargs="*",
        default=[],
        help="more training seeds of the same config (.pt): the IQM over all seeds per split",
    )
    _results.add_output_args(ap, "pixel_placement")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    cfg = model_config(args.model) or {}
    with tempfile.TemporaryDirectory() as tmp:
        res = benchmark(
            ENV,
            [str(args.model), *map(str, args.seed_models), str(PPO), "oracle"],
            episodes=args.episodes,
            seed=args.seed,
            split_names=["test", "ood", "real"],
            level="hard",
            out=tmp,
            verbose=False,
        )
    scenes = per_scene(args.model)
    names = {str(args.model): "pixel policy", str(PPO): "PPO (ppo_placement_random)"}
    rows = []
    iqm = _results.iqm_rows(res)
    for split, r in res["splits"].items():
        for p in r["policies"]:
            if p["spec"] in map(str, args.seed_models):
                continue  # in the IQM only
            rows.append(
                {
                    "split": split,
                    "policy": names.get(p["spec"], p["spec"]),
                    "successes": p["successes"],
                    "episodes": p["episodes"],
                    "distinct": p["distinct_episodes"],
                    "ci95": list(p["success_ci95"]),
                }
            )
    data: dict[str, Any] = {
        "command": _results.command("benchmarks.pixel_placement", argv),
        "machine": _results.machine(),
        "model": args.model.name,
        "training": {
            k: cfg.get(k)
            for k in ("command", "labelled_scenes", "solvable_fraction", "epochs", "wall_time_s")
        },
        "rows": rows,
        "iqm": iqm,
        "scenes": scenes,
        "seconds": round(time.perf_counter() - t0, 1),
    }
    _results.write("pixel_placement", data, args.out, args.update_results)
    print(render(data))
    return 0


#: the procedural split of :func:`per_scene`: the hard level's test pool, every scene once
TEST_POOL = {"scene": "random", "difficulty": "hard", "scene_pool_seed": 1, "scene_pool_size": 64}


def per_scene(model: Path) -> list[dict[str, Any]]:
    """Rows ``{split, scenes, solvable, policy, rule}``: of the ``scenes`` of each split,
    how many have a right pixel action, how many the pixel policy ``model`` gets right and how
    many :func:`~agents.learning.pixel_bc.channel_rule` does, each scene played once."""
    import numpy as np

    from agents.learning import pixel_bc
    from agents.learning.policies import model_config, play_env_kwargs
    from sensorplan_gym import BUNDLED_SCENES, REAL_SCENES

    policy = pixel_bc.PixelPolicy.load(model)
    cfg = model_config(model) or {}
    views = {"hull_views": True, "aim_views": True}
    aim = pixel_bc.aim_channels(views)
    splits = {"test": TEST_POOL}
    splits.update({f"ood:{s}": {"scene": s} for s in BUNDLED_SCENES})
    splits.update({f"real:{s[5:]}": {"scene": s} for s in REAL_SCENES})
    rows = []
    for name, kw in splits.items():
        obs_r, masks = pixel_bc.scene_data({**kw, **views})
        play = play_env_kwargs(cfg, kw)
        same = all(play.get(k) == v for k, v in views.items())
        obs_m = obs_r if same else pixel_bc.scene_data(play)[0]
        flat = masks.reshape(len(masks), -1)
        at = np.arange(len(flat))
        got = flat[at, policy.predict(obs_m)[0]]
        rule = flat[at, pixel_bc.channel_rule(obs_r, aim)]
        rows.append(
            {
                "split": name,
                "scenes": len(flat),
                "solvable": int(flat.any(axis=1).sum()),
                "policy": int(got.sum()),
                "rule": int(rule.sum()),
            }
        )
    return rows


def render(data: dict[str, Any]) -> str:
    """The page fragment: success per split and policy, then the training record."""
    order = ["pixel policy", "PPO (ppo_placement_random)", "oracle"]
    splits = list(dict.fromkeys(r["split"] for r in data["rows"]))
    by = {(r["split"], r["policy"]): r for r in data["rows"]}
    lines = [
        "| split | " + " | ".join(order) + " | distinct episodes |",
        "|---|" + "---|" * (len(order) + 1),
    ]
    for s in splits:
        cells = [_results.success_cell(by.get((s, p))) for p in order]
        d = next(by[(s, p)]["distinct"] for p in order if (s, p) in by)
        lines.append(f"| {s} | " + " | ".join(cells) + f" | {d} |")
    if data.get("iqm"):
        runs = data["iqm"][0]["runs"]
        seeds = ", ".join(str(s) for s in data["iqm"][0]["train_seeds"])
        lines += [
            "",
            f"The pixel policy's config over {runs} training seeds ({seeds}), IQM of the success "
            "rate [95 % stratified-bootstrap interval]: "
            + "; ".join(
                f"{r['split']} {r['iqm']:.2f} [{r['ci95'][0]:.2f}, {r['ci95'][1]:.2f}]"
                for r in data["iqm"]
            )
            + ".",
        ]
    if data.get("scenes"):
        lines += [
            "",
            "Each scene played once, scored by the exact labels of all its pixel actions:",
            "",
            "| split | scenes | with a right pixel action | pixel policy | channel rule "
            "(no learning) |",
            "|---|---|---|---|---|",
        ]
        for r in data["scenes"]:
            lines.append(
                f"| {r['split']} | {r['scenes']} | {r['solvable']} | {r['policy']} | {r['rule']} |"
            )
    t = data["training"]
    wall = t.get("wall_time_s") or {}
    lines += [
        "",
        f"Success rate [95 % Wilson interval, sized by the distinct episodes], "
        f"{data['rows'][0]['episodes']} episodes per split, deterministic policies, one training "
        f"seed. The pixel policy (`{data['model']}`) was trained with `{t.get('command')}`: "
        f"{t.get('labelled_scenes')} scenes labelled exactly in {wall.get('label')} s "
        f"({t.get('solvable_fraction', 0):.3f} of them have a right pixel action), "
        f"{t.get('epochs')} epochs in {wall.get('fit')} s on the 2-CPU machine.",
        "",
        f"Measured with `{data['command']}` ({data['seconds']} s).",
    ]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    raise SystemExit(main())

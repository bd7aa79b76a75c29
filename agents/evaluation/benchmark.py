"""The benchmark protocol: every policy on named scene splits, one table.

``sensorplan benchmark --env ID --policies oracle random model.zip ... [--episodes N]
[--difficulty D] [--level easy|medium|hard] [--splits train test ood] [--env-kwargs JSON]
[--out DIR]``

Splits (each an env-kwargs override on top of ``--env-kwargs``):

Procedural splits of tasks with a start (Navigate, Recognize) draw a start per episode
(``random_start=True``); every result reports its number of distinct (scene, start) episodes
(``distinct_episodes``), which sizes its Wilson interval.

* ``train`` -- the training pool: the scene pool the model policies were trained on (the
  pool kwargs of their resolved configs, :data:`POOL_KWARGS`, at their own
  ``min_start_distance``); without a model trained on ``scene="random"``, the pool of seed
  :data:`TRAIN_POOL_SEED` (what ``scene="random"`` trains on by default);
* ``test`` -- procedural scenes from the disjoint pool of seed :data:`TEST_POOL_SEED`, never
  trained on;
* ``ood`` -- every bundled scene (``lab``, ``edr``, ``corridor``, ``warehouse``), one split
  each (``ood:lab`` ...): hand-made maps outside the generator's distribution, from a start
  drawn per episode (``random_start=True``) where the task has one;
* ``real`` -- every bundled real floor plan (:data:`sensorplan_gym.REAL_SCENES`, public ROS
  maps of the Willow Garage office and the LSE arena), one split each (``real:willow_north``
  ...); not in the default splits (give ``--splits train test ood real``);
* ``narrow`` -- the bundled scenes and real maps with a narrow sensor: each at the narrowest
  of 60°, 75° and 90° from which some pose of its recognizable region keeps both swept hulls
  in view (:data:`NARROW_FOV_DEG`, the scene's own field of view replaced; ``warehouse`` has
  none up to 120°), one split each (``narrow:lab`` ...): the narrow-field-of-view rooms that
  policies trained on full circles fail; not in the default splits.

The difficulty knob ``--difficulty D`` (default :data:`DEFAULT_DIFFICULTY`) is the env kwarg
``min_start_distance``: procedural scenes start at least ``D`` scene diameters away from the
recognizable region (Navigate, Recognize; Placement has no start).  It is reported with every
result, with the measured mean start distance of the scenes played.  At the default the random
policy succeeds in about 0.2 of Navigate-v0's test episodes (measured with 64 batched
envs over 1,000 steps: 0.22 at ``D = 0.35``, 0.83 at ``D = 0``).

The benchmark levels ``--level easy|medium|hard`` (:data:`geometry.families.DIFFICULTIES`)
draw the procedural splits from the level's scene family (field of view, range, room shapes,
clutter, G/H kinds, targets) at the level's ``min_start_distance`` (unless ``--difficulty``
is given); the bundled scenes are played as they are.

Per split and policy: what :func:`agents.evaluation.evaluate.evaluate` reports (success with
its Wilson interval, return, steps, path length, normalized score; IQM over training seeds).  Writes
``benchmark.json`` and ``benchmark.csv`` to ``--out`` and each split's evaluation files under
``--out/<split>/``.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Any

from ..checks import check_writable_dir
from ..learning.policies import check_policies, make_env
from .episodes import EVAL_SEED_BASE
from .evaluate import evaluate, fresh_dir

__all__ = [
    "DEFAULT_DIFFICULTY",
    "POOL_KWARGS",
    "TEST_POOL_SEED",
    "TRAIN_POOL_SEED",
    "benchmark",
    "splits",
    "training_pool",
]

TRAIN_POOL_SEED = 0
TEST_POOL_SEED = 1
DEFAULT_DIFFICULTY = 0.35


# env kwargs that decide which scenes a scene="random" pool holds (and their defaults)
POOL_KWARGS = {
    "scene_pool_seed": TRAIN_POOL_SEED,
    "scene_pool_size": 64,
    "min_start_distance": None,
    "max_scene_tries": 25,
    "random_scene_kwargs": None,
    "family": None,
    "difficulty": None,
}


def training_pool(policies: list[str]) -> dict | None:
    """The pool the model policies were trained on: the :data:`POOL_KWARGS` of their resolved
    configs' env kwargs (defaults filled in), for models trained on ``scene="random"``;
    ``None`` when none was.  Raises ``ValueError`` naming the models when their pools differ
    (benchmark them separately: one ``train`` split is one pool)."""
    from ..learning.policies import model_config

    pools: dict[str, list[str]] = {}
    for spec in policies:
        if spec in ("oracle", "random"):
            continue
        kw = (model_config(spec) or {}).get("env_kwargs") or {}
        if kw.get("scene") != "random":
            continue
        pool = {k: kw.get(k, d) for k, d in POOL_KWARGS.items()}
        pools.setdefault(json.dumps(pool, sort_keys=True), []).append(spec)
    if len(pools) > 1:
        raise ValueError(
            "the models were trained on different scene pools, so no one train split is "
            "their training pool; benchmark them separately: "
            + "; ".join(f"{', '.join(v)}: {k}" for k, v in pools.items())
        )
    return json.loads(next(iter(pools))) if pools else None


#: the field of view (degrees) of each ``narrow`` split: per scene the narrowest of 60, 75 and
#: 90 at which the oracle finds a recognizing pose (``agents.planning.oracle.plan_viewpoint``;
#: tested); ``lab`` at 60 and ``corridor`` at 75 have none, ``warehouse`` none up to 120
NARROW_FOV_DEG = {
    "edr": 60.0,
    "lab": 75.0,
    "corridor": 90.0,
    "real/heidelberg_l1": 60.0,
    "real/heidelberg_l2": 60.0,
    "real/lse_arena": 60.0,
    "real/willow_north": 60.0,
    "real/willow_south": 60.0,
}


def splits(
    names: list[str],
    difficulty: float | None,
    needs_start: bool,
    train_pool: dict | None = None,
    level: str | None = None,
) -> dict[str, dict]:
    """Env-kwargs overrides of the named splits (``ood`` expands to one split per scene).
    ``train`` is ``train_pool`` (see :func:`training_pool`; its own ``min_start_distance``
    replaces ``difficulty``) when given, else the default pool of seed
    :data:`TRAIN_POOL_SEED` at ``difficulty``.  ``level`` (``"easy"``, ``"medium"``,
    ``"hard"``: :data:`geometry.families.DIFFICULTIES`) draws the procedural splits from that
    level's scene family, at its ``min_start_distance`` unless ``difficulty`` is given."""
    from sensorplan_gym import BUNDLED_SCENES, REAL_SCENES

    hard: dict = {}
    if level is not None:
        hard["difficulty"] = level
    if needs_start and difficulty is not None and difficulty > 0:
        hard.update(min_start_distance=difficulty)
    if needs_start and (level is not None or "min_start_distance" in hard):
        hard["max_scene_tries"] = 200
    if needs_start:  # a start drawn per episode: 100 episodes are not 64 scene-start pairs
        hard = {"random_start": True, **hard}
    # bundled and real scenes: a start drawn per episode too (their fixed start is one episode)
    start = {"random_start": True} if needs_start else {}
    out: dict[str, dict] = {}
    for name in names:
        if name == "train" and train_pool is not None:
            pool = {k: v for k, v in train_pool.items() if v is not None}
            if not needs_start:
                pool.pop("min_start_distance", None)
            out[name] = {"scene": "random", **start, **pool}
        elif name == "train":
            out[name] = {"scene": "random", "scene_pool_seed": TRAIN_POOL_SEED, **hard}
        elif name == "test":
            out[name] = {"scene": "random", "scene_pool_seed": TEST_POOL_SEED, **hard}
        elif name == "ood":
            out.update({f"ood:{s}": {"scene": s, **start} for s in BUNDLED_SCENES})
        elif name == "real":
            out.update({f"real:{s[5:]}": {"scene": s, **start} for s in REAL_SCENES})
        elif name.startswith("ood:") and name[4:] in BUNDLED_SCENES:
            out[name] = {"scene": name[4:], **start}
        elif name.startswith("real:") and f"real/{name[5:]}" in REAL_SCENES:
            out[name] = {"scene": f"real/{name[5:]}", **start}
        elif name == "narrow":
            for scene, fov in NARROW_FOV_DEG.items():
                out[f"narrow:{scene.removeprefix('real/')}"] = {
                    "scene": scene,
                    "fov_deg": fov,
                    **start,
                }
        elif name.startswith("narrow:") and (
            name[7:] in NARROW_FOV_DEG or f"real/{name[7:]}" in NARROW_FOV_DEG
        ):
            scene = name[7:] if name[7:] in NARROW_FOV_DEG else f"real/{name[7:]}"
            out[name] = {"scene": scene, "fov_deg": NARROW_FOV_DEG[scene], **start}
        else:
            raise ValueError(
                f"unknown split {name!r}: use train, test, ood, ood:<scene> "
                f"({', '.join(BUNDLED_SCENES)}), real or real:<map> "
                f"({', '.join(s[5:] for s in REAL_SCENES)}), narrow or narrow:<scene or map> "
                f"({', '.join(s.removeprefix('real/') for s in NARROW_FOV_DEG)})"
            )
    return out


def _start_distance(env_id: str, kw: dict, seeds: list[int]) -> float | None:
    """Mean distance (scene diameters) from the start to the region over the episodes."""
    import gymnasium as gym

    env = gym.make(env_id, **kw)
    if not env.unwrapped.batch.needs_start:
        return None
    ds = []
    for s in seeds:
        _, info = env.reset(seed=s)
        ds.append(info["distance_to_region"] / env.unwrapped.world.diameter)
    return float(sum(ds) / len(ds))


def benchmark(
    env_id: str,
    policies: list[str],
    *,
    episodes: int = 100,
    seed: int = 0,
    difficulty: float | None = DEFAULT_DIFFICULTY,
    split_names: list[str] | None = None,
    level: str | None = None,
    env_kwargs: dict | None = None,
    out: str | Path | None = None,
    verbose: bool = True,
    deterministic: bool = True,
) -> dict[str, Any]:
    """Evaluate ``policies`` on every split (``deterministic=False``: trained models sample
    their actions); returns ``{"splits": {name: results}, "rows":
    [...]}`` (one row per split and policy) and writes benchmark.json / .csv to ``out``."""

    import sensorplan_gym  # noqa: F401

    check_policies(policies)  # every path, before any episode is played
    if level is not None:
        from geometry.families import get_difficulty

        lv = get_difficulty(level)  # a clear error for an unknown level, before any output
        if difficulty is None:
            difficulty = lv.min_start_distance
    out = check_writable_dir(
        out if out is not None else fresh_dir(Path("runs") / f"benchmark_{env_id.split('/')[-1]}")
    )
    base = dict(env_kwargs or {})
    probe = make_env(env_id, {k: v for k, v in base.items() if k != "scene"})
    needs_start = bool(probe.unwrapped.batch.needs_start)
    probe.close()
    names = split_names or ["train", "test", "ood"]
    pool = training_pool(policies) if "train" in names else None
    sp = splits(names, difficulty, needs_start, train_pool=pool, level=level)
    res: dict[str, Any] = {
        "env_id": env_id,
        "difficulty": {
            "min_start_distance": difficulty if needs_start else None,
            "level": level,
        },
        "episodes": episodes,
        "seed": seed,
        "deterministic": bool(deterministic),
        "splits": {},
        "rows": [],
    }
    seeds = [EVAL_SEED_BASE + seed + i for i in range(min(episodes, 20))]
    for name, over in sp.items():
        kw = {**base, **over}
        if verbose:
            print(f"split {name}: {over}", flush=True)
        r = evaluate(
            env_id,
            policies,
            episodes=episodes,
            seed=seed,
            env_kwargs=kw,
            out=out / name.replace(":", "_"),
            verbose=verbose,
            deterministic=deterministic,
        )
        r["start_distance"] = _start_distance(env_id, kw, seeds)
        r["min_start_distance"] = kw.get("min_start_distance") if needs_start else None
        res["splits"][name] = r
        for p in r["policies"]:
            res["rows"].append(
                {
                    "split": name,
                    "policy": p["name"],
                    "success_rate": p["success_rate"],
                    "ci_low": p["success_ci95"][0],
                    "ci_high": p["success_ci95"][1],
                    "distinct_episodes": p["distinct_episodes"],
                    "mean_return": p["mean_return"],
                    "mean_steps": p["mean_steps"],
                    "mean_path_length": p["mean_path_length"],
                    "normalized_score": p.get("normalized_score"),
                    "start_distance": r["start_distance"],
                    "min_start_distance": r["min_start_distance"],
                }
            )
    out.mkdir(parents=True, exist_ok=True)  # evaluate made it, unless no split ran
    (out / "benchmark.json").write_text(json.dumps(res, indent=1, default=str))
    with open(out / "benchmark.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(res["rows"][0]))
        w.writeheader()
        w.writerows(res["rows"])
    if verbose:
        print(format_rows(res))
    return res


def format_rows(res: dict[str, Any]) -> str:
    """A plain-text table of ``res["rows"]``."""
    head = (
        f"{'split':<16} {'policy':<28} {'success':>7} {'95% CI':>15} {'return':>7} "
        f"{'steps':>6} {'norm.':>6} {'start d':>7} {'distinct':>8}"
    )
    lines = [head, "-" * len(head)]
    for r in res["rows"]:
        ns = "" if r["normalized_score"] is None else f"{r['normalized_score']:.2f}"
        sd = "" if r["start_distance"] is None else f"{r['start_distance']:.2f}"
        lines.append(
            f"{r['split']:<16} {r['policy'][:28]:<28} {r['success_rate']:7.3f} "
            f"[{r['ci_low']:.3f}, {r['ci_high']:.3f}] {r['mean_return']:7.3f} "
            f"{r['mean_steps']:6.1f} {ns:>6} {sd:>7} {r['distinct_episodes']:>8}"
        )
    d = res["difficulty"]["min_start_distance"]
    lines.append(
        f"difficulty: min_start_distance = {d} (start d: mean start distance / diameter; "
        "distinct: distinct (scene, start) episodes, which size the 95% CI)"
    )
    return "\n".join(lines)

"""``sensorplan demo``: the paper's surveillance scenario end to end (section 6).

On the bundled ``lab`` scene (a room with furniture footprints, a doorway G and a
second watch spot H, and a start like TOMMY's from which neither can be watched):

1. the exact complete-visibility region of the doorway (paper Figure 15);
2. the recognizable region R(G) n R(H) - C(G, H), shrunk for safety, the chosen
   placement, the aim and the motion to it (Figure 16; a shortest path around
   obstacles when no one-step motion exists);
3. the oracle drives there in ``Recognize-v0`` (a hidden target stands in G or H),
   reads the simulated range sensor, and declares G or H from the readings;
4. oracle vs the shipped PPO policies vs random on ``Navigate-v0`` (lab): a table.

Figures and the evaluation files go to the folder given by ``--out`` (default
``sensorplan-demo``); the path is printed.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

__all__ = ["main"]

PRETRAINED = [
    Path(__file__).parent / "pretrained" / "ppo_navigate_lab.zip",
    Path(__file__).parent / "pretrained" / "ppo_navigate_lab_random_start.zip",
]


def _figure_15(scene, region, path: Path) -> None:
    import matplotlib.pyplot as plt

    from geometry.plot import draw_region, draw_scene

    fig, ax = plt.subplots(figsize=(7, 6))
    draw_region(ax, region, label="complete visibility of the doorway G")
    draw_scene(ax, scene)
    ax.set_title("Figure 15: placements that see all of the target anywhere in G")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)


def _figure_16(scene, world, plan, start, path: Path) -> None:
    import matplotlib.pyplot as plt

    from geometry.plot import draw_pose, draw_region, draw_scene

    fig, ax = plt.subplots(figsize=(7, 6))
    draw_region(ax, world.region, color="#bdbdbd", alpha=0.6, label="recognizable region")
    if plan.placement is not None and plan.placement.region is not None:
        draw_region(ax, plan.placement.region, label="shrunk region")
    draw_scene(ax, scene)
    ax.plot(start[0], start[1], "s", color="black", ms=7, label="start (cannot tell G from H)")
    if plan.status == "ok":
        p = np.asarray(plan.path)
        motion = "one-step motion" if plan.one_step else "shortest path"
        ax.plot(p[:, 0], p[:, 1], "-", color="#ff7f0e", lw=2, label=motion)
        draw_pose(
            ax,
            plan.point[0],
            plan.point[1],
            plan.aim,
            fov=world.fov,
            length=0.06 * world.diameter,
            color="#ff7f0e",
            label="chosen placement",
        )
    ax.set_title("Figure 16: shrunk region, chosen placement and motion")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)


def _recognize(out: Path, seed: int) -> tuple[str, str, int]:
    """One Recognize-v0 episode with the oracle; returns (truth, declared, steps)."""
    import gymnasium as gym
    from PIL import Image

    import sensorplan_gym  # noqa: F401

    from .oracle import OraclePolicy

    env = gym.make("sensorplan/Recognize-v0", scene="lab", render_mode="rgb_array")
    oracle = OraclePolicy(env)
    obs, info = env.reset(seed=seed)
    start, done, steps = True, False, 0
    while not done:
        action, _ = oracle.predict(obs, episode_start=start)
        start = False
        obs, _, term, trunc, info = env.step(action)
        steps += 1
        done = term or trunc
        if done:
            Image.fromarray(env.render()).save(out / "recognize_lab.png")
    drv = oracle.drivers[0]
    if drv.decision is not None:
        print(f"   readings: {drv.decision.n_points} target points; {drv.decision.reason}")
    env.close()
    return info.get("target_in", "?"), info.get("declared") or "none", steps


def main(argv: list[str] | None = None) -> int:
    """Run the demo; returns a process exit code."""
    ap = argparse.ArgumentParser(prog="sensorplan demo", description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="sensorplan-demo", help="folder for figures and results")
    ap.add_argument(
        "--episodes",
        type=int,
        default=50,
        help="evaluation episodes per policy (default 50; README uses 200)",
    )
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    import matplotlib

    matplotlib.use("Agg")
    t0 = time.perf_counter()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    from geometry import complete_region
    from sensorplan_gym.core.world import World, WorldConfig, load_scene

    from .oracle import plan_viewpoint

    scene = load_scene("lab")
    print(f"1. Scene 'lab': {len(scene.obstacles)} furniture footprints, doorway G, watch spot H")
    t = time.perf_counter()
    vis = complete_region(scene, target_in="goal", theta=0.0)
    print(
        f"   complete-visibility region of the doorway: area {vis.area:.2f} m^2, "
        f"computed exactly in {1e3 * (time.perf_counter() - t):.1f} ms"
    )
    _figure_15(scene, vis, out / "fig15_visibility.png")

    world = World(scene, WorldConfig())
    start = scene.start
    plan = plan_viewpoint(world, start[:2])
    print(
        f"2. Recognizable region R(G) n R(H) - C(G,H): area {world.region.area:.2f} m^2; "
        f"start {tuple(round(v, 2) for v in start[:2])} recognizes: "
        f"{world.recognizing(*start)}"
    )
    if plan.status != "ok":
        print(f"   no placement: {plan.reason}")
        return 1
    kind = "one-step motion" if plan.one_step else f"shortest path with {len(plan.path) - 1} legs"
    print(
        f"   chosen placement ({plan.point[0]:.2f}, {plan.point[1]:.2f}), aim "
        f"{math.degrees(plan.aim):.1f} deg, {kind} of {plan.length:.2f} m"
    )
    _figure_16(scene, world, plan, start, out / "fig16_placement.png")

    truth, declared, steps = _recognize(out, args.seed)
    verdict = "correct" if truth == declared else "WRONG"
    print(
        f"3. Oracle drove there and declared '{declared}' after {steps} steps; the target was "
        f"in '{truth}' ({verdict})"
    )

    print(f"4. Navigate-v0 (lab), {args.episodes} episodes per policy:")
    from .evaluate import evaluate, format_table

    policies = ["oracle", "random"] + [str(p) for p in PRETRAINED if p.exists()]
    if len(policies) == 2:
        print("   (no shipped policy found; evaluating oracle and random only)")
    res = evaluate(
        "sensorplan/Navigate-v0",
        policies,
        episodes=args.episodes,
        seed=args.seed,
        env_kwargs={"scene": "lab"},
        out=out / "navigate_eval",
        verbose=False,
    )
    print(format_table(res))
    print(f"Figures and results in {out.resolve()} ({time.perf_counter() - t0:.1f} s)")
    return 0 if truth == declared else 1

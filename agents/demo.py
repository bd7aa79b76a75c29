"""``sensorplan demo``: the paper's surveillance scenario end to end (section 6).

On the bundled ``lab`` scene (a room with furniture footprints, a doorway G and a
second watch spot H, and a start like TOMMY's from which neither can be watched):

1. the exact complete-visibility region of the doorway (paper Figure 15);
2. the recognizable region R(G) n R(H) - C(G, H), shrunk for safety, the chosen
   placement, the aim and the motion to it (Figure 16; a shortest path around
   obstacles when no one-step motion exists);
3. the oracle drives there in ``Recognize-v0`` (a hidden target stands in G or H),
   reads the simulated range sensor, and declares G or H from the readings;
4. oracle vs the shipped PPO policies vs random on ``Navigate-v0`` (lab): a table;
5. oracle vs the shipped PPO policy for the EDR task (trained on procedural scenes, never
   on ``lab``) vs random on ``Recognize-v0`` (lab, random starts): a table.

Figures and the evaluation files go to the folder given by ``--out`` (default
``sensorplan-demo``); the path is printed.
"""

from __future__ import annotations

import argparse
import importlib.util
import math
import time
from pathlib import Path

import numpy as np

__all__ = ["figure_15", "figure_16", "main", "merge_short_legs"]

#: modules of the ``rl`` extra that loading the shipped PPO policies needs
RL_MODULES = ("yaml", "stable_baselines3", "torch")

#: ``sensorplan demo --help`` text (plain, no reST markup)
_HELP_TEXT = """\
The paper's surveillance scenario end to end (section 6), on the bundled 'lab' scene:

  1. the exact complete-visibility region of the doorway G (paper Figure 15);
  2. the recognizable region R(G) n R(H) - C(G, H), shrunk for safety, the chosen
     placement, the aim and the motion to it (Figure 16);
  3. the oracle drives there in Recognize-v0 and declares G or H from its range readings;
  4. oracle vs the shipped PPO policies vs random on Navigate-v0 (lab): a table.
  5. oracle vs the shipped PPO policy for the EDR task (trained on procedural scenes,
     never on lab) vs random on Recognize-v0 (lab, random starts): a table.
     The PPO policies need the rl extra (pip install -e ".[rl]"); without it the
     tables have oracle and random only.

Figures and evaluation files go to --out (default: sensorplan-demo)."""

PRETRAINED = [
    Path(__file__).parent / "pretrained" / "ppo_navigate_lab.zip",
    Path(__file__).parent / "pretrained" / "ppo_navigate_lab_random_start.zip",
]
#: the shipped Recognize-v0 policy (trained on procedural scenes) and the env it plays
PRETRAINED_RECOGNIZE = Path(__file__).parent / "pretrained" / "ppo_recognize_random.zip"
RECOGNIZE_KWARGS = {
    "scene": "lab",
    "map_ranges": True,
    "map_evidence": True,
    "declare_hold": 3,
    "random_start": True,
}


def merge_short_legs(path: np.ndarray, min_len: float) -> np.ndarray:
    """The way points of ``path`` ((N, 2), world frame) without degenerate legs.

    A way point is dropped when the leg that ends at it is shorter than ``min_len``
    (scene units); the start and the end are always kept.  The planner keeps path corners a
    hair off the obstacles, which can leave a leg of a fraction of a millimetre at a corner:
    such legs are not worth a line in a figure or a count in the text.
    """
    p = np.asarray(path, dtype=float)
    if len(p) <= 2:
        return p
    keep = [p[0]]
    for q in p[1:-1]:
        if np.hypot(*(q - keep[-1])) >= min_len:
            keep.append(q)
    if len(keep) > 1 and np.hypot(*(p[-1] - keep[-1])) < min_len:
        keep.pop()  # the last kept corner is a hair from the end: the end replaces it
    keep.append(p[-1])
    return np.asarray(keep)


def _legend(ax) -> None:
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, framealpha=1.0)


def figure_15(scene, region):
    """Figure 15 analogue: the complete-visibility region of G (a matplotlib Figure)."""
    import matplotlib.pyplot as plt

    from geometry.plot import draw_region, draw_scene

    fig, ax = plt.subplots(figsize=(8, 6))
    draw_region(
        ax,
        region,
        color="#74c476",
        alpha=0.6,
        edgecolor="#238b45",
        linewidth=1.0,
        label=f"complete visibility of the target anywhere in G ({region.area:.1f} m²)",
    )
    draw_scene(ax, scene, unit="m")
    ax.set_title("Figure 15: placements that see all of the target anywhere in G", fontsize=11)
    _legend(ax)
    return fig


def figure_16(scene, world, plan, start, margin: float):
    """Figure 16 analogue: recognizable and shrunk regions, the chosen placement, its aim
    and the motion to it, with a zoom on the margin band (a matplotlib Figure)."""
    import matplotlib.pyplot as plt

    from geometry.plot import draw_pose, draw_region, draw_scene

    fig, ax = plt.subplots(figsize=(8, 6))
    shrunk = plan.placement.region if plan.placement is not None else None
    # zoom window: around the boundary point of the region nearest to the chosen placement,
    # where the safety margin between the two regions shows
    axes = [ax]
    zoom = None
    if plan.status == "ok" and shrunk is not None and not shrunk.is_empty:
        import shapely

        edge = shapely.shortest_line(world.region.boundary, shapely.Point(plan.point))
        cx, cy = np.asarray(edge.coords[0])
        half = max(8 * margin, 0.02 * world.diameter)
        zoom = ax.inset_axes([1.04, 0.0, 0.42, 0.42])
        axes.append(zoom)
    for a in axes:
        main = a is ax
        draw_region(
            a,
            world.region,
            color="#c7e9c0",
            alpha=1.0,
            edgecolor="#238b45",
            linewidth=1.4 if main else 2.0,
            linestyle="--",
            label=(
                f"recognizable region R(G)∩R(H)−C(G,H) ({world.region.area:.2f} m²)"
                if main
                else None
            ),
        )
        if shrunk is not None:
            draw_region(
                a,
                shrunk,
                color="#31a354",
                alpha=0.75,
                label=(
                    f"shrunk by a {margin * 100:.1f} cm safety margin ({shrunk.area:.2f} m²)"
                    if main
                    else None
                ),
            )
        draw_scene(a, scene, unit="m", legend_labels=main)
    ax.plot(start[0], start[1], "s", color="black", ms=7, label="start (cannot tell G from H)")
    if plan.status == "ok":
        p = merge_short_legs(plan.path, 1e-3 * world.diameter)
        legs = len(p) - 1
        motion = (
            f"one-step motion ({plan.length:.2f} m)"
            if legs == 1
            else f"shortest path around obstacles: {legs} legs, {plan.length:.2f} m"
        )
        for a in axes:
            a.plot(
                p[:, 0],
                p[:, 1],
                "-",
                color="#ff7f0e",
                lw=2,
                label=motion if a is ax else None,
                zorder=5,
            )
            draw_pose(
                a,
                plan.point[0],
                plan.point[1],
                plan.aim,
                fov=world.fov,
                length=0.06 * world.diameter if a is ax else 0.3 * half,
                color="black",
                label="chosen placement" if a is ax else None,
                aim_color="#7b3294",
                aim_label=f"aim {math.degrees(plan.aim):.1f}°" if a is ax else None,
            )
    if zoom is not None:
        zoom.set_xlim(cx - half, cx + half)
        zoom.set_ylim(cy - half, cy + half)
        zoom.set_title(
            f"zoom, {2 * half:.2f} m wide: the light band is the margin",
            fontsize=7,
        )
        zoom.tick_params(labelsize=6)
        zoom.set_xlabel("x (m)", fontsize=7)
        zoom.set_ylabel("y (m)", fontsize=7)
        ax.indicate_inset_zoom(zoom, edgecolor="black")
    ax.set_title("Figure 16: shrunk region, chosen placement, aim and motion", fontsize=11)
    _legend(ax)
    return fig


def _save(fig, path: Path) -> None:
    import matplotlib.pyplot as plt

    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)


def _save_with_legend(frame: np.ndarray, title: str, path: Path) -> None:
    """The env frame next to a legend of what the env renderer draws."""
    import matplotlib.pyplot as plt

    from sensorplan_gym.core.rendering import legend_handles

    h, w, _ = frame.shape
    fig = plt.figure(figsize=(w / 100 + 2.6, h / 100 + 0.3), dpi=100)
    ax = fig.add_axes((0, 0, w / 100 / (w / 100 + 2.6), 1 - 0.3 / (h / 100 + 0.3)))
    ax.imshow(frame)
    ax.set_axis_off()
    fig.suptitle(title, fontsize=9, x=0.02, ha="left")
    fig.legend(
        handles=legend_handles(),
        loc="center right",
        fontsize=8,
        frameon=False,
    )
    fig.savefig(path, dpi=100)
    plt.close(fig)


def _recognize(out: Path, seed: int) -> tuple[str, str, int]:
    """One Recognize-v0 episode with the oracle; returns (truth, declared, steps)."""
    import gymnasium as gym

    import sensorplan_gym  # noqa: F401

    from .planning.oracle import OraclePolicy

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
            _save_with_legend(
                env.render(),
                f"Recognize-v0 on lab after {steps} steps: declared {info.get('declared')}, "
                f"the target was in {info.get('target_in')}",
                out / "recognize_lab.png",
            )
    drv = oracle.drivers[0]
    if drv.decision is not None:
        print(f"   readings: {drv.decision.n_points} target points; {drv.decision.reason}")
    env.close()
    return info.get("target_in", "?"), info.get("declared") or "none", steps


def _shipped(paths: list[Path]) -> list[str]:
    """The shipped policy files of ``paths`` that exist and can be loaded (the rl extra);
    says why when none can."""
    missing = [m for m in RL_MODULES if importlib.util.find_spec(m) is None]
    if missing:
        print(
            f"   (the shipped PPO policies need the rl extra -- missing {', '.join(missing)}; "
            f'install it with: pip install -e ".[rl]"; evaluating oracle and random only)'
        )
        return []
    found = [str(p) for p in paths if p.exists()]
    if not found:
        print("   (no shipped policy found; evaluating oracle and random only)")
    return found


def main(argv: list[str] | None = None) -> int:
    """Run the demo; returns a process exit code."""
    ap = argparse.ArgumentParser(
        prog="sensorplan demo",
        description=_HELP_TEXT,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
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

    from .planning.oracle import plan_viewpoint

    scene = load_scene("lab")
    print(f"1. Scene 'lab': {len(scene.obstacles)} furniture footprints, doorway G, watch spot H")
    t = time.perf_counter()
    vis = complete_region(scene, target_in="goal", theta=0.0)
    cold = time.perf_counter() - t
    t = time.perf_counter()
    complete_region(scene, target_in="goal", theta=0.0)  # warm: the kernels are compiled
    warm = time.perf_counter() - t
    print(
        f"   complete-visibility region of the doorway: area {vis.area:.2f} m^2, "
        f"computed exactly in {1e3 * warm:.1f} ms ({1e3 * cold:.0f} ms on the first call, "
        "which compiles the numba kernels)"
    )
    _save(figure_15(scene, vis), out / "fig15_visibility.png")

    world = World(scene, WorldConfig())
    start = scene.start
    margin = 2e-3 * world.diameter  # plan_viewpoint's default safety margin, named here
    plan = plan_viewpoint(world, start[:2], margin=margin)
    print(
        f"2. Recognizable region R(G) n R(H) - C(G,H): area {world.region.area:.2f} m^2; "
        f"start {tuple(round(v, 2) for v in start[:2])} recognizes: "
        f"{world.recognizing(*start)}"
    )
    if plan.status != "ok":
        print(f"   no placement: {plan.reason}")
        return 1
    legs = len(merge_short_legs(plan.path, 1e-3 * world.diameter)) - 1
    kind = "one-step motion" if legs == 1 else f"shortest path with {legs} legs"
    print(
        f"   chosen placement ({plan.point[0]:.2f}, {plan.point[1]:.2f}), aim "
        f"{math.degrees(plan.aim):.1f} deg, {kind} of {plan.length:.2f} m"
    )
    _save(figure_16(scene, world, plan, start, margin), out / "fig16_placement.png")

    truth, declared, steps = _recognize(out, args.seed)
    verdict = "correct" if truth == declared else "WRONG"
    print(
        f"3. Oracle drove there and declared '{declared}' after {steps} steps; the target was "
        f"in '{truth}' ({verdict})"
    )

    print(f"4. Navigate-v0 (lab), {args.episodes} episodes per policy:")
    from .evaluation.evaluate import evaluate, format_table

    policies = ["oracle", "random"] + _shipped(PRETRAINED)
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

    print(
        f"5. Recognize-v0 (lab, random starts), {args.episodes} episodes per policy "
        "(the PPO policy was trained on procedural scenes, never on lab):"
    )
    res = evaluate(
        "sensorplan/Recognize-v0",
        ["oracle", "random"] + _shipped([PRETRAINED_RECOGNIZE]),
        episodes=args.episodes,
        seed=args.seed,
        env_kwargs=RECOGNIZE_KWARGS,
        out=out / "recognize_eval",
        verbose=False,
    )
    print(format_table(res))
    print(f"Figures and results in {out.resolve()} ({time.perf_counter() - t0:.1f} s)")
    return 0 if truth == declared else 1

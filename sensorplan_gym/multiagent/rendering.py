"""RGB frames of the watch task with matplotlib's Agg canvas (no pyplot, no window).

A frame shows the room (outside in grey), obstacles (dark grey), G (blue) and H (red), the
exact region that sees A wherever it is in G and in H (light green:
``complete_region``/``partial_region`` of G intersected with that of H, swept over G and H,
paper 3.1.2/3.2.2), robot A (filled green while some watcher sees it, else grey) with its
trail so far, and every watcher (a coloured disc with a heading tick, its field-of-view wedge
out to its reach, and its beams to their hit points).  The picture is for people: it shows
A, which the watchers' observations never do.
"""

from __future__ import annotations

import math
from typing import Any, Protocol

import numpy as np
import shapely

from ..core.sensor import RangeSensor
from .world import WatchWorld

__all__ = ["WatchRenderer", "WatchView", "watch_region"]


class WatchView(Protocol):
    """What :meth:`WatchRenderer.render` reads of the env's state (a
    :class:`~sensorplan_gym.multiagent.env.WatchParallelEnv` is one): the renderer sits below
    the env and never imports it.  Poses are ``(x, y, heading)`` in the world frame (radians),
    ``scans[i][0]`` watcher ``i``'s beam ranges, ``_a_poly`` A's outline now ((K, 2) array)."""

    world: WatchWorld
    sensor: RangeSensor
    robot_radius: float
    max_steps: int
    t: int
    traj: Any
    trail: list
    poses: list[tuple[float, float, float]]
    scans: list
    sees: list[bool]
    declared: list[str | None]
    _a_poly: np.ndarray

    @property
    def a_position(self) -> np.ndarray: ...


_COLORS = ["#ff7f0e", "#9467bd", "#17becf", "#e377c2", "#8c564b", "#bcbd22"]


def watch_region(world, which: str = "both") -> shapely.Geometry:
    """Placements that see A wherever it is in G (``which="G"``), in H (``"H"``) or in both
    (``"both"``), under the world's model (orientation 0; the partial model uses the
    conservative swept region).  Cached on the world."""
    cache = world.__dict__.setdefault("_regions", {})
    if which in cache:
        return cache[which]
    from geometry import complete_region, partial_region

    if which == "both":
        r = shapely.intersection(watch_region(world, "G"), watch_region(world, "H"))
    else:
        target = "goal" if which == "G" else "failure"
        if world.model == "complete":
            r = complete_region(world.scene, target_in=target, theta=0.0)
        else:
            r = partial_region(world.scene, target_in=target, theta=0.0, conservative=True)
    cache[which] = r
    return r


def _path(geom):
    from matplotlib.path import Path

    verts, codes = [], []
    for poly in shapely.get_parts(geom):
        if poly.is_empty or poly.geom_type != "Polygon":
            continue
        for ring in [poly.exterior, *poly.interiors]:
            c = np.asarray(ring.coords)
            verts.append(c)
            codes.append([Path.MOVETO] + [Path.LINETO] * (len(c) - 2) + [Path.CLOSEPOLY])
    if not verts:
        return None
    return Path(np.concatenate(verts), np.concatenate(codes))


class WatchRenderer:
    """Draws ``width x height`` RGB frames (uint8 arrays ``(height, width, 3)``) of a watch
    env's state (:class:`WatchView`)."""

    def __init__(self, width: int = 480, height: int = 480) -> None:
        self.width, self.height = int(width), int(height)
        self._fig = None

    def _figure(self):
        if self._fig is None:
            from matplotlib.backends.backend_agg import FigureCanvasAgg
            from matplotlib.figure import Figure

            fig = Figure(figsize=(self.width / 100, self.height / 100), dpi=100)
            FigureCanvasAgg(fig)
            self._fig = fig
        return self._fig

    def render(self, env: WatchView) -> np.ndarray:
        from matplotlib.patches import Circle, PathPatch, Polygon, Wedge

        w = env.world
        fig = self._figure()
        fig.clear()
        fig.set_facecolor("#9a9a9a")
        ax = fig.add_axes((0, 0, 1, 1))
        ax.set_axis_off()
        span = float(max(w.hi - w.lo))
        cx, cy = (w.lo + w.hi) / 2
        half = 0.53 * span
        ax.set_xlim(cx - half, cx + half)
        ax.set_ylim(cy - half, cy + half)
        ax.set_aspect("equal")

        scene = w.scene
        ax.add_patch(PathPatch(_path(scene.bounds_geom), fc="white", ec="black", lw=1.2))
        for o in scene.obstacle_geoms:
            ax.add_patch(PathPatch(_path(o), fc="#555555", ec="black", lw=0.8))
        reg = _path(watch_region(w, "both"))
        if reg is not None:
            ax.add_patch(PathPatch(reg, fc="#b8e6b8", ec="none", alpha=0.7))
        for g, col, lab in ((w.goal_geom, "#1f77b4", "G"), (w.failure_geom, "#d62728", "H")):
            if g.geom_type == "Point":
                ax.plot([g.x], [g.y], "o", color=col, ms=6)
                x, y = g.x, g.y
            else:
                ax.add_patch(PathPatch(_path(g), fc=col, ec=col, alpha=0.5))
                c = g.centroid
                x, y = c.x, c.y
            ax.text(x, y, lab, color=col, fontsize=11, fontweight="bold", ha="center", va="center")

        if env.traj is not None:
            trail = np.asarray(env.trail)
            ax.plot(trail[:, 0], trail[:, 1], "-", color="#2ca02c", lw=1.0, alpha=0.8)
            seen = any(env.sees)
            ax.add_patch(
                Polygon(
                    env._a_poly,
                    closed=True,
                    fc="#2ca02c" if seen else "#aaaaaa",
                    ec="black",
                    lw=0.8,
                )
            )
            a = env.a_position
            ax.text(a[0], a[1], "A", fontsize=8, ha="center", va="center")

        r_dot = max(env.robot_radius, 0.012 * span)
        for i, pose in enumerate(env.poses):
            col = _COLORS[i % len(_COLORS)]
            x, y, psi = pose
            if env.scans:
                dist = env.scans[i][0]
                ang = env.sensor.beam_angles(psi)
                for d, t in zip(dist, ang, strict=True):
                    ax.plot(
                        [x, x + d * math.cos(t)],
                        [y, y + d * math.sin(t)],
                        "-",
                        color=col,
                        lw=0.4,
                        alpha=0.6,
                    )
            if not w.full_fov:
                r = min(w.reach, span)
                ax.add_patch(
                    Wedge(
                        (x, y),
                        r,
                        math.degrees(psi - w.fov / 2),
                        math.degrees(psi + w.fov / 2),
                        fc=col,
                        alpha=0.08,
                        ec=col,
                        lw=0.5,
                    )
                )
            ax.add_patch(Circle((x, y), r_dot, fc=col, ec="black", lw=0.8))
            ax.plot(
                [x, x + 2.2 * r_dot * math.cos(psi)],
                [y, y + 2.2 * r_dot * math.sin(psi)],
                "-",
                color="black",
                lw=1.2,
            )
            label = f"{i}" + (f":{env.declared[i]}" if env.declared and env.declared[i] else "")
            ax.text(x + 1.5 * r_dot, y + 1.5 * r_dot, label, fontsize=8, color="black")
        status = f"watch_v0 {scene.name}  t={env.t}/{env.max_steps}"
        if env.sees:
            status += "  sees: " + "".join("1" if s else "0" for s in env.sees)
        ax.text(cx - half * 0.97, cy + half * 0.93, status, fontsize=8, color="black")
        fig.canvas.draw()
        buf = np.asarray(fig.canvas.buffer_rgba())
        return np.ascontiguousarray(buf[:, :, :3])

    def close(self) -> None:
        self._fig = None

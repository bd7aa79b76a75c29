"""RGB frames with matplotlib's Agg canvas (no pyplot, no window, thread-safe).

A frame shows: the walls (outside of the room in grey), obstacles (dark grey),
the recognizable region (shaded green), G (blue) and H (red), the target when
the env reveals it to the renderer (Recognize: dashed outline; the picture is
for people, never part of the observation), the robot or sensor (orange disc
with a heading tick), its field-of-view wedge and its beams (thin lines to the
hit points).

``human`` mode shows the same frame with pyplot; under a non-interactive
backend (Agg, e.g. on CI or without a display) it only draws, it opens no window and
does not fail, and it says so once with a ``UserWarning`` naming the backend.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["Renderer", "HumanViewer", "legend_handles"]


def _path(geom):
    from matplotlib.path import Path

    verts, codes = [], []
    for poly in getattr(geom, "geoms", [geom]):
        if poly.is_empty or poly.geom_type != "Polygon":
            continue
        for ring in [poly.exterior, *poly.interiors]:
            c = np.asarray(ring.coords)
            verts.append(c)
            codes.append([Path.MOVETO] + [Path.LINETO] * (len(c) - 2) + [Path.CLOSEPOLY])
    if not verts:
        return None
    return Path(np.concatenate(verts), np.concatenate(codes))


def legend_handles() -> list:
    """Matplotlib legend proxies for what :class:`Renderer` draws, in the same colours
    (frames carry no legend of their own: put these next to a frame, e.g.
    ``fig.legend(handles=legend_handles())``)."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    return [
        Patch(fc="white", ec="black", lw=1.5, label="room (walls)"),
        Patch(fc="#9a9a9a", ec="none", label="outside the room"),
        Patch(fc="#454545", ec="black", lw=0.8, label="obstacles"),
        Patch(fc="#7fd37f", ec="#2e8b2e", lw=0.6, alpha=0.55, label="recognizable region"),
        Patch(fc="#1f5fd1", ec="#1f5fd1", alpha=0.45, label="G: goal region"),
        Patch(fc="#d12f2f", ec="#d12f2f", alpha=0.45, label="H: failure region"),
        Patch(fc="none", ec="#7a2fbf", lw=1.4, ls="--", label="target (hidden from the agent)"),
        Line2D(
            [],
            [],
            marker="o",
            ls="none",
            ms=9,
            mfc="#ff8c1a",
            mec="black",
            label="robot, not recognizing",
        ),
        Line2D(
            [],
            [],
            marker="o",
            ls="none",
            ms=9,
            mfc="#2e8b2e",
            mec="black",
            label="robot, recognizing",
        ),
        Patch(fc="#ffcc66", ec="none", alpha=0.3, label="field of view"),
        Line2D([], [], color="#e08a00", lw=0.8, label="range beams"),
        Line2D([], [], marker=".", ls="none", ms=5, color="#b35f00", label="beam hits"),
    ]


class Renderer:
    """Draws frames of ``width x height`` pixels."""

    def __init__(self, width: int = 480, height: int = 480) -> None:
        self.width, self.height = int(width), int(height)
        self._fig = None

    def __getstate__(self) -> dict:
        return {"width": self.width, "height": self.height, "_fig": None}

    def _figure(self):
        if self._fig is None:
            from matplotlib.backends.backend_agg import FigureCanvasAgg
            from matplotlib.figure import Figure

            dpi = 100
            fig = Figure(figsize=(self.width / dpi, self.height / dpi), dpi=dpi)
            FigureCanvasAgg(fig)
            self._fig = fig
        return self._fig

    def render(self, world, state: dict[str, Any]) -> np.ndarray:
        from matplotlib.patches import Circle, PathPatch, Wedge

        fig = self._figure()
        fig.clear()
        ax = fig.add_axes((0, 0, 1, 1))
        ax.set_axis_off()
        ax.set_facecolor("#9a9a9a")
        fig.set_facecolor("#9a9a9a")
        span = float(max(world.hi - world.lo))
        pad = 0.03 * span
        cx, cy = (world.lo + world.hi) / 2
        half = span / 2 + pad
        ax.set_xlim(cx - half, cx + half)
        ax.set_ylim(cy - half, cy + half)
        ax.set_aspect("equal")

        scene = world.scene
        from shapely.geometry import Polygon

        room = PathPatch(_path(Polygon(scene.bounds)), fc="white", ec="black", lw=1.5, zorder=0)
        ax.add_patch(room)
        region_path = _path(world.region)
        if region_path is not None:
            ax.add_patch(
                PathPatch(region_path, fc="#7fd37f", ec="#2e8b2e", lw=0.6, alpha=0.55, zorder=1)
            )
        for o in scene.obstacles:
            ax.add_patch(PathPatch(_path(Polygon(o)), fc="#454545", ec="black", lw=0.8, zorder=2))
        for g, color, label in (
            (world.goal_geom, "#1f5fd1", "G"),
            (world.failure_geom, "#d12f2f", "H"),
        ):
            if g.geom_type == "Point":
                ax.plot([g.x], [g.y], marker="o", ms=6, color=color, zorder=3)
                tx, ty = g.x, g.y
            else:
                ax.add_patch(PathPatch(_path(g), fc=color, ec=color, alpha=0.45, lw=1, zorder=3))
                c = g.centroid
                tx, ty = c.x, c.y
            ax.text(
                tx,
                ty + 0.03 * span,
                label,
                color=color,
                ha="center",
                va="bottom",
                fontsize=11,
                fontweight="bold",
            )

        tgt = state.get("target")
        if tgt is not None:
            ax.add_patch(
                PathPatch(_path(Polygon(tgt)), fc="none", ec="#7a2fbf", lw=1.4, ls="--", zorder=3)
            )

        pose = state.get("pose")
        if pose is not None:
            x, y, psi = pose
            sensor_pose = state.get("sensor_pose") or pose
            sx, sy, spsi = sensor_pose
            fov = world.fov
            R = world.reach
            if fov < 2 * math.pi - 1e-9:
                wedge = Wedge(
                    (sx, sy),
                    R,
                    math.degrees(spsi - fov / 2),
                    math.degrees(spsi + fov / 2),
                    fc="#ffcc66",
                    ec="none",
                    alpha=0.3,
                    zorder=0.5,
                )
                ax.add_patch(wedge)
                wedge.set_clip_path(room)
            scan = state.get("scan")
            if scan is not None:
                dist, _, _, ang = scan
                ex = sx + dist * np.cos(ang)
                ey = sy + dist * np.sin(ang)
                segs = np.stack(
                    [
                        np.stack([np.full_like(ex, sx), ex], 1),
                        np.stack([np.full_like(ey, sy), ey], 1),
                    ],
                    axis=2,
                )
                from matplotlib.collections import LineCollection

                ax.add_collection(
                    LineCollection(segs, colors="#e08a00", linewidths=0.6, alpha=0.8, zorder=4)
                )
                hit = scan[2]
                ax.plot(ex[hit], ey[hit], ".", ms=2.5, color="#b35f00", zorder=4)
            rr = max(world.robot_radius, 0.012 * span)
            rec = state.get("recognizing", False)
            ax.add_patch(
                Circle((x, y), rr, fc="#2e8b2e" if rec else "#ff8c1a", ec="black", lw=1, zorder=5)
            )
            ax.plot(
                [x, x + 1.8 * rr * math.cos(psi)],
                [y, y + 1.8 * rr * math.sin(psi)],
                color="black",
                lw=1.5,
                zorder=6,
            )
        title = state.get("title")
        if title:
            ax.text(
                cx - half + 0.02 * span,
                cy + half - 0.02 * span,
                title,
                va="top",
                fontsize=9,
                family="monospace",
                bbox=dict(fc="white", ec="none", alpha=0.7),
            )
        fig.canvas.draw()
        buf = np.asarray(fig.canvas.buffer_rgba())
        return np.ascontiguousarray(buf[:, :, :3])

    def close(self) -> None:
        self._fig = None


class HumanViewer:
    """Shows frames with pyplot; a no-op display under a non-interactive backend (warned
    once per viewer)."""

    def __init__(self) -> None:
        self._plt = None
        self._im = None
        self._warned = False

    def __getstate__(self) -> dict:
        return {"_plt": None, "_im": None, "_warned": False}

    def show(self, frame: np.ndarray, fps: float) -> None:
        import matplotlib

        if self._plt is None:
            import matplotlib.pyplot as plt

            self._plt = plt
            fig = plt.figure("sensorplan")
            ax = fig.add_axes((0, 0, 1, 1))
            ax.set_axis_off()
            self._im = ax.imshow(frame)
        else:
            self._im.set_data(frame)
        backend = matplotlib.get_backend().lower()
        if "agg" in backend or backend in ("pdf", "ps", "svg", "cairo", "template"):
            self._im.figure.canvas.draw()  # non-interactive: draw only, no window
            if not getattr(self, "_warned", False):
                import warnings

                warnings.warn(
                    f"render_mode='human': matplotlib's backend {backend!r} cannot open a "
                    "window (no display, or MPLBACKEND=Agg), so nothing is shown; use "
                    "render_mode='rgb_array' to get the frames, or an interactive backend "
                    "(e.g. MPLBACKEND=TkAgg) on a machine with a display",
                    UserWarning,
                    stacklevel=3,
                )
                self._warned = True
            return
        self._plt.pause(1.0 / fps)

    def close(self) -> None:
        if self._plt is not None:
            self._plt.close("sensorplan")
        self._plt = None
        self._im = None

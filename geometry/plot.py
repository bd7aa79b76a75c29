"""Matplotlib drawing of scenes and regions (world coordinates, equal aspect).

Kept apart from the algorithms: importing :mod:`geometry` does not import
matplotlib; this module does, lazily through the ``ax`` it is given.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
import shapely

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes

    from .scene import Scene

__all__ = ["draw_pose", "draw_region", "draw_scene"]


def draw_region(
    ax: Axes,
    region: shapely.Geometry,
    *,
    color: str = "#7fc97f",
    alpha: float = 0.55,
    label: str | None = None,
    **kw: Any,
) -> None:
    """Fill a (Multi)Polygon, holes included."""
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path

    first = True
    for poly in shapely.get_parts(region):
        if poly.is_empty or poly.geom_type != "Polygon":
            continue
        verts, codes = [], []
        for ring in [poly.exterior, *poly.interiors]:
            c = np.asarray(ring.coords)[:, :2]
            verts.append(c)
            codes += [Path.MOVETO] + [Path.LINETO] * (len(c) - 2) + [Path.CLOSEPOLY]
        patch = PathPatch(
            Path(np.vstack(verts), codes),
            facecolor=color,
            edgecolor="none",
            alpha=alpha,
            label=label if first else None,
            **kw,
        )
        ax.add_patch(patch)
        first = False


def draw_scene(ax: Axes, scene: Scene, *, show_target: bool = True) -> None:
    """Walls, obstacles (dark), G (blue) and H (red); the target drawn at G and H."""
    b = np.vstack([scene.bounds, scene.bounds[:1]])
    ax.plot(b[:, 0], b[:, 1], color="black", lw=2)
    draw_region(ax, scene.obstacle_union, color="#404040", alpha=1.0, label="obstacles")
    for geom, color, name in (
        (scene.goal_geom, "#1f77b4", "G"),
        (scene.failure_geom, "#d62728", "H"),
    ):
        if geom.geom_type == "Point":
            ax.plot(geom.x, geom.y, "o", color=color, ms=6)
            anchor = (geom.x, geom.y)
        else:
            draw_region(ax, geom, color=color, alpha=0.35)
            anchor = tuple(np.asarray(geom.centroid.coords[0]))
        ax.annotate(
            name,
            anchor,
            color=color,
            fontsize=12,
            fontweight="bold",
            xytext=(4, 4),
            textcoords="offset points",
        )
        if show_target:
            a = scene.target_at(anchor[0], anchor[1], 0.0)
            c = np.asarray(a.exterior.coords)
            ax.plot(c[:, 0], c[:, 1], color=color, lw=1, ls="--")
    lo, hi = scene.bounds.min(axis=0), scene.bounds.max(axis=0)
    pad = 0.03 * (hi - lo).max()
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal")


def draw_pose(
    ax: Axes,
    x: float,
    y: float,
    psi: float,
    *,
    fov: float | None = None,
    length: float = 1.0,
    color: str = "black",
    label: str | None = None,
) -> None:
    """A sensor pose: a dot, an aim arrow of ``length`` and the field-of-view wedge."""
    ax.plot(x, y, "o", color=color, ms=7, label=label)
    ax.arrow(
        x,
        y,
        length * np.cos(psi),
        length * np.sin(psi),
        color=color,
        width=0.02 * length,
        length_includes_head=True,
    )
    if fov is not None and fov < 2 * np.pi - 1e-9:
        for s in (-1, 1):
            a = psi + s * fov / 2
            ax.plot(
                [x, x + 1.5 * length * np.cos(a)],
                [y, y + 1.5 * length * np.sin(a)],
                color=color,
                lw=0.8,
                ls=":",
            )

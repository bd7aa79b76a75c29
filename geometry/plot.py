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
    edgecolor: str = "none",
    linewidth: float = 0.0,
    hatch: str | None = None,
    **kw: Any,
) -> None:
    """Fill a (Multi)Polygon, holes included.

    ``edgecolor``/``linewidth`` outline every part (default: no outline); ``hatch`` is a
    matplotlib hatch pattern drawn in ``edgecolor``.  The legend entry (``label``) is
    attached to the first part only, so an empty region adds no entry.
    """
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
            edgecolor=edgecolor,
            linewidth=linewidth,
            hatch=hatch,
            alpha=alpha,
            label=label if first else None,
            **kw,
        )
        ax.add_patch(patch)
        first = False


def draw_scene(
    ax: Axes,
    scene: Scene,
    *,
    show_target: bool = True,
    unit: str | None = "m",
    legend_labels: bool = True,
) -> None:
    """Walls, obstacles (dark), G (blue) and H (red); the target drawn at G and H.

    ``unit`` names the scene unit on the axis labels (``"x (m)"``; ``None``: plain ``x``);
    the bundled scenes are in metres.  With ``legend_labels`` the obstacles, G, H and the
    target outline carry legend labels (call ``ax.legend()`` afterwards).
    """
    b = np.vstack([scene.bounds, scene.bounds[:1]])
    ax.plot(b[:, 0], b[:, 1], color="black", lw=2, label="walls" if legend_labels else None)
    draw_region(
        ax,
        scene.obstacle_union,
        color="#404040",
        alpha=1.0,
        label="obstacles" if legend_labels else None,
    )
    target_labelled = False
    for geom, color, name, what in (
        (scene.goal_geom, "#1f77b4", "G", "goal region"),
        (scene.failure_geom, "#d62728", "H", "failure region"),
    ):
        label = f"{name}: {what}" if legend_labels else None
        if geom.geom_type == "Point":
            ax.plot(geom.x, geom.y, "o", color=color, ms=6, label=label)
            anchor = (geom.x, geom.y)
        else:
            draw_region(ax, geom, color=color, alpha=0.35, label=label)
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
            tl = None
            if legend_labels and not target_labelled:
                tl = "target A at the centre of G / of H"
                target_labelled = True
            ax.plot(c[:, 0], c[:, 1], color=color, lw=1, ls="--", label=tl)
    lo, hi = scene.bounds.min(axis=0), scene.bounds.max(axis=0)
    pad = 0.03 * (hi - lo).max()
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal")
    ax.set_xlabel(f"x ({unit})" if unit else "x")
    ax.set_ylabel(f"y ({unit})" if unit else "y")


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
    aim_color: str | None = None,
    aim_label: str | None = None,
) -> None:
    """A sensor pose: a dot, an aim arrow of ``length`` and the field-of-view wedge.

    ``psi`` and ``fov`` are radians, ``length`` is in scene units.  The arrow is drawn in
    ``aim_color`` (default ``color``); with ``aim_label`` it becomes a legend entry and the
    text is also written next to the arrow head.
    """
    from matplotlib.lines import Line2D

    ac = color if aim_color is None else aim_color
    ax.plot(x, y, "o", color=color, ms=7, label=label, zorder=6)
    dx, dy = length * np.cos(psi), length * np.sin(psi)
    ax.annotate(
        "",
        xy=(x + dx, y + dy),
        xytext=(x, y),
        arrowprops=dict(arrowstyle="-|>", color=ac, lw=2.2, mutation_scale=16),
        zorder=7,
    )
    if aim_label is not None:
        ax.annotate(
            aim_label,
            (x + dx, y + dy),
            xytext=(6 * np.cos(psi), 6 * np.sin(psi)),
            textcoords="offset points",
            ha="left" if np.cos(psi) >= 0 else "right",
            va="bottom" if np.sin(psi) >= 0 else "top",
            color=ac,
            fontsize=9,
            fontweight="bold",
            bbox=dict(fc="white", ec="none", alpha=0.75, pad=1),
            zorder=8,
        )
        # a legend proxy in the arrow's colour (annotations have no legend entry)
        ax.add_line(Line2D([], [], color=ac, lw=2.2, marker=">", markevery=[-1], label=aim_label))
    if fov is not None and fov < 2 * np.pi - 1e-9:
        for s in (-1, 1):
            a = psi + s * fov / 2
            ax.plot(
                [x, x + 1.5 * length * np.cos(a)],
                [y, y + 1.5 * length * np.sin(a)],
                color=ac,
                lw=0.8,
                ls=":",
            )

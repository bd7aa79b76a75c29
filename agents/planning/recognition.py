"""Recognising "target in G" versus "target in H" from range readings (paper 6.4, on range data).

The paper located LILY with Rucklidge's translation-only matcher: the model's edge points are
translated over the image and a match is declared where the *fractional* (partial) Hausdorff
distance -- the ``frac``-quantile of the distances from points to the nearest model point -- is
below a threshold.  Here the "image" is a range scan and the "edges" are beam end points:

1. the readings that differ from the known static map (walls and obstacles) are *target
   points* (:func:`target_points`);
2. for each hypothesis X in {G, H} the target outline ``boundary(A_theta) + g`` is translated
   over every ``g`` in X (and, optionally, over several orientations ``theta``), and the fraction
   ``frac`` of the target points closest to that outline gives the directed partial Hausdorff
   distance ``h_frac(points, outline)``; ``d_X`` is its minimum over the poses in X
   (:func:`match_distance`).  Matching one translated outline rather than the whole swept area
   ``A_theta (+) X`` means an object of another shape standing in G (a person in the doorway)
   does not count as the target;
3. :func:`classify` returns ``"G"`` or ``"H"`` for the clearly smaller distance when it is below
   ``tau``, and ``"not_seen"`` -- move or re-aim, do not guess -- when there are too few target
   points, when neither hypothesis fits, or when both fit about equally well.

Frames and units: world frame, scene units; orientations in radians.  Pure numpy/shapely.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import shapely
from shapely.geometry.base import BaseGeometry

if TYPE_CHECKING:  # pragma: no cover
    from geometry import Scene

__all__ = [
    "Decision",
    "classify",
    "fractional_distance",
    "match_distance",
    "target_points",
]

#: Upper bound on the number of translations tried per orientation in the coarse search.
MAX_POSES = 2048
#: Work per vectorised chunk (poses x points x outline segments).
_CHUNK = 2_000_000


@dataclass(frozen=True)
class Decision:
    """Result of :func:`classify`.

    label : ``"G"``, ``"H"`` or ``"not_seen"``.
    d_G, d_H : fractional Hausdorff distances (scene units) of the target points to the best
        matching target outline with its reference point in G, resp. in H (``inf`` when not
        computed because there were too few target points).
    pose_G, pose_H : the best matching target configurations ``(x, y, theta)`` (or None).
    n_points : number of target points (readings that differ from the static map).
    tau : acceptance threshold used (scene units); frac : the fraction used.
    reason : a sentence explaining the decision.
    """

    label: str
    d_G: float
    d_H: float
    pose_G: tuple[float, float, float] | None
    pose_H: tuple[float, float, float] | None
    n_points: int
    tau: float
    frac: float
    reason: str

    @property
    def seen(self) -> bool:
        """True when the target was recognised (label G or H)."""
        return self.label in ("G", "H")

    @property
    def pose(self) -> tuple[float, float, float] | None:
        """The matched target configuration for the decided label, else None."""
        return {"G": self.pose_G, "H": self.pose_H}.get(self.label)


# ---------------------------------------------------------------------------------------------
# target points
# ---------------------------------------------------------------------------------------------


def target_points(readings_xy: Any, static: Any = None, *, tol: float = 1e-6) -> np.ndarray:
    """The readings that differ from the known static map.

    Parameters
    ----------
    readings_xy : (n, 2) beam end points, world frame.  Rows with a non-finite coordinate (no
        return) are never target points.
    static : what the static map predicts, one of
        * ``None``: every finite reading is a target point (already filtered by the caller);
        * a boolean array (n,): True where the beam hit something other than the static map;
        * an (n, 2) float array: the expected end points of the same beams on the static map
          (walls and obstacles only); a reading is a target point when it is farther than
          ``tol`` (scene units) from its expected end point.

    Returns
    -------
    (m, 2) float array of target points.
    """
    pts = np.asarray(readings_xy, dtype=float).reshape(-1, 2)
    finite = np.all(np.isfinite(pts), axis=1)
    if static is None:
        mask = finite
    else:
        st = np.asarray(static)
        if st.dtype == bool:
            if st.shape != (len(pts),):
                raise ValueError(f"static mask must have shape ({len(pts)},), got {st.shape}")
            mask = finite & st
        else:
            st = st.astype(float).reshape(-1, 2)
            if len(st) != len(pts):
                raise ValueError(
                    f"static end points must have the readings' shape ({len(pts)}, 2), "
                    f"got {np.asarray(static).shape}"
                )
            with np.errstate(invalid="ignore"):
                gap = np.hypot(*(pts - st).T)
            # an expected hit with no return (inf) differs from any finite reading
            mask = finite & ~(gap <= tol)
    return pts[mask]


# ---------------------------------------------------------------------------------------------
# fractional Hausdorff distances
# ---------------------------------------------------------------------------------------------


def _rank(n: int, frac: float) -> int:
    """Rank (1-based) of the fractional distance: ceil(frac * n), at least 1."""
    return max(1, min(n, math.ceil(frac * n - 1e-12)))


def fractional_distance(points: Any, geom: BaseGeometry, frac: float = 0.8) -> float:
    """Directed partial Hausdorff distance from ``points`` to ``geom``.

    The ``ceil(frac * n)``-th smallest of the distances (scene units) from the n points to
    ``geom`` (shapely distance: 0 inside a polygon); ``frac = 1`` is the ordinary directed
    Hausdorff distance.  ``inf`` for no points.
    """
    _check_frac(frac)
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    if len(p) == 0:
        return math.inf
    d = np.asarray(shapely.distance(shapely.points(p), geom), dtype=float)
    k = _rank(len(d), frac)
    return float(np.partition(d, k - 1)[k - 1])


def _check_frac(frac: float) -> None:
    if not (0.0 < float(frac) <= 1.0):
        raise ValueError(f"frac must be in (0, 1], got {frac!r}")


def _outline_segments(target: np.ndarray, theta: float) -> tuple[np.ndarray, np.ndarray]:
    """Edges (start, direction) of the target outline rotated by ``theta`` about (0, 0)."""
    c, s = math.cos(theta), math.sin(theta)
    t = np.asarray(target, dtype=float).reshape(-1, 2)
    r = np.column_stack([c * t[:, 0] - s * t[:, 1], s * t[:, 0] + c * t[:, 1]])
    a = r
    b = np.roll(r, -1, axis=0)
    return a, b - a


def _frac_dist_poses(
    pts: np.ndarray, a: np.ndarray, e: np.ndarray, poses: np.ndarray, k: int
) -> np.ndarray:
    """For each translation g in ``poses`` (q, 2): k-th smallest distance of pts to outline+g."""
    ee = np.maximum(np.einsum("ij,ij->i", e, e), 1e-300)
    out = np.empty(len(poses))
    m, s = len(pts), len(a)
    step = max(1, _CHUNK // max(1, m * s))
    for i0 in range(0, len(poses), step):
        g = poses[i0 : i0 + step]
        q = pts[None, :, None, :] - g[:, None, None, :] - a[None, None, :, :]  # (c, m, s, 2)
        t = np.clip(np.einsum("cmsk,sk->cms", q, e) / ee, 0.0, 1.0)
        r = q - t[..., None] * e
        d = np.sqrt(np.einsum("cmsk,cmsk->cms", r, r)).min(axis=2)  # (c, m)
        out[i0 : i0 + step] = np.partition(d, k - 1, axis=1)[:, k - 1]
    return out


def _translations(region: BaseGeometry, h: float) -> np.ndarray:
    """Sample translations of ``region``: a square grid of spacing ``h`` inside it, its
    vertices and its boundary sampled at spacing ``h`` (every point of the region is within
    about ``h`` of a sample)."""
    if region.geom_type == "Point":
        return np.array([[region.x, region.y]])
    x0, y0, x1, y1 = region.bounds
    xs = np.arange(x0 + h / 2, x1, h)
    ys = np.arange(y0 + h / 2, y1, h)
    gx, gy = np.meshgrid(xs, ys)
    grid = np.column_stack([gx.ravel(), gy.ravel()])
    if len(grid):
        grid = grid[shapely.covers(region, shapely.points(grid))]
    bnd = shapely.get_coordinates(shapely.segmentize(region.boundary, h))
    return np.unique(np.vstack([grid.reshape(-1, 2), bnd]), axis=0)


def match_distance(
    points: Any,
    target: Any,
    region: BaseGeometry,
    *,
    theta: float | Sequence[float] = 0.0,
    frac: float = 0.8,
    resolution: float | None = None,
) -> tuple[float, tuple[float, float, float] | None]:
    """Best fit of the translated target outline to ``points`` over poses in ``region``.

    ``min over g in region, theta in thetas of h_frac(points, boundary(A_theta) + g)``: the
    paper's translation-only fractional Hausdorff matcher (6.4) restricted to the hypothesis'
    region.

    Parameters
    ----------
    points : (m, 2) target points, world frame.
    target : the target polygon A in its own frame ((k, 2) vertices or a shapely Polygon),
        reference point at (0, 0).
    region : where the reference point may be (shapely Point or Polygon, world frame).
    theta : orientation(s) of the target, radians (a number or a sequence to search).
    frac : fraction of the points that must fit, in (0, 1].
    resolution : translation search step (scene units).  The search is a grid of this spacing
        over the region (coarse; at most ``MAX_POSES`` poses) refined 4x around the best
        poses, so the returned distance exceeds the true minimum by at most about
        ``resolution`` (the fractional distance is 1-Lipschitz in the translation).  Default:
        1/20 of the target's radius.

    Returns
    -------
    ``(distance, (x, y, theta))`` of the best pose; ``(inf, None)`` when there are no points.
    """
    _check_frac(frac)
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    if isinstance(target, BaseGeometry):
        tgt = np.asarray(shapely.orient_polygons(target, exterior_cw=False).exterior.coords)[:-1]
    else:
        tgt = np.asarray(target, dtype=float).reshape(-1, 2)
    if len(pts) == 0:
        return math.inf, None
    radius = float(np.hypot(*tgt.T).max())
    h = float(resolution) if resolution is not None else radius / 20.0
    if not (h > 0 and math.isfinite(h)):
        raise ValueError(f"resolution must be positive, got {resolution!r}")
    k = _rank(len(pts), frac)
    thetas = [float(theta)] if np.ndim(theta) == 0 else [float(t) for t in theta]
    if region.geom_type != "Point":
        # coarse step: keep the number of poses bounded
        while region.area / (h * h) > MAX_POSES:
            h *= 1.5
    best, best_pose = math.inf, None
    for th in thetas:
        a, e = _outline_segments(tgt, th)
        poses = _translations(region, h)
        d = _frac_dist_poses(pts, a, e, poses, k)
        if region.geom_type != "Point" and len(poses) > 1:
            # refine around the best few coarse poses (grid of spacing h/4 within +-h)
            top = poses[np.argsort(d)[:4]]
            off = np.arange(-4, 5) * (h / 4)
            ox, oy = np.meshgrid(off, off)
            grid = np.column_stack([ox.ravel(), oy.ravel()])
            fine = (top[:, None, :] + grid[None]).reshape(-1, 2)
            fine = fine[shapely.covers(region, shapely.points(fine))]
            if len(fine):
                df = _frac_dist_poses(pts, a, e, fine, k)
                poses = np.vstack([poses, fine])
                d = np.concatenate([d, df])
        i = int(np.argmin(d))
        if d[i] < best:
            best = float(d[i])
            best_pose = (float(poses[i, 0]), float(poses[i, 1]), th)
    return best, best_pose


# ---------------------------------------------------------------------------------------------
# decision
# ---------------------------------------------------------------------------------------------


def classify(
    readings_xy: Any,
    static: Any = None,
    scene: Scene | None = None,
    *,
    target: Any = None,
    goal: BaseGeometry | None = None,
    failure: BaseGeometry | None = None,
    theta: float | Sequence[float] | None = 0.0,
    frac: float = 0.8,
    tau: float | None = None,
    separation: float | None = None,
    min_points: int = 3,
    static_tol: float | None = None,
    resolution: float | None = None,
) -> Decision:
    """Decide whether the target is in G, in H, or not (reliably) seen, from range readings.

    Parameters
    ----------
    readings_xy : (n, 2) beam end points, world frame (non-finite rows: no return).
    static : which readings belong to the static map -- see :func:`target_points` (None, a
        boolean "differs from the static map" mask, or the (n, 2) expected static end points).
    scene : supplies the defaults ``target = scene.target``, ``goal = scene.goal_geom``,
        ``failure = scene.failure_geom``; not needed when all three are given.
    target : target polygon in its own frame ((k, 2) array or Polygon), reference point (0, 0).
    goal, failure : G and H (shapely Point or Polygon, world frame): where the reference point
        is under each hypothesis.
    theta : target orientation(s) in radians; a sequence is searched; ``None`` searches the
        full circle at a step fine enough for ``tau``.
    frac : fraction of the target points that must fit (Rucklidge's partial distance); below 1
        a few outliers (noise, a passer-by) cannot flip the decision.
    tau : acceptance threshold (scene units).  Default: 0.1 times the target's radius.  Set it
        above the range noise (about 3 sigma).
    separation : the other hypothesis' distance must exceed the winner's by at least this much
        (scene units).  Default: ``tau``.
    min_points : fewer target points than this gives ``"not_seen"``.
    static_tol : tolerance of the end-point comparison with ``static`` (default ``tau / 2``).
    resolution : translation search step, see :func:`match_distance` (default ``tau / 4``).

    Returns
    -------
    A :class:`Decision` (label ``"G"``, ``"H"`` or ``"not_seen"``, both distances, best poses,
    the number of target points and a reason).
    """
    _check_frac(frac)
    if target is None or goal is None or failure is None:
        if scene is None:
            raise ValueError("classify: give a scene, or all of target=, goal= and failure=")
        target = scene.target if target is None else target
        goal = scene.goal_geom if goal is None else goal
        failure = scene.failure_geom if failure is None else failure
    tgt = (
        np.asarray(shapely.orient_polygons(target, exterior_cw=False).exterior.coords)[:-1]
        if isinstance(target, BaseGeometry)
        else np.asarray(target, dtype=float).reshape(-1, 2)
    )
    radius = float(np.hypot(*tgt.T).max())
    tau = 0.1 * radius if tau is None else float(tau)
    if not (tau > 0 and math.isfinite(tau)):
        raise ValueError(f"tau must be positive and finite, got {tau!r}")
    sep = tau if separation is None else float(separation)
    stol = tau / 2 if static_tol is None else float(static_tol)
    res = tau / 4 if resolution is None else float(resolution)
    if theta is None:
        n_th = max(8, math.ceil(2 * math.pi * radius / res))
        thetas: float | list[float] = list(np.linspace(0.0, 2 * math.pi, n_th, endpoint=False))
    else:
        thetas = theta

    pts = target_points(readings_xy, static, tol=stol)
    n = len(pts)
    if n < min_points:
        return Decision(
            "not_seen",
            math.inf,
            math.inf,
            None,
            None,
            n,
            tau,
            frac,
            f"only {n} reading(s) differ from the static map (need {min_points}): "
            "the target is not in view; move or re-aim",
        )
    d_g, pose_g = match_distance(pts, tgt, goal, theta=thetas, frac=frac, resolution=res)
    d_h, pose_h = match_distance(pts, tgt, failure, theta=thetas, frac=frac, resolution=res)
    lo, hi = min(d_g, d_h), max(d_g, d_h)
    win = "G" if d_g <= d_h else "H"
    pct = f"{100 * frac:g}%"
    if lo > tau:
        label = "not_seen"
        reason = (
            f"{n} readings differ from the static map, but {pct} of them fit neither the target "
            f"in G (d_G={d_g:.3g}) nor in H (d_H={d_h:.3g}) within tau={tau:.3g}: something "
            "else is there, or the view is too poor; move or re-aim"
        )
    elif hi - lo < sep:
        label = "not_seen"
        reason = (
            f"ambiguous: the readings fit the target in G (d_G={d_g:.3g}) and in H "
            f"(d_H={d_h:.3g}) about equally (separation < {sep:.3g}); move or re-aim"
        )
    else:
        label = win
        reason = (
            f"{pct} of the {n} target points lie within {lo:.3g} of the target outline in "
            f"{win} (tau={tau:.3g}); the best fit in {'H' if win == 'G' else 'G'} is "
            f"{hi:.3g}"
        )
    return Decision(label, d_g, d_h, pose_g, pose_h, n, tau, frac, reason)

"""Shared helpers of the region algorithms: the target specification, convex
hulls and Minkowski sums, the cached visibility domain of a scene, and the
positional-uncertainty shrink of paper section 4."""

from __future__ import annotations

import math
import numbers
import time
import weakref
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import shapely
from shapely import affinity

from ._frame import to_world_point
from ._shapes import disc_sum, polygonal
from ._vis import Domain, domain_from_geometry

if TYPE_CHECKING:  # pragma: no cover
    from .scene import Scene

#: Polygonal arcs (disc buffers) use this many segments per quarter circle.
QUAD_SEGS = 16
#: Radius factor making a polygonal buffer contain the exact disc buffer.
OUTER = 1.0 / math.cos(math.pi / (4 * QUAD_SEGS))

_DOMAINS: weakref.WeakKeyDictionary[Scene, Domain] = weakref.WeakKeyDictionary()


def scene_domain(scene: Scene) -> Domain:
    """The free space of ``scene`` as a visibility domain (cached per scene)."""
    dom = _DOMAINS.get(scene)
    if dom is None:
        dom = domain_from_geometry(scene.free_space)
        _DOMAINS[scene] = dom
    return dom


def hull_points(geom: shapely.Geometry) -> np.ndarray:
    """Vertices of the convex hull of ``geom`` as an (n, 2) array, counter-clockwise."""
    hull = shapely.convex_hull(geom)
    if hull.geom_type == "Polygon":
        hull = shapely.orient_polygons(hull, exterior_cw=False)
        return np.asarray(hull.exterior.coords)[:-1, :2]
    return np.asarray(shapely.get_coordinates(hull))


def minkowski_sum(a: shapely.Geometry, b: shapely.Geometry) -> shapely.Geometry:
    """Exact Minkowski sum of two polygons (or a polygon and a point).

    Both are split into triangles (constrained Delaunay); the sum is the union of
    the convex hulls of the pairwise sums of triangle vertices.
    """
    if b.geom_type == "Point":
        return affinity.translate(a, b.x, b.y)
    if a.geom_type == "Point":
        return affinity.translate(b, a.x, a.y)
    ta = _triangles(a)
    tb = _triangles(b)
    sums = (ta[:, None, :, None, :] + tb[None, :, None, :, :]).reshape(len(ta) * len(tb), 9, 2)
    hulls = shapely.convex_hull(shapely.multipoints(sums))
    return shapely.union_all(hulls)


def _triangles(p: shapely.Geometry) -> np.ndarray:
    if shapely.equals(p, shapely.convex_hull(p)):
        c = np.asarray(p.exterior.coords)[:-1]
        return np.stack([np.repeat(c[:1], len(c) - 2, 0), c[1:-1], c[2:]], axis=1)
    tri = shapely.constrained_delaunay_triangles(p)
    return np.asarray([np.asarray(t.exterior.coords)[:3] for t in tri.geoms])


@dataclass(frozen=True)
class TargetSpec:
    """What must be seen: the (swept) target area and its convex hull.

    ``area`` is the set the target can occupy (sensor placements must avoid it);
    ``hull_pts`` the vertices of its convex hull, with ``radius`` > 0 when every
    hull vertex stands for a disc of that radius (rotating target); ``center`` a
    point inside the hull.  ``pose`` is set for a stationary target.
    """

    area: shapely.Geometry
    hull_pts: np.ndarray
    radius: float
    center: np.ndarray
    pose: tuple[float, float, float] | None
    label: str

    @property
    def hull(self) -> shapely.Geometry:
        h = shapely.convex_hull(shapely.multipoints(self.hull_pts))
        if self.radius > 0:
            h = disc_sum(h, self.radius)
        return h


def target_spec(
    scene: Scene,
    target_at: tuple[float, float, float] | None,
    target_in: str | shapely.Geometry | None,
    theta: float | None,
) -> TargetSpec:
    """Resolve the ``target_at`` / ``target_in`` / ``theta`` arguments.

    Raises ``ValueError`` for contradictory or malformed arguments and
    ``SceneError`` when the paper's assumption (no obstacle or wall meets the
    convex hull of the swept target) fails for this query.
    """
    if (target_at is None) == (target_in is None):
        raise ValueError("give exactly one of target_at=(x, y, theta) or target_in=<region>")
    if target_at is not None:
        try:
            x, y, th = (float(v) for v in target_at)
        except (TypeError, ValueError):
            raise ValueError(
                f"target_at must be (x, y, theta) numbers, got {target_at!r}"
            ) from None
        if not all(math.isfinite(v) for v in (x, y, th)):
            raise ValueError(f"target_at must be finite, got {target_at!r}")
        if theta not in (0.0, None) and theta != th:
            raise ValueError("with target_at the orientation is target_at[2]; do not pass theta")
        area = scene.target_at(x, y, th)
        pts = hull_points(area)
        spec = TargetSpec(
            area,
            pts,
            0.0,
            np.asarray(area.centroid.coords[0]),
            (x, y, th),
            "target at ({:.10g}, {:.10g}, {:g})".format(*to_world_point(x, y), th),
        )
    else:
        region = _region(scene, target_in)
        label = f"target in {target_in}" if isinstance(target_in, str) else "target in region"
        if theta is None:
            r = float(scene.target_radius)
            pts = hull_points(region)
            area = disc_sum(region, r)
            center = (
                np.asarray(shapely.convex_hull(region).centroid.coords[0])
                if len(pts) > 2
                else pts.mean(axis=0)
            )
            spec = TargetSpec(area, pts, r, center, None, label + " (any orientation)")
        else:
            th = float(theta)
            if not math.isfinite(th):
                raise ValueError(f"theta must be finite or None, got {theta!r}")
            a = scene.target_at(0.0, 0.0, th)
            area = minkowski_sum(a, region)
            pts = hull_points(area)
            c = shapely.convex_hull(area).centroid
            spec = TargetSpec(
                area, pts, 0.0, np.asarray(c.coords[0]), None, label + f" (orientation {th:g})"
            )
    scene.check_clear(spec.hull, spec.label)
    return spec


def _region(scene: Scene, which: str | shapely.Geometry) -> shapely.Geometry:
    if isinstance(which, str):
        if which not in ("goal", "failure"):
            raise ValueError(
                f"target_in must be 'goal', 'failure' or a shapely Polygon/Point, got {which!r}"
            )
        return scene.region(which)
    if not isinstance(which, shapely.Geometry) or which.geom_type not in ("Polygon", "Point"):
        raise ValueError(
            f"target_in must be 'goal', 'failure' or a shapely Polygon/Point, got {which!r}"
        )
    if which.is_empty or not which.is_valid:
        raise ValueError(f"target_in region is empty or invalid: {shapely.is_valid_reason(which)}")
    if not scene.free_space.covers(which):
        raise ValueError("target_in region is not inside the free space (bounds minus obstacles)")
    return which


def as_scene(scene: Any) -> Scene:
    """``scene`` as a :class:`~geometry.scene.Scene`: a Scene is returned as is, a scene
    dictionary (the JSON object) is validated; anything else raises ``SceneError``."""
    from .scene import Scene, SceneError

    if isinstance(scene, Scene):
        return scene
    if isinstance(scene, Mapping):
        return Scene.from_dict(scene)
    raise SceneError(
        f"scene must be a geometry.Scene or a scene dictionary, got {type(scene).__name__}"
    )


def _real(v: Any) -> bool:
    return isinstance(v, numbers.Real) and not isinstance(v, (bool, np.bool_))


def check_theta(theta: Any, *, allow_none: bool = True) -> float | None:
    """Validate a target orientation (radians, a finite real number; ``None`` = any
    orientation where ``allow_none``).  Strings and booleans are rejected."""
    if theta is None and allow_none:
        return None
    if not _real(theta) or not math.isfinite(float(theta)):
        want = "a finite number (radians) or None" if allow_none else "a finite number (radians)"
        raise ValueError(f"theta must be {want}, got {theta!r}")
    return _radians("theta", float(theta))


def _radians(what: str, th: float) -> float:
    """``th`` if it lies in [-2 pi, 2 pi]; else the error the JSON ``start`` gives (a value
    like 90 is degrees by mistake, issues 25 item 6 and 26 item 10)."""
    if abs(th) > 2 * math.pi:
        raise ValueError(
            f"{what}: {th!r} is outside [-2 pi, 2 pi]; orientations are in radians (did you "
            f"mean {th!r} degrees = {math.radians(th):.6g} rad?)"
        )
    return th


def check_pose(target_at: Any) -> tuple[float, float, float] | None:
    """Validate ``target_at = (x, y, theta)`` (world frame, radians); ``None`` passes."""
    if target_at is None:
        return None
    try:
        vals = list(target_at)
    except TypeError:
        vals = []
    if len(vals) != 3 or not all(_real(v) for v in vals):
        raise ValueError(f"target_at must be (x, y, theta) numbers, got {target_at!r}")
    x, y, th = (float(v) for v in vals)
    if not all(math.isfinite(v) for v in (x, y, th)):
        raise ValueError(f"target_at must be finite, got {target_at!r}")
    _radians("target_at[2] (theta)", th)
    return x, y, th


def check_aim(value: Any) -> float:
    """Validate the aim uncertainty ``eps_aim`` (radians, in [0, pi)): with eps_aim >= pi
    the aim cone would be every direction."""
    v = check_eps("eps_aim", value)
    if v >= math.pi:
        raise ValueError(
            f"eps_aim must be in [0, pi) radians (an aim error of pi or more means any "
            f"direction), got {value!r}"
        )
    return v


def check_eps_pos(scene: Scene, value: Any) -> float:
    """Validate the placement uncertainty ``eps_pos`` (scene units, >= 0, below the
    scene's diameter: a larger error puts the sensor anywhere in the room)."""
    v = check_eps("eps_pos", value)
    if v >= scene.diameter:
        raise ValueError(
            f"eps_pos={value!r} is not below the scene's diameter ({scene.diameter:.6g} scene "
            "units): a placement that uncertain could be anywhere in the room"
        )
    return v


@dataclass(frozen=True)
class Budget:
    """Time limit and progress reporting of a swept query.

    ``deadline`` is a ``time.monotonic()`` value (None: no limit); ``progress(done,
    total)`` is called after every swept edge of the region's boundary (edges of G,
    then of H for paper 5.2); ``what`` names the query in the timeout message."""

    deadline: float | None = None
    progress: Callable[[int, int], None] | None = None
    what: str = "the swept query"
    offset: int = 0
    total: int | None = None

    @staticmethod
    def make(timeout: Any, progress: Any, what: str) -> Budget:
        """Validate ``timeout`` (seconds, > 0, or None) and ``progress`` (callable or None)."""
        if timeout is not None:
            if not _real(timeout) or not math.isfinite(float(timeout)) or float(timeout) <= 0:
                raise ValueError(
                    f"timeout must be a number of seconds > 0 or None, got {timeout!r}"
                )
        if progress is not None and not callable(progress):
            raise ValueError(
                f"progress must be a callable progress(done, total) or None, got {progress!r}"
            )
        deadline = None if timeout is None else time.monotonic() + float(timeout)
        return Budget(deadline, progress, what)

    def report(self, done: int, total: int) -> None:
        if self.progress is not None:
            self.progress(self.offset + done, total if self.total is None else self.total)


def check_eps(name: str, value: float) -> float:
    """Validate a non-negative finite uncertainty bound and return it as float.  Only real
    numbers are accepted (a string such as ``"0.1"`` or a bool is an error)."""
    if not _real(value):
        raise ValueError(f"{name} must be a number, got {value!r}")
    v = float(value)
    if not math.isfinite(v) or v < 0:
        raise ValueError(f"{name} must be finite and >= 0, got {value!r}")
    return v


def check_tol(tol: float | None) -> float | None:
    """Validate an optional positive tolerance (scene units); ``None`` stays ``None``."""
    if tol is None:
        return None
    tol = check_eps("tol", tol)
    if tol <= 0:
        raise ValueError(f"tol must be > 0, got {tol!r}")
    return tol


def shrink_for_position(
    region: shapely.Geometry, allowed: shapely.Geometry, eps_pos: float
) -> shapely.Geometry:
    """Paper section 4, positional uncertainty: grow the shadows by the eps-disc.

    ``allowed`` is the placement space (free space minus the target area);
    shadows are ``allowed - region``.  The result keeps the points of ``region``
    whose whole eps-disc, within ``allowed``, lies in ``region``.  The disc is a
    polygon circumscribing the true disc, so the result is conservative: it lies
    inside the exact region, within ``eps_pos * (1/cos(pi/64) - 1)`` of it.  Shadow
    slivers thinner than 2e-9 of the scene's diagonal (float noise of the boolean
    operations) are ignored.
    """
    if eps_pos <= 0 or region.is_empty:
        return region
    shadows = _polygonal(shapely.difference(allowed, region))
    # open the shadows by a float-noise width first: the difference leaves 1e-16-wide
    # slivers along obstacle edges, which must not grow into eps-wide bands
    delta = 1e-9 * max(_diag(allowed), 1.0)
    shadows = shapely.buffer(shadows, -delta, join_style="mitre")
    grown = disc_sum(shadows, eps_pos + 2 * delta)
    return _polygonal(shapely.difference(region, grown))


def _diag(g: shapely.Geometry) -> float:
    x0, y0, x1, y1 = g.bounds
    return float(np.hypot(x1 - x0, y1 - y0))


_polygonal = polygonal  # the old private name (kept for callers outside the package)

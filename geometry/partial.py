"""Partial visibility (paper 3.2.1) with aim uncertainty (paper section 4).

A placement p partially sees the target when some point of the target's
boundary is visible.  Sweep the directions in which p sees a wanted part P of
the boundary: an extreme direction of that set either hits an endpoint of P
(a target vertex, or the end of a wanted piece) or grazes a vertex v of the
domain (a convex obstacle corner or a convex target corner: a *reflex* vertex
of the free space around the target) and then runs on to P.  So the region is
the union of *visibility triangles* anchored at

* every endpoint a of P: the points that see a from the front of a wanted edge;
* every reflex vertex v: the points p that see v such that the ray from p
  through v, continued past v, hits P first.

Both families are fans of exact triangles from :mod:`geometry._vis`: the second
is the visibility of v restricted to the directions opposite to those in which
v sees P.  Grouping adjacent triangles of one anchor that end on the same
polygon gives the paper's *visibility polygons*; with aim uncertainty
``eps_aim`` those whose apex angle is below ``eps_aim`` are dropped.
"""

from __future__ import annotations

import weakref
from collections import OrderedDict
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
import shapely

from . import sweep as _sweep
from ._common import (
    Budget,
    as_scene,
    check_aim,
    check_eps,
    check_eps_pos,
    check_pose,
    check_theta,
    check_tol,
    polygonal,
    scene_domain,
    shrink_for_position,
    target_spec,
)
from ._frame import world_messages
from ._shapes import ccw_ring, disc_sum, snapped
from .nonstar import hull_target, is_star_shaped, pocket_area
from .sweep import swept_shadows
from .weak import ENV, UNWANTED, WANTED, weak_visibility  # noqa: F401 (re-exported)

if TYPE_CHECKING:  # pragma: no cover
    from .scene import Scene

__all__ = ["partial_region", "weak_visibility"]  # weak_visibility: from geometry.weak


ROTATING_PARTIAL = (
    "the partial-visibility model for a target of unknown orientation (theta=None) is not "
    "given by the paper (its conclusion leaves it to future work); use model='complete' "
    "or a fixed theta"
)


def partial_region(
    scene: Scene,
    *,
    target_at: tuple[float, float, float] | None = None,
    target_in: str | shapely.Geometry | None = None,
    theta: float | None = 0.0,
    eps_pos: float = 0.0,
    eps_aim: float = 0.0,
    tol: float | None = None,
    conservative: bool = False,
    timeout: float | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> shapely.Geometry:
    """Sensor placements from which some point of the target is visible.

    Parameters
    ----------
    target_at : ``(x, y, theta)`` of a stationary target (world frame, radians).
    target_in : ``"goal"``, ``"failure"`` or a shapely Polygon/Point: the target
        translates through this region at orientation ``theta`` and the answer is
        the placements that see some point of it *wherever* it is there (the
        complement of the swept shadows, paper 3.2.2-3.2.3, :mod:`geometry.sweep`).
        A target that is not star-shaped sweeps as its convex hull, which gives the
        exact region here (:mod:`geometry.nonstar`; with ``eps_aim > 0`` the hull's
        visibility polygons are the ones dropped).
    theta : orientation (radians) of a target given by ``target_in``; ``None``
        (any orientation) is not supported in the partial model.
    eps_pos : worst-case placement error (scene units): shadows grown by the disc.
    eps_aim : worst-case aim error (radians): visibility polygons whose apex angle
        at their anchor vertex is below ``eps_aim`` are dropped (paper section 4).
        With ``target_in`` it shapes the shadows at the sample configurations; the
        traces between samples are validated by the exact (aim-free) point test, so
        shadow edges that exist only because of ``eps_aim`` are not traced between
        samples (the answer may keep placements that the construction would drop
        at an intermediate configuration).
    tol : only with ``target_in``: the shadow boundaries traced by free vertices
        (lines and conics) are emitted as polylines whose chords stay within
        ``tol`` (scene units) of the curves; default ``1e-4 * scene.diameter``.
    timeout : only with ``target_in``: a time limit in seconds; past it the query
        raises :class:`~geometry.sweep.QueryTimeout` (a ``TimeoutError``) naming
        the edges of the region's boundary left to sweep.  ``None``: no limit.
    progress : only with ``target_in``: ``progress(done, total)`` is called after
        every swept edge of the region's boundary.
    conservative : only with ``target_in``: grow the shadows by ``tol`` (plus the
        ~1e-12 D snap-rounding grid of their union, see
        :func:`~geometry.sweep.swept_shadows`), so that the answer lies inside
        the exact region as long as the sweep misses no shadow deeper than ``tol``
        (checked, not proven: a shadow *spike* that lives between two samples is caught
        only where a sample falls inside its life; see docs/DESIGN.md, "What is and is not
        guaranteed").  For a region proven inside, use
        ``geometry.swept_bounds(...).proven_inner``.

    Returns
    -------
    A shapely Polygon/MultiPolygon (possibly empty) in world coordinates: the
    placements inside the bounds, outside obstacles and outside the target (for
    ``target_in``: outside the area the target sweeps).  Computed in the scene's local
    frame (see :func:`~geometry.complete_region`); ``scene`` may be a scene dictionary.
    """
    scene = as_scene(scene)
    theta = check_theta(theta)
    target_at = check_pose(target_at)
    eps_pos = check_eps_pos(scene, eps_pos)
    eps_aim = check_aim(eps_aim)
    tol = check_tol(tol)
    budget = Budget.make(timeout, progress, "partial_region(target_in=...)")
    if target_in is None and (timeout is not None or progress is not None):
        raise ValueError("timeout and progress apply to a moving target (target_in=...) only")
    fr = scene.frame
    with world_messages(fr):
        out = _partial_region(
            scene.local,
            fr.pose(target_at),
            fr.region(target_in),
            theta,
            fr.length(eps_pos),
            eps_aim,
            fr.length(tol),
            conservative,
            budget,
        )
    return fr.to_world(out)


def _partial_region(
    scene: Scene,
    target_at: tuple[float, float, float] | None,
    target_in: str | shapely.Geometry | None,
    theta: float | None,
    eps_pos: float,
    eps_aim: float,
    tol: float | None,
    conservative: bool,
    budget: Budget | None = None,
) -> shapely.Geometry:
    """:func:`partial_region` on a scene in its local frame (arguments checked)."""
    if target_in is not None:
        if target_at is not None:
            raise ValueError("give exactly one of target_at=(x, y, theta) or target_in=<region>")
        return _swept_region(
            scene, target_in, theta, eps_pos, eps_aim, tol, conservative, budget=budget
        )
    if tol is not None or conservative:
        raise ValueError("tol and conservative apply to a moving target (target_in=...) only")
    if target_at is None:
        raise ValueError("give target_at=(x, y, theta)")
    spec = target_spec(scene, target_at, None, theta)
    ring = _hole_ring(spec.area)
    region = weak_visibility(scene_domain(scene), ring, np.ones(len(ring), dtype=bool), eps_aim)
    # clipped to the free space: an anchor on a target edge that lies flush against an
    # obstacle (touching within the scene's tolerance) may be inside that obstacle by
    # rounding, and its fan then fills the obstacle (issue 10, fuzz seed 223)
    g = scene.snap  # snap-rounding overlays: exact contacts (docs/DESIGN.md, "Contacts")
    allowed = snapped(shapely.difference, scene.free_space, spec.area, g)
    # (snap-rounding overlays take one dimension: the areal parts of the fans' union)
    region = polygonal(snapped(shapely.intersection, region, allowed, g))
    if eps_pos > 0:
        region = shrink_for_position(region, allowed, eps_pos)
    return region


def _swept_region(
    scene: Scene,
    target_in: str | shapely.Geometry,
    theta: float | None,
    eps_pos: float,
    eps_aim: float,
    tol: float | None,
    conservative: bool,
    strips: list[shapely.Geometry] | None = None,
    budget: Budget | None = None,
    sink: dict | None = None,
    extra_samples: int = 0,
    lazy: bool | None = None,
) -> shapely.Geometry:
    """The partial region of a target translating through ``target_in``.  ``sink``: a
    dict that receives the sampled exact shadows and the pieces of the answer
    (:mod:`geometry.certify`); ``lazy``: the sweep's sampling rules
    (:attr:`geometry.sweep.Sweeper.lazy_samples`; None: :data:`geometry.sweep.LAZY_SAMPLES`)."""
    budget = budget or Budget()
    if theta is None:
        raise NotImplementedError(ROTATING_PARTIAL)
    tol = swept_tol(scene, tol)
    spec = target_spec(scene, None, target_in, float(theta))
    region = scene.region(target_in) if isinstance(target_in, str) else target_in
    target = _ccw_ring(scene.target_at(0.0, 0.0, float(theta)))
    # a target that is not star-shaped sweeps as its convex hull (geometry/nonstar.py):
    # exact for the whole outline, a certified inner region with strips (5.2)
    stand_in = None if is_star_shaped(target) else hull_target(target, strips, region)
    if stand_in is not None:
        target, strips = stand_in.ring, stand_in.strips
    lazy = _sweep.LAZY_SAMPLES if lazy is None else lazy
    reuse = sink is None and extra_samples == 0 and budget.progress is None
    key = _sweep_key(scene, target, region, strips, eps_aim, tol) + (lazy,) if reuse else None
    got = _SWEEPS.get(key) if key is not None else None
    if got is not None and got[0]() is scene:
        _SWEEPS.move_to_end(key)
        shadows, stats = got[1]
    else:
        shadows, stats = swept_shadows(
            scene_domain(scene),
            scene.free_space,
            target,
            region,
            strips=strips,
            eps_aim=eps_aim,
            tol=tol,
            deadline=budget.deadline,
            progress=budget.report if budget.progress is not None else None,
            what=budget.what,
            samples=None if sink is None else sink.setdefault("samples", []),
            extra_samples=extra_samples,
            lazy=lazy,
        )
        if key is not None:
            _SWEEPS[key] = (weakref.ref(scene), (shadows, stats))
            while len(_SWEEPS) > SWEEPS_KEPT:
                _SWEEPS.popitem(last=False)
    if conservative:
        # tol: the traced arcs' chords; grid: the snap-rounding of the union (sweep.py)
        shadows = disc_sum(shadows, tol + stats["grid"])
    # floating overlay: the shadows are already snap-rounded on the sweep's own grid
    allowed = shapely.difference(scene.free_space, spec.area)
    if stand_in is not None and not stand_in.exact:
        # the pockets swept through the region are dropped like shadows (eps_pos too)
        shadows = shapely.union(shadows, pocket_area(target, region))
    out = polygonal(shapely.difference(allowed, shadows))
    if sink is not None:
        sink.update(
            allowed=allowed, grid=stats["grid"], stand_in=stand_in, region=region, stats=stats
        )
    if eps_pos > 0:
        out = shrink_for_position(out, allowed, eps_pos)
    return out


#: How many sweeps (the union of the swept shadows, before ``conservative`` and ``eps_pos``)
#: are kept, over all scenes, for a query that repeats one: the swept partial region with and
#: without ``conservative=True``, or the 5.2 region and its conservative version, run the
#: same sweeps.  A sweep is a deterministic function of its key (:func:`_sweep_key`), so a
#: reused one is the one that would be computed.
SWEEPS_KEPT = 16

_SWEEPS: OrderedDict[tuple, tuple] = OrderedDict()


def _sweep_key(
    scene: Scene,
    target: np.ndarray,
    region: shapely.Geometry,
    strips: list[shapely.Geometry] | None,
    eps_aim: float,
    tol: float,
) -> tuple:
    """What a sweep of ``scene`` (in its local frame) depends on; the scene by identity
    (checked against a weak reference when the sweep is reused)."""
    return (
        id(scene),
        target.shape,
        np.ascontiguousarray(target, dtype=float).tobytes(),
        shapely.to_wkb(region),
        None if strips is None else tuple(shapely.to_wkb(g) for g in strips),
        float(eps_aim),
        float(tol),
    )


def swept_tol(scene: Scene, tol: float | None) -> float:
    """Validate ``tol`` (scene units, > 0); ``None`` gives 1e-4 of the scene diameter."""
    if tol is None:
        return 1e-4 * scene.diameter
    t = check_eps("tol", tol)
    if t <= 0:
        raise ValueError(f"tol must be > 0, got {tol!r}")
    return t


def _ccw_ring(poly: shapely.Polygon) -> np.ndarray:
    return ccw_ring(poly)


def _hole_ring(poly: shapely.Polygon) -> np.ndarray:
    """Exterior of ``poly`` clockwise (free space on the left), no closing vertex."""
    return ccw_ring(poly, clockwise=True)

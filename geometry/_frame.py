"""Local frames: every region computation runs on a scene centred at the origin
with a diameter between 1/sqrt(2) and sqrt(2), and its results are mapped back.

Why: the region algorithms compare cross products, angles and distances against
tolerances relative to the scene's size.  At georeferenced coordinates (UTM,
1e6 m) with a 10 m room, the last bit of a coordinate is already 1e-11 of the
room and the cross products of un-centred coordinates lose six more digits, so
answers changed under translation (issue 10).  In the local frame the answer
depends on the *shape* of the scene only.

The map is ``local = (world - offset) / scale`` with ``scale`` a power of two
(dividing by it is exact) and ``offset`` a multiple of ``scale`` (so that the
subtraction is exact for every coordinate whose last bit is at most ``scale``,
i.e. for every scene whose diameter exceeds its coordinates' rounding).  The
local scene is therefore the *exact* image of the world scene; only the mapped
back results are rounded once (to the world coordinates' last bit).

Error messages raised while a local scene is validated or queried name world
coordinates: :func:`world_messages` makes :mod:`geometry.scene` format points
through the inverse map.
"""

from __future__ import annotations

import contextlib
import contextvars
import math
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
import shapely
import shapely.errors

from ._shapes import areal

__all__ = ["Frame", "IDENTITY", "frame_params", "world_messages", "to_world_point"]

#: (offset_x, offset_y, scale) of the frame whose coordinates are being formatted
#: into error messages; None: coordinates are world coordinates.
_MESSAGE_FRAME: contextvars.ContextVar[tuple[float, float, float] | None] = contextvars.ContextVar(
    "geometry_message_frame", default=None
)


@dataclass(frozen=True)
class Frame:
    """``local = (world - (ox, oy)) / scale``; ``scale`` is a power of two."""

    ox: float
    oy: float
    scale: float

    @property
    def identity(self) -> bool:
        return self.ox == 0.0 and self.oy == 0.0 and self.scale == 1.0

    # -- world -> local ----------------------------------------------------------------------

    def points(self, pts: np.ndarray) -> np.ndarray:
        """(n, 2) world points -> local points."""
        p = np.asarray(pts, dtype=float)
        return (p - np.array([self.ox, self.oy])) / self.scale

    def length(self, v: float | None) -> float | None:
        """A length (scene units) in the local frame; ``None`` stays ``None``."""
        return None if v is None else float(v) / self.scale

    def pose(self, q: tuple[float, float, float] | None) -> tuple[float, float, float] | None:
        """A target configuration ``(x, y, theta)`` (radians unchanged)."""
        if q is None:
            return None
        x, y, th = q
        return ((float(x) - self.ox) / self.scale, (float(y) - self.oy) / self.scale, float(th))

    def geom(self, g: shapely.Geometry) -> shapely.Geometry:
        """A shapely geometry, world -> local."""
        if self.identity:
            return g
        return shapely.transform(g, lambda c: (c - np.array([self.ox, self.oy])) / self.scale)

    def region(self, which: object) -> object:
        """A ``target_in`` argument: names pass through, shapely geometries are mapped."""
        if isinstance(which, shapely.Geometry):
            return self.geom(which)
        return which

    # -- local -> world ----------------------------------------------------------------------

    def to_world(self, g: shapely.Geometry) -> shapely.Geometry:
        """A shapely geometry, local -> world (one rounding per coordinate).

        Rounding can fold a sliver of a valid polygon (two vertices closer than the world
        coordinates' last bit): such a result is repaired (``make_valid``, areal parts
        kept, twisted loops kept as areas)."""
        if self.identity:
            return g
        if (self.ox or self.oy) and not g.is_empty and g.geom_type in ("Polygon", "MultiPolygon"):
            # snap-round onto the world's grid first (GEOS set_precision keeps the result
            # valid): every local coordinate then maps to a world coordinate exactly, so the
            # rounding of the map cannot twist a ring (fuzz seeds 102667, 302211, 309618)
            top = max(abs(self.ox), abs(self.oy)) + 4.0 * self.scale
            grid = float(np.spacing(top)) / self.scale
            try:
                g = shapely.set_precision(g, grid)
            except shapely.errors.GEOSException:  # pragma: no cover - GEOS corner cases
                pass
        w = shapely.transform(g, lambda c: c * self.scale + np.array([self.ox, self.oy]))
        if w.is_empty or w.is_valid or g.geom_type not in ("Polygon", "MultiPolygon"):
            return w
        # No single repair is right every time: "structure" (and buffer(0)) drop the loop
        # of a ring that rounding twisted (4e-6 lost at a 3.2e5 offset, fuzz seed 102667),
        # "linework" keeps it but fills a hole whose ring touched the shell (7e-4 D^2
        # gained, seed 302211).  The local area, times scale^2, is known to the last bits:
        # keep the candidate closest to it.
        want = float(g.area) * self.scale * self.scale
        best, err = None, math.inf
        for cand in (
            lambda: shapely.make_valid(w, method="structure", keep_collapsed=False),
            lambda: shapely.make_valid(w, method="linework"),
            lambda: shapely.buffer(w, 0.0),
        ):
            try:
                c = areal(shapely.union_all(shapely.get_parts(areal(cand()))))
            except shapely.errors.GEOSException:  # pragma: no cover - GEOS corner cases
                continue
            if c.is_valid and abs(c.area - want) < err:
                best, err = c, abs(c.area - want)
        return best if best is not None else areal(shapely.make_valid(w))

    def to_world_pts(self, p: np.ndarray) -> np.ndarray:
        return np.asarray(p, dtype=float) * self.scale + np.array([self.ox, self.oy])


IDENTITY = Frame(0.0, 0.0, 1.0)


def frame_params(pts: np.ndarray) -> Frame:
    """The local frame of a scene whose walls have vertices ``pts`` (world frame).

    ``scale`` is the power of two nearest (in log) to the diagonal of their bounding box;
    ``offset`` is the box's centre rounded to a multiple of ``scale``.
    """
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    diag = float(math.hypot(*(hi - lo)))
    if not math.isfinite(diag) or diag <= 0.0:
        return IDENTITY
    scale = math.ldexp(1.0, round(math.log2(diag)))
    mid = 0.5 * (lo + hi)
    ox, oy = (float(np.round(m / scale) * scale) for m in mid)
    return Frame(ox + 0.0, oy + 0.0, scale)


@contextlib.contextmanager
def world_messages(frame: Frame) -> Iterator[None]:
    """While active, points in :class:`~geometry.scene.SceneError` messages are
    mapped from ``frame`` to world coordinates."""
    if frame.identity:
        yield
        return
    token = _MESSAGE_FRAME.set((frame.ox, frame.oy, frame.scale))
    try:
        yield
    finally:
        _MESSAGE_FRAME.reset(token)


def to_world_point(x: float, y: float) -> tuple[float, float]:
    """A point of an error message in world coordinates (see :func:`world_messages`)."""
    f = _MESSAGE_FRAME.get()
    if f is None:
        return x, y
    return x * f[2] + f[0], y * f[2] + f[1]

"""The domain of the visibility computations: directed boundary segments of a free region.

:class:`Domain` is what :mod:`geometry._vis` (visibility polygons by angular gaps) and
:mod:`geometry.visindex` (the grid-accelerated ray shooting) both read; it lives below both so
neither imports the other's module for it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely

from . import _libm
from ._shapes import cross

TAU = 2.0 * np.pi

__all__ = ["TAU", "Domain", "domain_from_geometry"]

_cross = cross  # the package's one cross product (geometry._shapes)


@dataclass(frozen=True)
class Domain:
    """Boundary segments of a free region (free side on the left of each segment).

    Attributes
    ----------
    seg : (E, 4) float array of ``x0, y0, x1, y1`` per directed segment.
    seg_ring : (E,) int ring index of each segment.
    seg_tag : (E,) int caller's tag of each segment (e.g. 0 environment, 1 target).
    vert : (V, 2) float array of ring vertices (each vertex once per ring).
    vert_prev, vert_next : (V, 2) neighbouring vertices along the ring.
    vert_ring : (V,) ring index of each vertex.
    reflex : (V,) bool, True where the free region's interior angle exceeds pi.
    scale : float, the diagonal of the domain's bounding box (tolerances are relative to it).
    """

    seg: np.ndarray
    seg_ring: np.ndarray
    seg_tag: np.ndarray
    vert: np.ndarray
    vert_prev: np.ndarray
    vert_next: np.ndarray
    vert_ring: np.ndarray
    reflex: np.ndarray
    scale: float

    @property
    def vert_wedge(self) -> np.ndarray:
        """(V, 2) free wedge ``(start, width)`` at every vertex: counter-clockwise
        from the direction of the next vertex to that of the previous one."""
        a = _libm.atan2(
            self.vert_next[:, 1] - self.vert[:, 1], self.vert_next[:, 0] - self.vert[:, 0]
        )
        b = _libm.atan2(
            self.vert_prev[:, 1] - self.vert[:, 1], self.vert_prev[:, 0] - self.vert[:, 0]
        )
        w = (b - a) % TAU
        return np.stack([a, np.where(w == 0.0, TAU, w)], axis=1)

    @staticmethod
    def from_rings(
        rings: list[np.ndarray], tags: list[int], seg_tags: list[np.ndarray] | None = None
    ) -> Domain:
        """Build a domain from closed rings (without repeated closing vertex).

        Each ring must already be oriented with the free region on its left; ``tags``
        gives one tag per ring, ``seg_tags`` optionally one per segment of each ring.
        """
        rings = [np.asarray(r, dtype=float) for r in rings]
        nxt = [np.roll(r, -1, axis=0) for r in rings]
        prv = [np.roll(r, 1, axis=0) for r in rings]
        ids = [np.full(len(r), i) for i, r in enumerate(rings)]
        if seg_tags is None:
            seg_tags = [np.full(len(r), t) for r, t in zip(rings, tags, strict=True)]
        vert, vprev, vnext = np.vstack(rings), np.vstack(prv), np.vstack(nxt)
        return Domain(
            seg=np.hstack([vert, vnext]),
            seg_ring=np.concatenate(ids),
            seg_tag=np.concatenate([np.asarray(t) for t in seg_tags]),
            vert=vert,
            vert_prev=vprev,
            vert_next=vnext,
            vert_ring=np.concatenate(ids),
            reflex=_cross(vert - vprev, vnext - vert) < 0.0,
            scale=float(np.hypot(*(vert.max(axis=0) - vert.min(axis=0)))),
        )

    def with_ring(self, ring: np.ndarray, tag: int, tags: np.ndarray | None = None) -> Domain:
        """Return a copy with one more ring (e.g. the target as a hole).

        ``tags`` optionally gives a tag per segment of the new ring.
        """
        extra = Domain.from_rings([ring], [tag], None if tags is None else [tags])
        r_i = int(self.seg_ring.max()) + 1 if len(self.seg_ring) else 0
        out = Domain(
            seg=np.vstack([self.seg, extra.seg]),
            seg_ring=np.concatenate([self.seg_ring, extra.seg_ring + r_i]),
            seg_tag=np.concatenate([self.seg_tag, extra.seg_tag]),
            vert=np.vstack([self.vert, extra.vert]),
            vert_prev=np.vstack([self.vert_prev, extra.vert_prev]),
            vert_next=np.vstack([self.vert_next, extra.vert_next]),
            vert_ring=np.concatenate([self.vert_ring, extra.vert_ring + r_i]),
            reflex=np.concatenate([self.reflex, extra.reflex]),
            scale=self.scale,
        )
        # the grid of geometry.visindex is shared with the parent (built once per scene)
        object.__setattr__(out, "_parent", self)
        return out


def domain_from_geometry(geom: shapely.Geometry, tag: int = 0) -> Domain:
    """Domain of a shapely Polygon/MultiPolygon (free region = its interior)."""
    geom = shapely.orient_polygons(geom, exterior_cw=False)
    rings: list[np.ndarray] = []
    for poly in getattr(geom, "geoms", [geom]):
        if poly.is_empty:
            continue
        for ring in [poly.exterior, *poly.interiors]:
            rings.append(_ring_coords(ring))
    return Domain.from_rings(rings, [tag] * len(rings))


def _ring_coords(ring: shapely.LinearRing) -> np.ndarray:
    c = np.asarray(ring.coords)[:-1, :2]
    # drop consecutive duplicates and collinear points are kept (harmless)
    keep = np.any(np.abs(c - np.roll(c, 1, axis=0)) > 0.0, axis=1)
    return c[keep]

"""Event samples that the known shadows make needless: the wedge's cone.

A live collinearity event asks for a sample between it and its neighbouring event, to catch
the wedge that can open there (:mod:`.events`).  The wedge lies beyond a corner of the event,
between the two lines through that corner (docs/DESIGN.md, "The sides of an event where its
wedge can be blind"), and it lies in every shadow bound of its interval; where the part of
that cone inside the bound is already held by the two samples' shadows, the sample can add
nothing to the union.  Part of :class:`geometry.sweep.Sweeper`; :data:`WEDGE_RULE` switches it.
"""

from __future__ import annotations

import numpy as np
import shapely

from .._shapes import areal, snapped

#: Whether :meth:`WedgeCover._wedge_covered` may leave samples out (docs/DESIGN.md, "Event
#: samples whose wedge the samples already hold").  It was off for a while: on fuzz seed
#: 202333 (mixed 5.2) a sample it left out had been the only one to catch a configuration
#: born and gone between two samples, which the continuation rule took as held by traces of
#: other configurations on the same line; a holder now stands in only for its own
#: configuration (:meth:`~geometry._sweep.cover.Coverage._unheld`), and with it the rule
#: leaves that shadow in the union (``tests/geometry/test_swept_births.py``).
WEDGE_RULE = True

#: Points on the arc of a wedge's cone (:func:`_cone`): the polygon's chords then stay
#: within ``1 - cos(pi / 16) < 2 %`` of its radius, which is four times the scene's size.
CONE_ARC = 9


class WedgeCover:
    """The wedge test of a :class:`~geometry.sweep.Sweeper` (a mixin of it: it uses the
    sweeper's anchors, birth-check bounds and samples' ``X``): :meth:`_wedge_covered`."""

    def _wedge_covered(self, r, k: int, side: int, lo: float, hi: float) -> bool:
        """Whether event ``k`` of the run ``r`` (``geometry.sweep._Run``) needs no sample on
        its ``side`` (-1 before, 1 after), the interval ``(lo, hi)`` between events that
        :meth:`_live_mids` would sample (no sample strictly inside it): every wedge the
        event can open there is held by the shadows of the samples ``a <= lo``, ``hi <= b``
        around it.  Lazy rules only.

        The wedge, born at the event's time ``t_e``, lies beyond a corner of the event line
        between the two lines through it: the event line itself and the line from the
        moving anchor to the corner (for the line of two target vertices through a corner
        b, the lines from both vertices to b).  Those lines change only at an event that
        involves the corner and the moving anchor (the moving line passing another corner,
        or the target's tangent vertex handing over to another, both of them on a line
        through the corner); with none in the wedge's life within
        ``(a, b)``, namely ``(t_e, b)`` after the event or ``(a, t_e)`` before it, the wedge
        stays in the cone at the corner swept by the moving line over that life
        (:meth:`_wedge_cone`; the moving anchors run on straight lines, so each line turns
        one way), and in a birth check's bound that holds every shadow there
        (``r.uppers``: that of the shortest interval checked holding ``(a, b)``, whether or
        not the check found a birth in it).  Where the part of cone and bound outside
        ``S_a u S_b``, i.e. inside ``X_a n X_b`` (:meth:`_seen_pair`), has no part wider
        than the union's grid (as :meth:`_closes` counts), the union already holds the
        wedge.  Both corners of an event line count (the wedge is beyond the farther one;
        along an obstacle edge, beyond the nearer one).  With overlap strips (5.2) the
        bound holds the full target's shadows only: as in :meth:`_closes`, only where no
        strip comes near (:meth:`_strips_miss`)."""
        if not (self.lazy_samples and WEDGE_RULE):
            return False
        times = np.array(sorted(r.frames))
        before, after = times[times <= lo], times[times >= hi]
        if not (len(before) and len(after)):
            return False
        a, b = float(before[-1]), float(after[0])
        upper = _tightest(r.uppers, a, b)
        if upper is None or (self.strips is not None and not self._strips_miss(r, a, b)):
            return False
        t_e = float(r.ev_t[k])
        life = (t_e, b) if side > 0 else (a, t_e)
        corners = {c for _, other in r.ev_ids[k] for c in other}
        if -1 in corners:  # an obstacle edge's end not known: no cone
            return False
        if self._wedge_moved(r, k, life):
            return False
        cone = self._wedge_cone(r, r.ev_ids[k], life)
        if cone is None:
            return False
        seen = self._seen_pair(*(self._frame_key(r.q0, r.q1, t) for t in (a, b)))
        if seen is None:
            return False
        g = self.grid
        rest = areal(
            snapped(
                shapely.intersection, areal(snapped(shapely.intersection, cone, upper, g)), seen, g
            )
        )
        parts = shapely.get_parts(rest)
        return not (2.0 * shapely.area(parts) > g * shapely.length(parts)).any()

    def _wedge_moved(self, r, k: int, life: tuple[float, float]) -> bool:
        """Whether an event of the run ``r`` strictly inside ``life`` moves the lines of event
        ``k``'s wedge: an event of one of its corners and one of its moving anchors (the
        anchor's line passing another corner, or the tangent vertex handing over; another
        vertex's event at the corner moves other lines), at either corner of an event line:
        the wedge is beyond the farther one, but a guard there alone leaves out samples whose
        shadows reach outside the union (fuzz seeds 200177 and 201224,
        ``tests/geometry/test_sweep_wedges.py``)."""
        return _moved_at(r, k, life, {c for _, other in r.ev_ids[k] for c in other})

    def _wedge_cone(self, r, ids: list, life: tuple[float, float]) -> shapely.Geometry | None:
        """The cones (:func:`_cone`) of an event's anchor tuples ``ids`` ((moving ids, other
        ids) each, :meth:`_events`) over the times ``life`` of the run ``r``: for a moving
        anchor x and corners c, at each c between the directions from x to c at the two
        times; for two moving vertices and a corner b, at b between the four directions
        from them to b.  None where a cone spans half a turn or more (then no wedge is
        ruled out)."""
        ts = np.asarray(life, dtype=float)
        qs = r.q0 + ts[:, None] * r.dq
        reach = 4.0 * self.env.scale
        cones = []
        for mov, other in ids:
            xs = np.vstack([self.pos(np.full(len(ts), m), qs) for m in mov])
            for c in other:
                apex = self.env.vert[c]
                got = _cone(apex, apex - xs, reach)
                if got is None:
                    return None
                cones.append(got)
        return shapely.union_all(cones) if cones else None


def _moved_at(r, k: int, life: tuple[float, float], corners: set) -> bool:
    """Whether an event of the run ``r`` strictly inside ``life`` involves one of
    ``corners`` and one of the moving anchors of event ``k``."""
    moving = {m for mov, _ in r.ev_ids[k] for m in mov}
    return any(
        corners & set(other) and moving & set(mov)
        for j, t in enumerate(r.ev_t)
        if j != k and life[0] < t < life[1]
        for mov, other in r.ev_ids[j]
    )


def _tightest(uppers: dict, a: float, b: float) -> shapely.Geometry | None:
    """The bound of the shortest interval of ``uppers`` ((x, y) -> bound of every shadow for
    times in [x, y]) that holds ``[a, b]``; None when none does."""
    best = None
    for (x, y), u in uppers.items():
        if x <= a and b <= y and (best is None or y - x < best[0]):
            best = (y - x, u)
    return None if best is None else best[1]


def _cone(apex: np.ndarray, dirs: np.ndarray, reach: float) -> shapely.Geometry | None:
    """The polygon of the cone at ``apex`` spanned by the directions ``dirs`` (n, 2) (the
    smallest angle holding all of them), out to ``reach`` (it holds the disc of radius
    ``reach cos(pi / 16)`` inside the cone); None when the directions span half a turn or
    more, or include a zero one."""
    if not (np.hypot(dirs[:, 0], dirs[:, 1]) > 0).all():
        return None
    ang = np.arctan2(dirs[:, 1], dirs[:, 0])
    rel = (ang - ang[0] + np.pi) % (2.0 * np.pi) - np.pi
    lo, hi = float(rel.min()), float(rel.max())
    if hi - lo >= np.pi:
        return None
    th = ang[0] + np.linspace(lo, hi, CONE_ARC)
    arc = apex + reach * np.stack([np.cos(th), np.sin(th)], axis=1)
    if hi - lo <= 0.0:  # one direction: a ray, no area
        return shapely.LineString([apex, arc[0]])
    return shapely.Polygon(np.vstack([apex, arc]))

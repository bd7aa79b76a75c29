"""Fuzzing the region functions on degenerate scenes (issue 10).

:func:`fuzz_scene` draws a *valid-looking* scene dictionary full of the contacts that
exact geometry gets wrong: obstacles flush on walls (vertices interpolated on the wall,
so off it by rounding), obstacles sharing edges or vertices, T-junctions (a vertex on
another polygon's edge), collinear edges, slivers (aspect ratio down to 1e-7), obstacles
touching the convex hull of the target at G (at a vertex or flush on an edge), non-convex
rooms, coordinates rounded to 6 decimals, and scales from 1e-6 to 1e6.  Coordinates are
snapped to a dyadic grid of ``2**-32`` of the scene's size so that translating the scene
by a multiple of its size (up to ~1e6 sizes) is *exact*: the translation check then
demands equality up to the output's rounding.

:func:`check_scene` runs every query type on one scene and returns the violations:

* ``crash``: an exception other than :class:`~geometry.SceneError` /
  ``NotImplementedError`` (``SceneError`` is the documented answer for a query that
  violates the paper's assumption, e.g. a rotated target whose hull meets an obstacle);
* ``invalid``: not a valid shapely Polygon/MultiPolygon;
* ``outside``: area outside the free space (or inside the target) above 1e-9 D^2;
* ``inclusion``: complete ⊆ partial, translating ⊆ stationary at every vertex of G, any
  orientation ⊆ fixed orientation, recognizable ⊆ both complete regions, swept partial
  (``conservative=True``) ⊆ stationary partial at the vertices of G and at three sampled
  configurations (two on its boundary, one inside), violated by more than 1e-8 D^2;
* ``unsafe``: a sampled member of a complete region that an independent segment test
  finds blind to part of the target (points within 1e-6 D of the region's boundary are
  skipped); a sampled member of the stationary partial region that sees no sampled point
  of the target's outline, contacts blocking (points within 1e-2 D skipped);
* ``missed``: a sampled non-member of the stationary partial region that sees a sampled
  outline point along a segment 1e-7 D clear of everything (issue 26 items 2, 5);
* ``translation``: the region of the scene translated by an exact offset (a multiple of a
  power of two near the scene's size, 10 to 1e5 sizes away), translated
  back, differs from the original by more than 1e-9 D^2;
* ``hang``: a query that took more than 10 s of CPU time (scenes of at most 60 edges).

* ``frame`` (``frames=True``, issue 26): the scene scaled by 1e-3 and 1e3 and moved to UTM
  coordinates (inexact maps: the inputs differ by rounding), regions mapped back, differ
  by more than 1e-7 D^2; with ``swept`` also the swept partial region and (polygonal G/H)
  the 5.2 recognizable region, up to their tracing tolerance (1e-4 D); and the 5.2 region
  ⊆ R(G), R(H) and ⊆ the stationary recognizable region of a vertex pair.

``contacts=True`` (``--contacts``) adds the scene families issue 26 found missing:
near-duplicate target vertices, flush obstacles over both ends of a target edge, a target
under an opening, a second obstacle sharing a flush one's edge.

``certify=True`` (``--certify``, with ``swept``; issue 25 item 2) also runs
:func:`geometry.swept_bounds` (no aim error) and demands (``inclusion``) proven inner ⊆
outer and inner ⊆ outer, the proven inner ⊆ the stationary partial region at the vertices
of G and the sampled configurations, and for polygonal or mixed G/H the 5.2 bounds' proven
inner ⊆ outer, ⊆ R(G) and ⊆ R(H) (a proven inner bound that is ``None``, for a target
too thin for the cells of G, is skipped).

``nonstar=True`` (``--nonstar``) draws targets with an empty kernel (U, comb, hook), and
with ``swept`` scenes that mix a point and a polygon also run the mixed recognizable
region (``⊆`` the partial regions of both; issue 25).

``python -m geometry.fuzz --n 10000 [--swept] [--contacts] [--frames] [--nonstar] [--jobs N]``
runs the long version and prints a table; ``tests/geometry/test_fuzz.py`` runs a fast one in the
default test run.

The package: :mod:`.scenes` (the generator), :mod:`.checks` (one scene's checks),
:mod:`.frames` (the frame checks), :mod:`.findings` (what is reported), :mod:`.run` (many
seeds, the command line).
"""

from .checks import check_scene
from .findings import HANG_S, Finding
from .frames import FRAMES
from .run import main, run_many
from .scenes import fuzz_scene

__all__ = ["FRAMES", "HANG_S", "Finding", "check_scene", "fuzz_scene", "main", "run_many"]

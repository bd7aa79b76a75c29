"""Scene model: the pinned JSON scene format, its validation, and derived shapely geometry.

Frames and units
----------------
* World frame: the plane of ``bounds``; lengths in the scene's own (arbitrary) unit.
* Target frame: ``target`` is given relative to its reference point, which is the origin
  ``(0, 0)``; it may lie inside the target polygon, on its outline or outside it.  A target
  *configuration* ``q = (x, y, theta)`` places the reference point at ``(x, y)`` and rotates
  the target by ``theta`` radians counter-clockwise about it (:meth:`Scene.target_at`).
* Angles: radians everywhere in the Python API; only the JSON fields whose names end in
  ``_deg`` are degrees.  ``start[2]`` is in radians.

The JSON format (see issue 2)::

    {
      "name": "lab",
      "bounds":    [[x, y], ...],          # simple polygon (walls), need not be convex
      "obstacles": [[[x, y], ...], ...],   # polygons; may touch or overlap (they are merged)
      "target":    [[x, y], ...],          # target A in its own frame (reference point (0, 0))
      "goal":      [[x, y], ...],          # G: a polygon, or one point [[x, y]]
      "failure":   [[x, y], ...],          # H: a polygon, or one point [[x, y]]
      "sensor":    {"fov_deg": 360, "max_range": null, "eps_pos": 0.0, "eps_aim_deg": 0.0,
                    "range_acc": null, "normal_acc_deg": 0.01},
      "start":     [x, y, theta]           # optional robot start pose (theta in radians)
    }

``sensor`` and ``start`` are optional.  ``Scene.to_dict()`` returns exactly the (JSON-style)
dictionary the scene was built from: same keys, same numbers, same vertex order.  The numpy
arrays exposed as attributes are counter-clockwise-normalised, read-only copies.

Tolerance
---------
Geometric validation and :meth:`Scene.check_clear` use ``scene.tol = 1e-9 * scene.diameter``:
geometry that merely *touches* an obstacle or a wall (to within ``tol``) is accepted.
"""

from __future__ import annotations

import copy
import functools
import json
import math
import numbers
import re
from collections.abc import Mapping
from dataclasses import dataclass
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from shapely.geometry import MultiPolygon, Point, Polygon
from shapely.geometry.base import BaseGeometry

from ._frame import IDENTITY, Frame, frame_params, to_world_point, world_messages
from ._shapes import areal, snap_grid

__all__ = ["SceneError", "SensorSpec", "Scene", "TOL_REL", "NEAR_REL", "PAPER_ASSUMPTION"]

#: Relative tolerance: ``scene.tol = TOL_REL * scene.diameter``.
TOL_REL = 1e-9

#: Target vertices closer than ``NEAR_REL * scene.tol`` (1e-7 D) are one vertex, and a point
#: touching the target's hull that close to a hull vertex touches it at that vertex: an edge
#: so short has a direction set by rounding, and a tolerance of one ``tol`` left the near-
#: duplicates of the fuzzer (1.0-1.1 tol apart) to be decided by it (docs/DESIGN.md,
#: "Contacts", rule 2).
NEAR_REL = 100.0

#: Text appended to every violation of the paper's stated assumption (Briggs & Donald 3.1.1).
PAPER_ASSUMPTION = (
    "this violates the paper's assumption that no obstacle or wall lies within the convex hull "
    "of the target's (swept) area (Briggs & Donald 3.1.1)"
)

REQUIRED_KEYS = ("name", "bounds", "obstacles", "target", "goal", "failure")
OPTIONAL_KEYS = ("sensor", "start")
ALLOWED_KEYS = REQUIRED_KEYS + OPTIONAL_KEYS
SENSOR_KEYS = ("fov_deg", "max_range", "eps_pos", "eps_aim_deg", "range_acc", "normal_acc_deg")
#: Sensor fields measured in scene units (scaled with the scene into its local frame).
_LENGTH_SENSOR_KEYS = ("max_range", "eps_pos", "range_acc")
#: Largest accepted coordinate magnitude (scene units): the cross products and areas the
#: region algorithms form must stay finite (1e300 coordinates used to be reported as a
#: "zero-area polygon", issue 26 item 10).
MAX_COORD = 1e100
#: Default range accuracy relative to the scene's diameter (``range_acc: null``).
RANGE_ACC_REL = 1e-6
#: Default normal accuracy in degrees.
NORMAL_ACC_DEG = 0.01


class SceneError(ValueError):
    """Invalid scene input.  The message names the offending element and says why."""


# ---------------------------------------------------------------------------------------------
# small helpers
# ---------------------------------------------------------------------------------------------


def _is_number(v: Any) -> bool:
    return isinstance(v, numbers.Real) and not isinstance(v, (bool, np.bool_))


def _fmt(v: float) -> str:
    return f"{float(v):.10g}"


def _fmt_pt(x: float, y: float) -> str:
    x, y = to_world_point(x, y)  # local-frame validation names world coordinates
    return f"({_fmt(x)}, {_fmt(y)})"


def _short(v: Any, limit: int = 60) -> str:
    r = repr(v)
    return r if len(r) <= limit else r[: limit - 3] + "..."


def _jsonable(v: Any) -> Any:
    """Deep copy into plain JSON-style containers (tuples/arrays -> lists, numpy -> python)."""
    if isinstance(v, Mapping):
        return {k: _jsonable(x) for k, x in v.items()}
    if isinstance(v, np.ndarray):
        return _jsonable(v.tolist())
    if isinstance(v, (list, tuple)):
        return [_jsonable(x) for x in v]
    if isinstance(v, np.generic):
        return v.item()
    return copy.deepcopy(v)


def _readonly(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


def _signed_area(pts: np.ndarray) -> float:
    """Shoelace area of the ring, computed about the vertices' mean (an uncentred sum loses
    every digit of a small polygon far from the origin)."""
    c = pts - pts.mean(axis=0)
    x, y = c[:, 0], c[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def _polygonal(g: BaseGeometry) -> Polygon | MultiPolygon:
    """Keep only the areal part of a shapely result; empty -> ``Polygon()``
    (:func:`geometry._shapes.areal`: no float-noise sliver is dropped here)."""
    return areal(g)


def _witness(g: BaseGeometry, fallback: BaseGeometry) -> tuple[float, float]:
    """A point of ``g`` (or of ``fallback`` if ``g`` is empty) for error messages."""
    src = g if not g.is_empty else fallback
    p = src.representative_point() if not src.is_empty else Point(0.0, 0.0)
    return p.x, p.y


_REASON_RE = re.compile(r"^(?P<what>[^\[]+)\[(?P<x>\S+) (?P<y>\S+)\]$")


def _parse_points(value: Any, where: str, *, allow_point: bool = False) -> np.ndarray:
    """Validate a JSON vertex list and return a CCW-normalised read-only ``(N, 2)`` array.

    With ``allow_point`` a single vertex ``[[x, y]]`` is accepted and returned as ``(1, 2)``.
    """
    if not isinstance(value, (list, tuple)):
        raise SceneError(f"{where}: expected a list of [x, y] vertices, got {_short(value)}")
    pts = []
    for i, v in enumerate(value):
        if not isinstance(v, (list, tuple)) or len(v) != 2:
            raise SceneError(f"{where}[{i}]: expected an [x, y] pair, got {_short(v)}")
        for c in v:
            if not _is_number(c):
                raise SceneError(f"{where}[{i}]: coordinates must be numbers, got {_short(c)}")
            if not math.isfinite(c):
                raise SceneError(f"{where}[{i}]: non-finite coordinate {c!r}")
            if abs(c) > MAX_COORD:
                raise SceneError(
                    f"{where}[{i}]: coordinate {c!r} is beyond +-{MAX_COORD:g}: products of "
                    "such coordinates (areas, cross products) overflow double precision"
                )
        pts.append((float(v[0]), float(v[1])))
    n = len(pts)
    if allow_point and n == 1:
        return _readonly(np.asarray(pts, dtype=np.float64).reshape(1, 2))
    if n < 3:
        hint = ", or a single point [[x, y]]" if allow_point else ""
        raise SceneError(f"{where}: a polygon needs at least 3 vertices{hint}; got {n}")
    a = np.asarray(pts, dtype=np.float64)
    for i in range(n):
        j = (i + 1) % n
        if a[i, 0] == a[j, 0] and a[i, 1] == a[j, 1]:
            if j == 0:
                raise SceneError(
                    f"{where}: the last vertex repeats the first at {_fmt_pt(*a[0])} "
                    "(do not close the ring)"
                )
            raise SceneError(
                f"{where}: repeated consecutive vertices [{i}] and [{j}] at {_fmt_pt(*a[i])}"
            )
    # Degenerate (collinear) polygons first: a bow-tie also has zero signed area.
    extent = float(np.ptp(a, axis=0).max())
    centred = a - a.mean(axis=0)
    sv = np.linalg.svd(centred, compute_uv=False)
    if extent == 0.0 or sv[-1] <= 1e-12 * max(sv[0], 1e-300):
        raise SceneError(f"{where}: zero-area polygon (all vertices are collinear)")
    reason = shapely.is_valid_reason(Polygon(a))
    if reason != "Valid Geometry":
        m = _REASON_RE.match(reason)
        if m and "self-intersection" in m.group("what").lower():
            at = _fmt_pt(float(m.group("x")), float(m.group("y")))
            raise SceneError(f"{where}: self-intersecting polygon at {at}")
        if m:
            at = _fmt_pt(float(m.group("x")), float(m.group("y")))
            raise SceneError(f"{where}: invalid polygon ({m.group('what').strip()}) at {at}")
        raise SceneError(f"{where}: invalid polygon ({reason})")
    area = _signed_area(a)
    if abs(area) <= 1e-12 * extent * extent:
        raise SceneError(f"{where}: zero-area polygon")
    if area < 0:
        a = a[::-1].copy()
    return _readonly(a)


def _merge_near(a: np.ndarray, where: str, tol: float) -> np.ndarray:
    """The CCW ring ``a`` with every vertex closer than ``tol`` (``NEAR_REL * TOL_REL`` times
    the scene's diameter) to the previous kept vertex dropped (docs/DESIGN.md, "Contacts"): two
    target vertices 1e-9 D apart made an edge whose direction is rounding noise, and the region
    algorithms took it for a real edge (issue 26 item 1).  Raises ``SceneError`` when
    fewer than 3 vertices remain."""
    keep = [0]
    for i in range(1, len(a)):
        if np.abs(a[i] - a[keep[-1]]).max() > tol:
            keep.append(i)
    while len(keep) > 1 and np.abs(a[keep[-1]] - a[keep[0]]).max() <= tol:
        keep.pop()
    if len(keep) == len(a):
        return a
    if len(keep) < 3:
        raise SceneError(f"{where}: fewer than 3 vertices more than {tol:.3g} apart")
    return _readonly(a[keep].copy())


# ---------------------------------------------------------------------------------------------
# sensor
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class SensorSpec:
    """The point-and-shoot sensor (paper sections 2 and 4).

    Attributes:
        fov_deg: field of view in degrees, in (0, 360].  360 = omnidirectional.
        max_range: maximum sensing distance in scene units, or ``None`` for unlimited.
        eps_pos: positional uncertainty of the placement (radius of the epsilon-disc, scene
            units), >= 0.
        eps_aim_deg: directional (aim) uncertainty in degrees, in [0, 180).
        range_acc: accuracy of a distance reading (scene units, >= 0): a reading is within
            ``range_acc`` of the true distance along the beam.  ``None`` (default) means
            ``1e-6 * scene.diameter`` (:attr:`Scene.range_acc`), far above the rounding of
            any input written with 7 significant digits.
        normal_acc_deg: accuracy of a surface-normal reading in degrees, in [0, 90); default
            0.01.  Two target edges whose readings can agree within these bounds are
            confusable (paper 5.1/5.2; docs/DESIGN.md, "Sensor accuracy").
    """

    fov_deg: float = 360.0
    max_range: float | None = None
    eps_pos: float = 0.0
    eps_aim_deg: float = 0.0
    range_acc: float | None = None
    normal_acc_deg: float = NORMAL_ACC_DEG

    def __post_init__(self) -> None:
        def num(name: str, v: Any) -> float:
            if not _is_number(v):
                raise SceneError(f"sensor.{name}: must be a number, got {_short(v)}")
            if not math.isfinite(v):
                raise SceneError(f"sensor.{name}: must be finite, got {v!r}")
            return float(v)

        fov = num("fov_deg", self.fov_deg)
        if not 0.0 < fov <= 360.0:
            raise SceneError(f"sensor.fov_deg: must be in (0, 360], got {self.fov_deg!r}")
        rng = self.max_range
        if rng is not None:
            rng = num("max_range", rng)
            if rng <= 0.0:
                raise SceneError(f"sensor.max_range: must be > 0 or null, got {self.max_range!r}")
        eps = num("eps_pos", self.eps_pos)
        if eps < 0.0:
            raise SceneError(f"sensor.eps_pos: must be >= 0, got {self.eps_pos!r}")
        aim = num("eps_aim_deg", self.eps_aim_deg)
        if not 0.0 <= aim < 180.0:
            raise SceneError(
                f"sensor.eps_aim_deg: must be in [0, 180) (an aim error of 180 degrees or more "
                f"means any direction), got {self.eps_aim_deg!r}"
            )
        racc = self.range_acc
        if racc is not None:
            racc = num("range_acc", racc)
            if racc < 0.0:
                raise SceneError(f"sensor.range_acc: must be >= 0 or null, got {self.range_acc!r}")
        nacc = num("normal_acc_deg", self.normal_acc_deg)
        if not 0.0 <= nacc < 90.0:
            raise SceneError(
                f"sensor.normal_acc_deg: must be in [0, 90), got {self.normal_acc_deg!r}"
            )
        object.__setattr__(self, "range_acc", racc)
        object.__setattr__(self, "normal_acc_deg", nacc)
        object.__setattr__(self, "fov_deg", fov)
        object.__setattr__(self, "max_range", rng)
        object.__setattr__(self, "eps_pos", eps)
        object.__setattr__(self, "eps_aim_deg", aim)

    @property
    def fov(self) -> float:
        """Field of view in radians."""
        return math.radians(self.fov_deg)

    @property
    def eps_aim(self) -> float:
        """Directional (aim) uncertainty in radians."""
        return math.radians(self.eps_aim_deg)

    @property
    def normal_acc(self) -> float:
        """Normal-reading accuracy in radians."""
        return math.radians(self.normal_acc_deg)

    @classmethod
    def from_dict(cls, d: Any) -> SensorSpec:
        """Build from the JSON ``sensor`` object (every key optional)."""
        if d is None:
            return cls()
        if not isinstance(d, Mapping):
            raise SceneError(f"sensor: expected an object, got {_short(d)}")
        for k in d:
            if k not in SENSOR_KEYS:
                raise SceneError(f"sensor: unknown key {k!r} (allowed: {', '.join(SENSOR_KEYS)})")
        return cls(**dict(d))

    def to_dict(self) -> dict[str, Any]:
        """All fields as a JSON-style dictionary."""
        return {
            "fov_deg": self.fov_deg,
            "max_range": self.max_range,
            "eps_pos": self.eps_pos,
            "eps_aim_deg": self.eps_aim_deg,
            "range_acc": self.range_acc,
            "normal_acc_deg": self.normal_acc_deg,
        }


# ---------------------------------------------------------------------------------------------
# scene
# ---------------------------------------------------------------------------------------------


def _scene_from_data(data: dict[str, Any]) -> Scene:  # pickle support
    return Scene.from_dict(data)


class Scene:
    """A validated planar scene (immutable).

    Build with :meth:`load`, :meth:`from_dict` or the keyword constructor.  All coordinates
    are world-frame scene units except ``target`` (target frame, reference point at the
    origin).  Attributes (read-only):

    Attributes:
        name: scene name.
        bounds: ``(N, 2)`` float64, the walls, counter-clockwise.
        obstacles: tuple of ``(Ni, 2)`` float64 arrays, each counter-clockwise.
        target: ``(M, 2)`` float64 target polygon in its own frame, counter-clockwise, the
            reference point ``(0, 0)`` anywhere (inside, on the outline or outside).
        goal: ``(K, 2)`` float64 goal region G (CCW polygon); ``K == 1`` means a point.
        failure: ``(K, 2)`` float64 failure region H, same convention.
        sensor: the :class:`SensorSpec` (defaults if the JSON has no ``sensor``).
        start: optional robot start pose ``(x, y, theta)``, theta in radians.

    Validation (raises :class:`SceneError`): every polygon is simple, has >= 3 vertices, no
    repeated consecutive vertices, positive area, finite numbers; obstacles lie inside the
    bounds; when the target's reference point is inside the target, G and H lie in the free space
    and do not overlap; no obstacle or wall meets CH(A ⊕ G) or CH(A ⊕ H) at orientation 0
    (the paper's assumption, section 3.1.1); ``start`` lies in the free space.
    """

    name: str
    bounds: np.ndarray
    obstacles: tuple[np.ndarray, ...]
    target: np.ndarray
    goal: np.ndarray
    failure: np.ndarray
    sensor: SensorSpec
    start: tuple[float, float, float] | None

    def __init__(
        self,
        *,
        name: str,
        bounds: Any,
        obstacles: Any = (),
        target: Any,
        goal: Any,
        failure: Any,
        sensor: SensorSpec | Mapping[str, Any] | None = None,
        start: Any = None,
    ) -> None:
        """Keyword constructor taking array-likes; equivalent to :meth:`from_dict`."""
        d: dict[str, Any] = {
            "name": name,
            "bounds": bounds,
            "obstacles": list(obstacles) if isinstance(obstacles, tuple) else obstacles,
            "target": target,
            "goal": goal,
            "failure": failure,
        }
        if sensor is not None:
            d["sensor"] = sensor.to_dict() if isinstance(sensor, SensorSpec) else sensor
        if start is not None:
            d["start"] = start
        self._setup(_jsonable(d))

    # -- construction -------------------------------------------------------------------------

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Scene:
        """Validate a scene dictionary (the JSON object) and build the scene."""
        if not isinstance(d, Mapping):
            raise SceneError(f"scene: expected a JSON object, got {_short(d)}")
        obj = cls.__new__(cls)
        obj._setup(_jsonable(d))
        return obj

    @classmethod
    def load(cls, path: str | PathLike[str]) -> Scene:
        """Read a JSON scene file.  Errors are prefixed with the file name."""
        p = Path(path)
        text = p.read_text(encoding="utf-8")
        try:
            d = json.loads(text)
        except json.JSONDecodeError as e:
            raise SceneError(f"{p}: invalid JSON: {e}") from e
        try:
            return cls.from_dict(d)
        except SceneError as e:
            raise SceneError(f"{p}: {e}") from e

    def to_dict(self) -> dict[str, Any]:
        """The scene as a JSON-style dictionary, exactly as it was given (a fresh copy)."""
        return copy.deepcopy(self._data)

    def save(self, path: str | PathLike[str]) -> None:
        """Write the scene as JSON (``load(save(s)) == s``) in the layout of :meth:`to_json`."""
        Path(path).write_text(self.to_json(), encoding="utf-8")

    def to_json(self) -> str:
        """The scene as JSON text (what :meth:`save` writes), indented, with every list of
        numbers -- a vertex ``[x, y]``, a pose, a sensor range -- on one line, so a polygon
        reads one vertex per line.  Floats are written as ``repr`` (round trips are exact)."""

        def dump(v: Any, pad: str) -> str:
            inner = pad + "  "
            if isinstance(v, Mapping) and v:
                items = (f"{inner}{json.dumps(k)}: {dump(x, inner)}" for k, x in v.items())
                return "{\n" + ",\n".join(items) + "\n" + pad + "}"
            if isinstance(v, (list, tuple)) and any(
                isinstance(x, (list, tuple, Mapping)) for x in v
            ):
                return "[\n" + ",\n".join(inner + dump(x, inner) for x in v) + "\n" + pad + "]"
            return json.dumps(v)

        return dump(self._data, "") + "\n"

    def replace(self, **changes: Any) -> Scene:
        """A new validated scene with some JSON keys replaced (``None`` removes sensor/start)."""
        d = self.to_dict()
        for k, v in changes.items():
            if v is None and k in OPTIONAL_KEYS:
                d.pop(k, None)
            elif isinstance(v, SensorSpec):
                d[k] = v.to_dict()
            else:
                d[k] = v
        return Scene.from_dict(d)

    def _setup(self, d: dict[str, Any]) -> None:
        for k in d:
            if k not in ALLOWED_KEYS:
                raise SceneError(f"unknown key {k!r} (allowed: {', '.join(ALLOWED_KEYS)})")
        for k in REQUIRED_KEYS:
            if k not in d:
                raise SceneError(f"missing required key {k!r}")
        set_ = functools.partial(object.__setattr__, self)
        set_("_data", d)

        name = d["name"]
        if not isinstance(name, str):
            raise SceneError(f"name: expected a string, got {_short(name)}")
        bounds = _parse_points(d["bounds"], "bounds")
        obs_in = d["obstacles"]
        if not isinstance(obs_in, list):
            raise SceneError(f"obstacles: expected a list of polygons, got {_short(obs_in)}")
        obstacles = tuple(_parse_points(o, f"obstacles[{i}]") for i, o in enumerate(obs_in))
        diam = float(np.hypot(*np.ptp(bounds, axis=0)))
        target = _merge_near(
            _parse_points(d["target"], "target"), "target", NEAR_REL * TOL_REL * diam
        )
        goal = _parse_points(d["goal"], "goal", allow_point=True)
        failure = _parse_points(d["failure"], "failure", allow_point=True)
        sensor = SensorSpec.from_dict(d.get("sensor"))
        start_in = d.get("start")
        start: tuple[float, float, float] | None = None
        if start_in is not None:
            if (
                not isinstance(start_in, list)
                or len(start_in) != 3
                or not all(_is_number(c) for c in start_in)
            ):
                raise SceneError(
                    f"start: expected [x, y, theta] (theta in radians), got {_short(start_in)}"
                )
            if not all(math.isfinite(c) for c in start_in):
                raise SceneError(f"start: non-finite value in {start_in!r}")
            if abs(start_in[2]) > 2 * math.pi:
                raise SceneError(
                    f"start[2] (theta): {start_in[2]!r} is outside [-2 pi, 2 pi]; theta is in "
                    f"radians (did you mean {start_in[2]!r} degrees = "
                    f"{math.radians(start_in[2]):.6g} rad?)"
                )
            start = (float(start_in[0]), float(start_in[1]), float(start_in[2]))

        set_("name", name)
        set_("bounds", bounds)
        set_("obstacles", obstacles)
        set_("target", target)
        set_("goal", goal)
        set_("failure", failure)
        set_("sensor", sensor)
        set_("start", start)
        self._validate_geometry()

    def _validate_geometry(self) -> None:
        if not self.frame.identity:
            # validate the exact image in the local frame (centred, unit size): the same
            # relative tolerances then mean the same thing at any offset and any scale
            _ = self.local
            return
        tol = self.tol
        bpoly = self.bounds_geom
        for i, o in enumerate(self.obstacles):
            op = Polygon(o)
            if not self._bounds_grown.covers(op):
                x, y = _witness(op.difference(bpoly), op)
                raise SceneError(
                    f"obstacles[{i}]: lies (partly) outside the bounds (walls), at {_fmt_pt(x, y)}"
                )
        # The reference point may lie anywhere (inside, on the outline, outside: an L-shaped
        # robot framed at its inner corner, a footprint framed at its rear axle).  Inside,
        # G and H are sets of points of the target and must lie in the free space; else
        # only the target's swept hull CH(A ⊕ G) must be clear (checked below), which is
        # all the paper's assumption asks.
        ref_inside = Polygon(self.target).contains(Point(0.0, 0.0))
        for which in ("goal", "failure") if ref_inside else ():
            g = self.region(which)
            v = self._violation(g)
            if v is not None:
                kind, x, y = v
                raise SceneError(
                    f"{which}: not inside the free space (bounds minus obstacles): "
                    f"meets {kind} at {_fmt_pt(x, y)}"
                )
        g, h = self.goal_geom, self.failure_geom
        if isinstance(g, Polygon) and isinstance(h, Polygon):
            inter = g.intersection(h)
            overlap = inter.area > tol * self.diameter
        elif isinstance(g, Point) and isinstance(h, Point):
            inter = g
            overlap = g.distance(h) <= tol
        else:
            inter = g if isinstance(g, Point) else h
            overlap = g.covers(h) if isinstance(g, Polygon) else h.covers(g)
        if overlap:
            x, y = _witness(inter, g)
            raise SceneError(
                f"goal and failure overlap at {_fmt_pt(x, y)}: a target there would be in both "
                "G and H, so recognition is impossible"
            )
        for which, sym in (("goal", "G"), ("failure", "H")):
            self.check_clear(
                self.swept_hull(which, 0.0),
                f"{which}: CH(A ⊕ {sym}) (convex hull of the target's swept area at orientation 0)",
            )
        if self.start is not None:
            # ``start`` is the sensor robot's pose, not the target's: its point must lie in
            # the free space whatever the target's shape or reference point (issue 25 item
            # 5: the target's footprint was placed there and valid scenes were rejected).
            # The scene does not know the robot's footprint; callers that do check it.
            v = self._violation(Point(self.start[0], self.start[1]))
            if v is not None:
                raise SceneError(
                    f"start: {_fmt_pt(self.start[0], self.start[1])} is not in the free space "
                    f"(bounds minus obstacles): meets {v[0]} (start is the sensor robot's pose)"
                )

    # -- read-only-ness, equality, pickling ------------------------------------------------------

    def __setattr__(self, key: str, value: Any) -> None:
        raise AttributeError(f"Scene is read-only (cannot set {key!r}); use Scene.replace()")

    def __delattr__(self, key: str) -> None:
        raise AttributeError(f"Scene is read-only (cannot delete {key!r})")

    def __reduce__(self) -> tuple[Any, tuple[dict[str, Any]]]:
        return (_scene_from_data, (self._data,))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Scene):
            return NotImplemented
        return self._data == other._data

    def __hash__(self) -> int:
        return hash((self.name, self.bounds.tobytes(), self.target.tobytes(), len(self.obstacles)))

    def __repr__(self) -> str:
        return (
            f"Scene(name={self.name!r}, bounds={len(self.bounds)} vertices, "
            f"obstacles={len(self.obstacles)}, target={len(self.target)} vertices, "
            f"goal={'point' if len(self.goal) == 1 else f'{len(self.goal)} vertices'}, "
            f"failure={'point' if len(self.failure) == 1 else f'{len(self.failure)} vertices'})"
        )

    # -- derived geometry (cached) ---------------------------------------------------------------

    @functools.cached_property
    def frame(self) -> Frame:
        """The local frame of this scene (:mod:`geometry._frame`): ``local = (world - offset)
        / scale`` with ``scale`` a power of two near the diameter and the offset near the
        centre of the bounds.  The region functions compute in it."""
        return frame_params(self.bounds)

    @functools.cached_property
    def local(self) -> Scene:
        """This scene mapped into :attr:`frame` (validated there; an identity frame gives
        the scene itself).  Error messages of its validation name world coordinates."""
        fr = self.frame
        if fr.identity:
            return self
        sensor = self.sensor.to_dict()
        for k in _LENGTH_SENSOR_KEYS:
            if sensor.get(k) is not None:
                sensor[k] = sensor[k] / fr.scale
        d: dict[str, Any] = {
            "name": self.name,
            "bounds": fr.points(self.bounds).tolist(),
            "obstacles": [fr.points(o).tolist() for o in self.obstacles],
            "target": (self.target / fr.scale).tolist(),
            "goal": fr.points(self.goal).tolist(),
            "failure": fr.points(self.failure).tolist(),
            "sensor": sensor,
        }
        if self.start is not None:
            d["start"] = list(fr.pose(self.start))
        obj = Scene.__new__(Scene)
        obj.__dict__["frame"] = IDENTITY
        with world_messages(fr):
            obj._setup(d)
        return obj

    @functools.cached_property
    def diameter(self) -> float:
        """Diagonal of the bounds' axis-aligned bounding box (scene units)."""
        lo, hi = self.bounds.min(axis=0), self.bounds.max(axis=0)
        return float(math.hypot(*(hi - lo)))

    @property
    def range_acc(self) -> float:
        """The sensor's range accuracy (scene units): ``sensor.range_acc``, or
        ``RANGE_ACC_REL * diameter`` when that is ``None``."""
        r = self.sensor.range_acc
        return RANGE_ACC_REL * self.diameter if r is None else r

    @property
    def tol(self) -> float:
        """Absolute geometric tolerance, ``TOL_REL * diameter`` (scene units)."""
        return TOL_REL * self.diameter

    @functools.cached_property
    def target_radius(self) -> float:
        """Largest distance from the reference point to a target vertex (paper 3.1.2)."""
        return float(np.hypot(self.target[:, 0], self.target[:, 1]).max())

    @functools.cached_property
    def bounds_geom(self) -> Polygon:
        """The bounds as a shapely Polygon (world frame)."""
        return Polygon(self.bounds)

    @functools.cached_property
    def obstacle_geoms(self) -> tuple[Polygon, ...]:
        """Each obstacle as a shapely Polygon, in input order."""
        return tuple(Polygon(o) for o in self.obstacles)

    @functools.cached_property
    def obstacle_union(self) -> Polygon | MultiPolygon:
        """Union of all obstacles (touching/overlapping ones merged); ``Polygon()`` if none."""
        if not self.obstacles:
            return Polygon()
        return _polygonal(shapely.union_all(self.obstacle_geoms))

    @functools.cached_property
    def free_space(self) -> Polygon | MultiPolygon:
        """Bounds minus the obstacle union (a Polygon, or a MultiPolygon if disconnected).

        GEOS's floating overlay can keep a sliver obstacle flush on a wall as free space
        (it judged the obstacle both inside and outside the bounds, issue 26 item 7); when
        an obstacle's interior point is in the floating result, the snap-rounding overlay
        on the grid :attr:`snap` is used instead (docs/DESIGN.md, "Contacts")."""
        if self.obstacle_union.is_empty:
            return self.bounds_geom
        fs = _polygonal(self.bounds_geom.difference(self.obstacle_union))
        inner = np.array([o.representative_point().coords[0] for o in self.obstacle_geoms])
        if fs.is_valid and not shapely.contains_xy(fs, inner[:, 0], inner[:, 1]).any():
            return fs
        return _polygonal(
            shapely.difference(self.bounds_geom, self.obstacle_union, grid_size=self.snap)
        )

    @functools.cached_property
    def snap(self) -> float:
        """Grid of the snap-rounded overlays that build :attr:`obstacle_union` and
        :attr:`free_space` (``SNAP_REL = 1e-13`` of the diameter; docs/DESIGN.md, "Contacts").
        GEOS's floating overlay can put a flush sliver obstacle both inside and outside
        a wall at once (issue 26 item 7); the snap-rounding overlay cannot."""
        return snap_grid(self.bounds)

    @functools.cached_property
    def goal_geom(self) -> Polygon | Point:
        """G as a shapely Polygon, or a Point if G is a single point."""
        return Point(self.goal[0]) if len(self.goal) == 1 else Polygon(self.goal)

    @functools.cached_property
    def failure_geom(self) -> Polygon | Point:
        """H as a shapely Polygon, or a Point if H is a single point."""
        return Point(self.failure[0]) if len(self.failure) == 1 else Polygon(self.failure)

    @functools.cached_property
    def _bounds_grown(self) -> Polygon:
        g = self.bounds_geom.buffer(self.tol, join_style="mitre")
        shapely.prepare(g)
        return g

    @functools.cached_property
    def _boundary_lines(self) -> BaseGeometry:
        rings = shapely.get_rings(np.asarray([self.bounds_geom, *self.obstacle_geoms]))
        g = shapely.MultiLineString([np.asarray(r.coords) for r in rings])
        shapely.prepare(g)
        return g

    @functools.cached_property
    def _obstacles_shrunk(self) -> BaseGeometry:
        g = self.obstacle_union.buffer(-self.tol, join_style="mitre")
        shapely.prepare(g)
        return g

    # -- queries --------------------------------------------------------------------------------

    def region(self, which: str | Polygon | Point) -> Polygon | Point:
        """``"goal"`` -> G, ``"failure"`` -> H; a shapely Polygon/Point is returned unchanged."""
        if isinstance(which, str):
            if which == "goal":
                return self.goal_geom
            if which == "failure":
                return self.failure_geom
        elif isinstance(which, (Polygon, Point)):
            return which
        raise SceneError(
            f"region: expected 'goal', 'failure' or a shapely Polygon/Point, got {_short(which)}"
        )

    def target_at(self, x: float, y: float, theta: float = 0.0) -> Polygon:
        """The target at configuration ``(x, y, theta)`` in the world frame.

        Rotates the target by ``theta`` radians counter-clockwise about its reference point,
        then translates the reference point to ``(x, y)``.
        """
        c, s = math.cos(theta), math.sin(theta)
        t = self.target
        xs = c * t[:, 0] - s * t[:, 1] + x
        ys = s * t[:, 0] + c * t[:, 1] + y
        return Polygon(np.column_stack([xs, ys]))

    def swept_hull(self, which: str | Polygon | Point, theta: float = 0.0) -> Polygon:
        """CH(A_theta ⊕ X) = CH(A_theta) ⊕ CH(X) for X = ``region(which)`` (paper 3.1.2).

        The convex hull of the area swept by the target translating over X at fixed
        orientation ``theta`` (radians); for a point X it is the hull of the placed target.
        """
        reg = self.region(which)
        c, s = math.cos(theta), math.sin(theta)
        t = self.target
        a = np.column_stack([c * t[:, 0] - s * t[:, 1], s * t[:, 0] + c * t[:, 1]])
        if isinstance(reg, Point):
            gpts = np.array([[reg.x, reg.y]])
        else:
            gpts = np.asarray(reg.convex_hull.exterior.coords)[:-1]
        sums = (a[:, None, :] + gpts[None, :, :]).reshape(-1, 2)
        return shapely.MultiPoint(sums).convex_hull

    def _violation(self, geom: BaseGeometry) -> tuple[str, float, float] | None:
        """``(what, x, y)`` if ``geom`` meets an obstacle interior or leaves the bounds."""
        if geom.is_empty:
            return None
        if not self._bounds_grown.covers(geom):
            x, y = _witness(geom.difference(self.bounds_geom), geom)
            return ("the bounds (walls)", x, y)
        if not self._obstacles_shrunk.is_empty and self._obstacles_shrunk.intersects(geom):
            tol = self.tol
            for i, op in enumerate(self.obstacle_geoms):
                shrunk = op.buffer(-tol, join_style="mitre")
                if shrunk.intersects(geom):
                    x, y = _witness(shrunk.intersection(geom), geom)
                    return (f"obstacles[{i}]", x, y)
            x, y = _witness(self._obstacles_shrunk.intersection(geom), geom)
            return ("the obstacles", x, y)
        # an obstacle (or a slit of the walls) thinner than 2 tol vanishes when shrunk, yet
        # its boundary can run deep into ``geom``: it overlaps by more than tol too (fuzz
        # contact seed 101082: a needle 1e-9 D wide 3.5e-3 D inside the target's hull)
        core = shapely.buffer(geom, -self.tol, join_style="mitre")
        if not core.is_empty and self._boundary_lines.intersects(core):
            for i, op in enumerate(self.obstacle_geoms):
                if op.boundary.intersects(core):
                    x, y = _witness(op.boundary.intersection(core), geom)
                    return (f"obstacles[{i}]", x, y)
            x, y = _witness(self.bounds_geom.exterior.intersection(core), geom)
            return ("the bounds (walls)", x, y)
        return None

    def check_clear(self, hull: BaseGeometry, what: str) -> None:
        """Raise :class:`SceneError` if an obstacle or a wall meets the convex set ``hull``.

        ``hull`` (world frame) is typically the convex hull of the target's (swept) area for
        some orientation; region functions call this at query time.  "Meets" means that
        ``hull`` intersects an obstacle's interior, or pokes outside the bounds, by more than
        ``scene.tol``; touching is fine.  The message starts with ``what`` and says that the
        paper's assumption (Briggs & Donald 3.1.1) is violated.
        """
        v = self._violation(hull)
        if v is not None:
            kind, x, y = v
            raise SceneError(f"{what}: meets {kind} at {_fmt_pt(x, y)}; {PAPER_ASSUMPTION}")

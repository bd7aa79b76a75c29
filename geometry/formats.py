"""Scene import and export in the formats floor plans come in: GeoJSON, shapely/WKT,
and obstacle maps given as polygons with holes.

Every importer builds a validated :class:`geometry.Scene` (the pinned JSON format of
:mod:`geometry.scene`); every error is a :class:`FormatError` (a ``SceneError``, hence a
``ValueError``) that names the offending feature or role and says what is wrong.

Coordinates
-----------
All coordinates are planar scene units (e.g. metres of a floor plan); nothing is
reprojected.  (RFC 7946 GeoJSON is nominally WGS84 longitude/latitude; floor plans
exported from CAD/GIS tools in a local metric CRS are read as they are.)  A third
coordinate (elevation) is dropped.

GeoJSON
-------
A ``FeatureCollection`` whose features carry ``properties.role``:

* ``"bounds"``   -- exactly one Polygon: the walls.  Its holes become obstacles.
* ``"obstacle"`` -- Polygon or MultiPolygon, any number.  Holes are allowed: the obstacle
  is split, along its own triangulation edges (no new vertices), into simple polygons
  whose union is exactly the polygon with holes (the scene format has simple obstacles).
* ``"target"``   -- exactly one Polygon without holes, in the *target frame* (its
  reference point at the origin), unless ``properties.origin = [x, y]`` gives the
  reference point's world position; then the polygon is in world coordinates and
  is translated by ``-origin``.
* ``"goal"``, ``"failure"`` -- exactly one each: a Polygon without holes, or a Point.
* ``"start"``    -- at most one Point; ``properties.theta`` (radians, default 0).

Top-level (foreign) members ``"name"`` (string) and ``"sensor"`` (the scene's sensor
object) are optional.  :func:`scene_to_geojson` writes this format with exterior rings
counter-clockwise (RFC 7946 right-hand rule), closed rings, and ``"frame": "target"`` on
the target feature, so ``scene_from_geojson(scene_to_geojson(s))`` rebuilds ``s``.

WKT
---
A text file of ``role: value`` lines (blank lines and ``#`` comments ignored): ``name:``
free text; ``bounds:``, ``target:``, ``goal:``, ``failure:`` one WKT geometry each;
``obstacles:`` a WKT Polygon/MultiPolygon/GeometryCollection of polygons (the line may
repeat); ``start: x y theta`` (theta radians); ``sensor:`` a JSON object.
"""

from __future__ import annotations

import json
import math
import re
import warnings
from collections.abc import Iterable, Mapping, Sequence
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from shapely.geometry import MultiPolygon, Point, Polygon, shape

from .scene import Scene, SceneError

__all__ = [
    "FormatError",
    "ROLES",
    "SCENE_SUFFIXES",
    "load_scene_file",
    "save_scene_file",
    "scene_from_data",
    "scene_from_geojson",
    "scene_from_obstacle_map",
    "scene_from_shapely",
    "scene_from_text",
    "scene_from_wkt",
    "scene_to_geojson",
    "scene_to_shapely",
    "scene_to_text",
    "scene_to_wkt",
    "simple_pieces",
]

#: Feature roles understood by :func:`scene_from_geojson`.
ROLES = ("bounds", "obstacle", "target", "goal", "failure", "start")


class FormatError(SceneError):
    """Malformed map input; the message names the feature (index and role) or the field."""


# ------------------------------------------------------------------------------------------
# geometry helpers
# ------------------------------------------------------------------------------------------


def _ring(coords: Any) -> list[list[float]]:
    """Ring coordinates as ``[[x, y], ...]`` without the closing vertex and without z."""
    c = np.asarray(coords, dtype=float)[:, :2]
    if len(c) > 1 and np.array_equal(c[0], c[-1]):
        c = c[:-1]
    return [[float(x), float(y)] for x, y in c]


def _closed(pts: np.ndarray) -> list[list[float]]:
    pts = np.asarray(pts, dtype=float)
    return [[float(x), float(y)] for x, y in np.vstack([pts, pts[:1]])]


def _check_polygon(g: Any, where: str, *, holes: bool) -> Polygon:
    """``g`` must be a valid, non-empty Polygon (with holes only if ``holes``)."""
    if not isinstance(g, Polygon):
        raise FormatError(f"{where}: expected a Polygon, got {g.geom_type}")
    if g.is_empty:
        raise FormatError(f"{where}: empty polygon")
    if g.has_z:
        g = shapely.force_2d(g)
    if not holes and len(g.interiors):
        raise FormatError(f"{where}: a polygon with {len(g.interiors)} hole(s) is not allowed here")
    if not g.is_valid:
        raise FormatError(f"{where}: invalid polygon ({shapely.is_valid_reason(g)})")
    return g


def simple_pieces(poly: Polygon) -> list[Polygon]:
    """Split a polygon with holes into simple polygons (no holes) whose union is ``poly``.

    The pieces are unions of triangles of the constrained Delaunay triangulation of
    ``poly``, which uses only its own vertices: the pieces share edges exactly and no
    vertex is computed (no float noise, no slits).  Triangles are grouped by vertical
    strips cut at an interior point of each hole; a group whose union still has a hole
    is emitted triangle by triangle.  A polygon without holes is returned as it is.
    """
    if not len(poly.interiors):
        return [poly]
    tris = shapely.get_parts(shapely.constrained_delaunay_triangles(poly))
    tris = tris[shapely.area(tris) > 0.0]
    cuts = np.sort([shapely.get_x(shapely.point_on_surface(Polygon(h))) for h in poly.interiors])
    cx = shapely.get_x(shapely.centroid(tris))
    group = np.searchsorted(cuts, cx)
    out: list[Polygon] = []
    for k in np.unique(group):
        members = tris[group == k]
        for part in shapely.get_parts(shapely.union_all(members)):
            if not isinstance(part, Polygon) or part.is_empty:
                continue
            if len(part.interiors) == 0:
                out.append(part)
            else:  # pragma: no cover - rare: a hole inside one strip's group
                shapely.prepare(part)
                out.extend(members[shapely.covers(part, members)])
    return out


def _obstacle_rings(g: Any, where: str) -> list[list[list[float]]]:
    """Simple obstacle rings of a Polygon/MultiPolygon (holes split by :func:`simple_pieces`)."""
    if isinstance(g, MultiPolygon):
        parts = list(g.geoms)
    elif isinstance(g, Polygon):
        parts = [g]
    else:
        raise FormatError(f"{where}: expected a Polygon or MultiPolygon, got {g.geom_type}")
    rings = []
    for j, p in enumerate(parts):
        w = where if len(parts) == 1 else f"{where} part {j}"
        p = _check_polygon(p, w, holes=True)
        for piece in simple_pieces(p):
            rings.append(_ring(piece.exterior.coords))
    return rings


def _region_coords(g: Any, where: str) -> list[list[float]]:
    """Goal/failure: a Polygon without holes or a Point."""
    if isinstance(g, Point):
        if g.is_empty:
            raise FormatError(f"{where}: empty point")
        return [[float(g.x), float(g.y)]]
    if not isinstance(g, Polygon):
        raise FormatError(f"{where}: expected a Polygon or a Point, got {g.geom_type}")
    return _ring(_check_polygon(g, where, holes=False).exterior.coords)


_OBST_RE = re.compile(r"obstacles\[(\d+)\]")


def _build(data: dict[str, Any], obstacle_src: Sequence[str], prefix: str = "") -> Scene:
    """``Scene.from_dict`` with ``obstacles[i]`` in error messages replaced by the source
    (feature) that obstacle ``i`` came from."""
    try:
        return Scene.from_dict(data)
    except SceneError as e:
        msg = str(e)

        def sub(m: re.Match[str]) -> str:
            i = int(m.group(1))
            return obstacle_src[i] if i < len(obstacle_src) else m.group(0)

        raise FormatError(prefix + _OBST_RE.sub(sub, msg)) from e


# ------------------------------------------------------------------------------------------
# GeoJSON
# ------------------------------------------------------------------------------------------


def scene_from_geojson(
    data: Mapping[str, Any] | str | PathLike[str], *, name: str | None = None
) -> Scene:
    """Build a scene from a GeoJSON FeatureCollection (a dict, JSON text or a file path).

    See the module docstring for the roles.  ``name`` overrides the collection's
    ``"name"`` member (default ``"imported"``, or the file stem for a path).
    """
    default_name = "imported"
    is_text = isinstance(data, str) and data.lstrip().startswith("{")
    if isinstance(data, (str, PathLike)) and not is_text:
        p = Path(data)
        default_name = p.stem
        try:
            data = json.loads(p.read_text(encoding="utf-8"))
        except json.JSONDecodeError as e:
            raise FormatError(f"{p}: invalid JSON: {e}") from e
    elif isinstance(data, str):
        try:
            data = json.loads(data)
        except json.JSONDecodeError as e:
            raise FormatError(f"invalid JSON: {e}") from e
    if not isinstance(data, Mapping) or data.get("type") != "FeatureCollection":
        got = data.get("type") if isinstance(data, Mapping) else type(data).__name__
        raise FormatError(f"expected a GeoJSON FeatureCollection, got {got!r}")
    feats = data.get("features")
    if not isinstance(feats, list):
        raise FormatError("FeatureCollection: 'features' must be a list")

    found: dict[str, list[tuple[int, Any, Mapping[str, Any]]]] = {r: [] for r in ROLES}
    for i, f in enumerate(feats):
        where = f"features[{i}]"
        if not isinstance(f, Mapping) or f.get("type") != "Feature":
            raise FormatError(f"{where}: expected a GeoJSON Feature object")
        props = f.get("properties") or {}
        if not isinstance(props, Mapping):
            raise FormatError(f"{where}: 'properties' must be an object")
        role = props.get("role")
        if role is None:
            raise FormatError(f"{where}: missing properties.role (one of {', '.join(ROLES)})")
        if role not in ROLES:
            raise FormatError(f"{where}: unknown role {role!r} (one of {', '.join(ROLES)})")
        where = f"features[{i}] (role {role!r})"
        gj = f.get("geometry")
        if gj is None:
            raise FormatError(f"{where}: missing geometry")
        try:
            with warnings.catch_warnings():  # NaN coordinates: reported below
                warnings.simplefilter("ignore", RuntimeWarning)
                g = shape(gj)
        except Exception as e:  # shapely raises several types for malformed input
            raise FormatError(f"{where}: malformed geometry: {e}") from None
        if g.has_z:
            g = shapely.force_2d(g)
        c = shapely.get_coordinates(g)
        if not np.all(np.isfinite(c)):
            raise FormatError(f"{where}: non-finite coordinate")
        found[role].append((i, g, props))

    def one(role: str, optional: bool = False) -> tuple[int, Any, Mapping[str, Any]] | None:
        got = found[role]
        if len(got) > 1:
            idx = ", ".join(str(i) for i, _, _ in got)
            raise FormatError(f"features {idx}: more than one feature with role {role!r}")
        if not got:
            if optional:
                return None
            raise FormatError(f"no feature with role {role!r}")
        return got[0]

    bi, bg, _ = one("bounds")  # type: ignore[misc]
    bwhere = f"features[{bi}] (role 'bounds')"
    bpoly = _check_polygon(bg, bwhere, holes=True)
    obstacles: list[list[list[float]]] = []
    src: list[str] = []
    for k, h in enumerate(bpoly.interiors):
        obstacles.append(_ring(h.coords))
        src.append(f"{bwhere} hole {k}")
    for i, g, _ in found["obstacle"]:
        where = f"features[{i}] (role 'obstacle')"
        rings = _obstacle_rings(g, where)
        obstacles += rings
        src += [where] * len(rings)

    ti, tg, tprops = one("target")  # type: ignore[misc]
    twhere = f"features[{ti}] (role 'target')"
    tpoly = _check_polygon(tg, twhere, holes=False)
    tpts = np.asarray(_ring(tpoly.exterior.coords))
    origin = tprops.get("origin")
    if origin is not None:
        if (
            not isinstance(origin, (list, tuple))
            or len(origin) != 2
            or not all(isinstance(v, (int, float)) and math.isfinite(v) for v in origin)
        ):
            raise FormatError(f"{twhere}: properties.origin must be [x, y] numbers, got {origin!r}")
        tpts = tpts - np.asarray(origin, dtype=float)

    d: dict[str, Any] = {
        "name": name
        if name is not None
        else (data.get("name") if isinstance(data.get("name"), str) else default_name),
        "bounds": _ring(bpoly.exterior.coords),
        "obstacles": obstacles,
        "target": [[float(x), float(y)] for x, y in tpts],
    }
    for role in ("goal", "failure"):
        i, g, _ = one(role)  # type: ignore[misc]
        d[role] = _region_coords(g, f"features[{i}] (role {role!r})")
    st = one("start", optional=True)
    if st is not None:
        i, g, props = st
        where = f"features[{i}] (role 'start')"
        if not isinstance(g, Point) or g.is_empty:
            raise FormatError(f"{where}: expected a Point, got {g.geom_type}")
        theta = props.get("theta", 0.0)
        if (
            not isinstance(theta, (int, float))
            or isinstance(theta, bool)
            or not math.isfinite(theta)
        ):
            raise FormatError(f"{where}: properties.theta must be a finite number (radians)")
        d["start"] = [float(g.x), float(g.y), float(theta)]
    if data.get("sensor") is not None:
        d["sensor"] = data["sensor"]
    return _build(d, src)


def _geo_polygon(pts: np.ndarray) -> dict[str, Any]:
    return {"type": "Polygon", "coordinates": [_closed(pts)]}


def _geo_region(pts: np.ndarray) -> dict[str, Any]:
    if len(pts) == 1:
        return {"type": "Point", "coordinates": [float(pts[0, 0]), float(pts[0, 1])]}
    return _geo_polygon(pts)


def _feature(role: str, geom: dict[str, Any], **props: Any) -> dict[str, Any]:
    return {"type": "Feature", "properties": {"role": role, **props}, "geometry": geom}


def scene_to_geojson(scene: Scene) -> dict[str, Any]:
    """The scene as a GeoJSON FeatureCollection (see the module docstring).

    Rings are closed and counter-clockwise (the scene's normalised arrays); the target
    is in its own frame (``"frame": "target"``); ``start`` is a Point with ``theta``.
    """
    feats = [_feature("bounds", _geo_polygon(scene.bounds))]
    feats += [_feature("obstacle", _geo_polygon(o), index=i) for i, o in enumerate(scene.obstacles)]
    feats.append(_feature("target", _geo_polygon(scene.target), frame="target"))
    feats.append(_feature("goal", _geo_region(scene.goal)))
    feats.append(_feature("failure", _geo_region(scene.failure)))
    if scene.start is not None:
        x, y, th = scene.start
        feats.append(_feature("start", {"type": "Point", "coordinates": [x, y]}, theta=th))
    out: dict[str, Any] = {"type": "FeatureCollection", "name": scene.name}
    d = scene.to_dict()
    if "sensor" in d:
        out["sensor"] = d["sensor"]
    out["features"] = feats
    return out


# ------------------------------------------------------------------------------------------
# shapely / WKT
# ------------------------------------------------------------------------------------------


def _geom(value: Any, where: str) -> Any:
    """A shapely geometry from a geometry or a WKT string."""
    if isinstance(value, str):
        try:
            return shapely.from_wkt(value)
        except Exception as e:
            raise FormatError(f"{where}: invalid WKT: {e}") from None
    if isinstance(value, shapely.Geometry):
        return value
    raise FormatError(f"{where}: expected a shapely geometry or a WKT string, got {value!r:.60}")


def scene_from_shapely(
    *,
    bounds: Any,
    target: Any,
    goal: Any,
    failure: Any,
    obstacles: Any = (),
    name: str = "imported",
    sensor: Mapping[str, Any] | None = None,
    start: Sequence[float] | None = None,
) -> Scene:
    """Build a scene from shapely geometries or WKT strings (world frame, scene units).

    ``bounds``: a Polygon (holes become obstacles); ``obstacles``: a Polygon,
    MultiPolygon or GeometryCollection of polygons, or an iterable of such (holes
    allowed, see :func:`simple_pieces`); ``target``: a Polygon in the target frame;
    ``goal``/``failure``: a Polygon or a Point; ``start``: ``(x, y, theta)``.
    """
    bpoly = _check_polygon(_geom(bounds, "bounds"), "bounds", holes=True)
    obs_rings: list[list[list[float]]] = []
    src: list[str] = []
    for k, h in enumerate(bpoly.interiors):
        obs_rings.append(_ring(h.coords))
        src.append(f"bounds hole {k}")
    if isinstance(obstacles, (str, shapely.Geometry)):
        obstacles = [obstacles]
    for i, o in enumerate(obstacles):
        g = _geom(o, f"obstacles item {i}")
        parts = shapely.get_parts(g) if g.geom_type == "GeometryCollection" else [g]
        for j, p in enumerate(parts):
            where = f"obstacles item {i}" + (f" part {j}" if len(parts) > 1 else "")
            rings = _obstacle_rings(p, where)
            obs_rings += rings
            src += [where] * len(rings)
    tpoly = _check_polygon(_geom(target, "target"), "target", holes=False)
    d: dict[str, Any] = {
        "name": name,
        "bounds": _ring(bpoly.exterior.coords),
        "obstacles": obs_rings,
        "target": _ring(tpoly.exterior.coords),
        "goal": _region_coords(_geom(goal, "goal"), "goal"),
        "failure": _region_coords(_geom(failure, "failure"), "failure"),
    }
    if sensor is not None:
        d["sensor"] = dict(sensor)
    if start is not None:
        d["start"] = [float(v) for v in start]
    return _build(d, src)


def scene_to_shapely(scene: Scene) -> dict[str, Any]:
    """The scene's parts as shapely geometries: ``bounds`` (Polygon), ``obstacles``
    (MultiPolygon of the obstacles as given, possibly empty), ``target`` (Polygon,
    target frame), ``goal`` and ``failure`` (Polygon or Point)."""
    return {
        "bounds": Polygon(scene.bounds),
        "obstacles": MultiPolygon([Polygon(o) for o in scene.obstacles]),
        "target": Polygon(scene.target),
        "goal": scene.goal_geom,
        "failure": scene.failure_geom,
    }


def scene_to_wkt(scene: Scene) -> str:
    """The scene in the ``role: value`` WKT text format (module docstring)."""
    lines = [f"name: {scene.name}"]
    for role, g in scene_to_shapely(scene).items():
        lines.append(f"{role}: {shapely.to_wkt(g, rounding_precision=-1)}")
    d = scene.to_dict()
    if scene.start is not None:
        lines.append("start: " + " ".join(repr(float(v)) for v in scene.start))
    if "sensor" in d:
        lines.append("sensor: " + json.dumps(d["sensor"]))
    return "\n".join(lines) + "\n"


def scene_from_wkt(text: str, *, name: str | None = None, default_name: str = "imported") -> Scene:
    """Parse the ``role: value`` WKT text format (module docstring).  ``name`` overrides
    the ``name:`` line; ``default_name`` is used when there is neither."""
    fields: dict[str, Any] = {}
    obstacles: list[Any] = []
    for ln, raw in enumerate(text.splitlines(), 1):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        key, sep, value = line.partition(":")
        key, value = key.strip(), value.strip()
        if not sep:
            raise FormatError(f"line {ln}: expected 'role: value', got {line[:60]!r}")
        if key == "obstacles":
            g = _geom(value, f"line {ln} (obstacles)")
            obstacles.append(g)
        elif key in ("bounds", "target", "goal", "failure"):
            if key in fields:
                raise FormatError(f"line {ln}: {key!r} given twice")
            fields[key] = _geom(value, f"line {ln} ({key})")
        elif key == "name":
            fields["name"] = value
        elif key == "start":
            try:
                st = [float(v) for v in value.replace(",", " ").split()]
            except ValueError:
                st = []
            if len(st) != 3:
                raise FormatError(f"line {ln}: start must be 'x y theta', got {value!r}")
            fields["start"] = st
        elif key == "sensor":
            try:
                fields["sensor"] = json.loads(value)
            except json.JSONDecodeError as e:
                raise FormatError(f"line {ln}: sensor must be a JSON object: {e}") from None
        else:
            raise FormatError(
                f"line {ln}: unknown key {key!r} (name, bounds, obstacles, target, goal, "
                "failure, start, sensor)"
            )
    for key in ("bounds", "target", "goal", "failure"):
        if key not in fields:
            raise FormatError(f"missing line '{key}: <WKT>'")
    if name is not None:
        fields["name"] = name
    fields.setdefault("name", default_name)
    return scene_from_shapely(obstacles=obstacles, **fields)


# ------------------------------------------------------------------------------------------
# obstacle maps (polygons with holes)
# ------------------------------------------------------------------------------------------


def _poly_from_rings(item: Any, where: str) -> Polygon:
    if isinstance(item, (str, shapely.Geometry)):
        return _check_polygon(_geom(item, where), where, holes=True)
    if not isinstance(item, Sequence) or not item:
        raise FormatError(f"{where}: expected a Polygon or [exterior, hole, ...] rings")
    try:
        rings = [np.asarray(r, dtype=float) for r in item]
        if any(r.ndim != 2 or r.shape[1] < 2 for r in rings):
            raise ValueError("each ring must be a list of [x, y] points")
        p = Polygon(rings[0][:, :2], [r[:, :2] for r in rings[1:]])
    except (TypeError, ValueError) as e:
        raise FormatError(f"{where}: malformed rings: {e}") from None
    if not np.all(np.isfinite(shapely.get_coordinates(p))):
        raise FormatError(f"{where}: non-finite coordinate")
    return _check_polygon(p, where, holes=True)


def scene_from_obstacle_map(
    polygons: Iterable[Any],
    *,
    target: Any,
    goal: Any,
    failure: Any,
    bounds: Any = None,
    margin: float = 0.0,
    name: str = "obstacle-map",
    sensor: Mapping[str, Any] | None = None,
    start: Sequence[float] | None = None,
) -> Scene:
    """Build a scene from an obstacle map: a list of polygons with holes.

    Each item of ``polygons`` is a shapely Polygon/WKT string or a list of rings
    ``[exterior, hole, ...]`` (each ring a list of ``[x, y]``, world frame).  Holes in an
    obstacle are free space enclosed by it.  ``bounds`` defaults to the bounding box of
    the obstacles grown by ``margin`` (scene units); with ``margin == 0`` obstacles on
    that box are walls.  ``target``/``goal``/``failure`` as in :func:`scene_from_shapely`
    (goal/failure may also be ``(x, y)`` points).
    """
    polys = [_poly_from_rings(p, f"polygons[{i}]") for i, p in enumerate(polygons)]
    if bounds is None:
        if not polys:
            raise FormatError("polygons: empty obstacle map and no bounds given")
        if not math.isfinite(margin) or margin < 0:
            raise FormatError(f"margin must be finite and >= 0, got {margin!r}")
        x0, y0, x1, y1 = shapely.total_bounds(polys)
        bounds = shapely.box(x0 - margin, y0 - margin, x1 + margin, y1 + margin)

    def region(v: Any, where: str) -> Any:
        if (
            isinstance(v, (tuple, list))
            and len(v) == 2
            and all(isinstance(c, (int, float)) for c in v)
        ):
            return Point(float(v[0]), float(v[1]))
        return v if isinstance(v, (str, shapely.Geometry)) else _poly_from_rings(v, where)

    return scene_from_shapely(
        bounds=bounds,
        obstacles=polys,
        target=target if isinstance(target, (str, shapely.Geometry)) else Polygon(target),
        goal=region(goal, "goal"),
        failure=region(failure, "failure"),
        name=name,
        sensor=sensor,
        start=start,
    )


# ------------------------------------------------------------------------------------------
# files
# ------------------------------------------------------------------------------------------


#: File extensions of the scene formats (the format follows the extension).
SCENE_SUFFIXES = (".json", ".geojson", ".wkt")


def scene_from_data(data: Any, *, name: str | None = None) -> Scene:
    """A scene from parsed JSON: a GeoJSON object (anything with a ``"type"`` member, which
    must be a ``FeatureCollection``; see :func:`scene_from_geojson`) or a scene dict in the
    pinned format (:meth:`geometry.Scene.from_dict`).  ``name`` overrides the scene's name."""
    if isinstance(data, Mapping) and "type" in data:  # no scene has a "type" key
        return scene_from_geojson(data, name=name)
    scene = Scene.from_dict(data)
    return scene.replace(name=name) if name is not None else scene


def scene_from_text(
    text: str,
    ext: str | None = None,
    *,
    name: str | None = None,
    default_name: str = "imported",
) -> Scene:
    """A scene from the text of a scene file in the format of extension ``ext``
    (``.json``: scene JSON or GeoJSON, told apart by content; ``.geojson``; ``.wkt``).
    ``ext=None`` tells the format by content: text starting with ``{`` is JSON, other text
    is WKT.  ``default_name`` names a GeoJSON/WKT scene that names itself nowhere."""
    if ext is None:
        ext = ".json" if text.lstrip().startswith("{") else ".wkt"
    ext = ext.lower()
    if ext == ".wkt":
        return scene_from_wkt(text, name=name, default_name=default_name)
    if ext not in (".json", ".geojson"):
        raise FormatError(f"unknown extension {ext!r} (use {', '.join(SCENE_SUFFIXES)})")
    try:
        data = json.loads(text)
    except json.JSONDecodeError as e:
        raise FormatError(f"invalid JSON: {e}") from None
    if ext == ".geojson" or (isinstance(data, Mapping) and "type" in data):
        if name is None and not (isinstance(data, Mapping) and isinstance(data.get("name"), str)):
            name = default_name
        return scene_from_geojson(data, name=name)
    return scene_from_data(data, name=name)


def scene_to_text(scene: Scene, ext: str) -> str:
    """The text of ``scene`` in the file format of extension ``ext`` (see
    :data:`SCENE_SUFFIXES`)."""
    ext = ext.lower()
    if ext == ".json":
        return scene.to_json()
    if ext == ".geojson":
        return json.dumps(scene_to_geojson(scene), indent=1) + "\n"
    if ext == ".wkt":
        return scene_to_wkt(scene)
    raise FormatError(f"unknown extension {ext!r} (use {', '.join(SCENE_SUFFIXES)})")


def load_scene_file(path: str | PathLike[str], *, name: str | None = None) -> Scene:
    """Load a scene from ``.json`` (scene JSON, or GeoJSON if it has a ``"type"`` member),
    ``.geojson`` or ``.wkt``.  Errors are :class:`FormatError` prefixed with the file name."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except OSError as e:
        raise FormatError(f"{p}: cannot read: {e.strerror or e}") from None
    except UnicodeDecodeError as e:
        raise FormatError(f"{p}: not a text file (UTF-8): {e}") from None
    try:
        return scene_from_text(text, p.suffix, name=name, default_name=p.stem)
    except SceneError as e:
        raise FormatError(f"{p}: {e}") from e


def save_scene_file(scene: Scene, path: str | PathLike[str]) -> None:
    """Write ``scene`` as scene JSON (``.json``), GeoJSON (``.geojson``) or WKT (``.wkt``)."""
    p = Path(path)
    try:
        text = scene_to_text(scene, p.suffix)
    except FormatError as e:
        raise FormatError(f"{p}: {e}") from None
    p.write_text(text, encoding="utf-8")

"""Generate the bundled GeoJSON floor plans ``sensorplan_gym/scenes/real/*.geojson`` from
a public OpenStreetMap indoor map (issues 22 and 25: real floor plans imported from
GeoJSON, 100-300 edges).

The source is OpenStreetMap indoor data (the ``buildingpart`` schema: rooms, corridors,
halls and stair wells as polygons on ``level`` relations, doors as nodes with a ``width``)
of the university building tagged ``Berliner Straße 48, Heidelberg`` (OSM relation
1370729), exported as a GeoJSON FeatureCollection.  The export is republished in
klajosw/js_map_indoor (``data.js``, the collection after ``var geoJSON =``, coordinates
moved by that project); it is not shipped here.  Get it at the recorded commit, then::

    C=561c6322a81e1d510eba358093b7883ed71bceab
    git -C js_map_indoor show $C:data.js > data.js
    python -m benchmarks.make_geojson_maps --osm data.js

The input's SHA-256 is checked, so the scenes are exactly reproducible.  For each
bundled level, deterministically:

* longitude/latitude are projected to metres with a local equirectangular projection
  about the centre of the collection's bounding box (Earth radius 6,371,008.8 m; over the
  building's 60 m the scale error is below 1e-5);
* the free space is the union of the level's rooms, corridors, halls and stair wells,
  each shrunk by half a wall (``wall`` / 2, mitred corners), and of one opening per door
  (a square of the door's tagged width, default 0.9 m, centred on the door node, for every
  door node that is a vertex of an outline of that level -- door nodes carry no level, and
  other levels' doors stand on the same wall lines -- clipped to the outlines grown by
  ``wall``): OSM draws rooms edge to edge or with a gap, and the walls are what separates
  them;
* the largest connected part is kept and simplified (``simplify`` metres, topology
  preserved); it is written as the ``bounds`` Polygon of the scene's GeoJSON, whose holes
  (wall pieces standing free between doors) :func:`geometry.formats.scene_from_geojson`
  turns into obstacles;
* target, G, H and start are placed as for the ROS maps (:mod:`benchmarks.make_real_maps`):
  a 0.4 m x 0.3 m target box, G a pentagon (radius 0.3 m) at the centre of the largest
  inscribed circle, H the free grid point in sight of G at least ``h_sep`` from it farthest
  from the walls, start the centre of the largest circle ``h_sep`` from both.

The bundled file *is* GeoJSON in the format of :mod:`geometry.formats`; the environments
load it through that importer.  Provenance (source, commit, licence, SHA-256, level,
projection, parameters, edge count) goes to ``provenance_geojson.json`` beside it.
OpenStreetMap data is (c) OpenStreetMap contributors, available under the Open Database
Licence (ODbL 1.0); the derived scenes are too.  ``--check`` compares instead of writing.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from shapely.geometry import shape

from benchmarks.make_real_maps import _centre, _in_sight, _pentagon, _r, write_or_check
from geometry.formats import scene_from_geojson

OUT = Path(__file__).resolve().parent.parent / "sensorplan_gym" / "scenes" / "real"
PROVENANCE = "provenance_geojson.json"
EARTH_RADIUS = 6_371_008.8  # metres (IUGG mean radius)
#: the ``buildingpart`` values whose polygons are walkable floor
WALKABLE = ("room", "corridor", "hall", "verticalpassage")

SOURCE = {
    "repository": "https://github.com/klajosw/js_map_indoor",
    "path": "data.js",
    "commit": "561c6322a81e1d510eba358093b7883ed71bceab",
    "sha256": "08c5da428245470a6696e6ad5b345c184d3ccff53e9f58659eaf4270011268f5",
    "licence": (
        "ODbL 1.0: (c) OpenStreetMap contributors (the repository's GPL-3.0 covers its code)"
    ),
    "what": (
        "OpenStreetMap indoor data (buildingpart schema) of the university building tagged "
        "'Berliner Straße 48, Heidelberg' (OSM relation 1370729, shell way 94551367), four "
        "levels, exported as GeoJSON (osmtogeojson layout: properties.tags, "
        "properties.relations[].reltags.level); coordinates moved by the republishing project"
    ),
}

#: The bundled levels and their conversion parameters (metres).
SCENES: dict[str, dict[str, Any]] = {
    "heidelberg_l1": {
        "level": "1",
        "what": "level 1 ('1. Obergeschoss'): L-shaped floor, two corridors and its rooms",
        "wall": 0.15,
        "simplify": 0.05,
        "size": 0.3,
        "h_sep": 4.0,
    },
    "heidelberg_l2": {
        "level": "2",
        "what": "level 2 ('Dachgeschoss'): one wing, a corridor, its rooms and a hall",
        "wall": 0.15,
        "simplify": 0.05,
        "size": 0.3,
        "h_sep": 4.0,
    },
}


def read_osm_geojson(text: str) -> dict[str, Any]:
    """The FeatureCollection in ``text``: GeoJSON, or a JavaScript file assigning it to a
    variable (``var name = {...};``)."""
    body = text.strip()
    if not body.startswith("{"):
        body = body[body.index("{") :]
    return json.loads(body.rstrip(";").rstrip())


def _levels(feature: Mapping[str, Any]) -> set[str]:
    props = feature.get("properties") or {}
    out = {
        str(r["reltags"]["level"])
        for r in props.get("relations", [])
        if "level" in r.get("reltags", {})
    }
    if "level" in props.get("tags", {}):
        out.add(str(props["tags"]["level"]))
    return out


def _width(tags: Mapping[str, Any], default: float = 0.9) -> float:
    """A door's ``width`` tag in metres (``"1"``, ``"1.2m"``, ``"0.9 m"``)."""
    raw = str(tags.get("width", default)).strip().removesuffix("m").strip()
    try:
        return float(raw)
    except ValueError:
        return default


def projection(collection: Mapping[str, Any]) -> tuple[float, float, float, float]:
    """``(lon0, lat0, kx, ky)``: the centre of the collection's bounding box (degrees) and
    the metres per degree of the local equirectangular projection about it."""
    c = np.vstack([shapely.get_coordinates(shape(f["geometry"])) for f in collection["features"]])
    lon0 = float((c[:, 0].min() + c[:, 0].max()) / 2)
    lat0 = float((c[:, 1].min() + c[:, 1].max()) / 2)
    k = EARTH_RADIUS * math.pi / 180
    return lon0, lat0, k * math.cos(math.radians(lat0)), k


def level_free_space(
    collection: Mapping[str, Any], level: str, *, wall: float, simplify: float
) -> tuple[shapely.Polygon, dict[str, int]]:
    """The walkable free space of ``level`` in projected metres: the largest connected
    part of the shrunk floor polygons and door openings (see the module docstring), and
    counts ``{"parts", "doors", "components"}``."""
    lon0, lat0, kx, ky = projection(collection)

    def proj(g: Any) -> Any:
        return shapely.transform(
            g, lambda a: np.column_stack([(a[:, 0] - lon0) * kx, (a[:, 1] - lat0) * ky])
        )

    feats = collection["features"]
    mine = [
        f
        for f in feats
        if f["geometry"]["type"] == "Polygon"
        and (f["properties"].get("tags") or {}).get("buildingpart") in WALKABLE
        and level in _levels(f)
    ]
    if not mine:
        raise ValueError(f"level {level!r}: no walkable buildingpart polygons")
    parts = [proj(shape(f["geometry"])) for f in mine]
    # a door node belongs to the ways it is a vertex of: the level's doors are the door nodes
    # at a vertex of its outlines (nodes carry no level; other levels' doors stand on the
    # same wall lines)
    corners = {
        (round(x, 9), round(y, 9))
        for f in mine
        for x, y in shapely.get_coordinates(shape(f["geometry"]))
    }
    outline = shapely.union_all(parts)
    floor = shapely.union_all([p.buffer(-wall / 2, join_style="mitre") for p in parts])
    grown = outline.buffer(wall)
    doors = []
    for f in feats:
        tags = f["properties"].get("tags") or {}
        if f["geometry"]["type"] != "Point" or tags.get("door") in (None, "no"):
            continue
        x, y = f["geometry"]["coordinates"][:2]
        if (round(x, 9), round(y, 9)) in corners:
            p = proj(shape(f["geometry"]))
            doors.append(p.buffer(_width(tags) / 2, cap_style="square").intersection(grown))
    free = shapely.union_all([floor, *doors])
    comps = sorted(shapely.get_parts(free), key=lambda g: -g.area)
    room = comps[0].simplify(simplify, preserve_topology=True)
    room = shapely.Polygon(
        [(_r(x), _r(y)) for x, y in room.exterior.coords],
        [[(_r(x), _r(y)) for x, y in r.coords] for r in room.interiors],
    )
    return room, {"parts": len(parts), "doors": len(doors), "components": len(comps)}


def build(name: str, collection: Mapping[str, Any]) -> tuple[dict[str, Any], dict[str, Any]]:
    """The scene's GeoJSON (the format of :mod:`geometry.formats`) and its provenance."""
    spec = SCENES[name]
    free, counts = level_free_space(
        collection, spec["level"], wall=spec["wall"], simplify=spec["simplify"]
    )
    s = spec["size"]
    a, b = _r(s * 2 / 3), _r(s / 2)  # the target's half sizes
    g = _centre(free, [], 0.0)
    h = _in_sight(free, g, spec["h_sep"], s / 2)
    st = _centre(free, [g, h], spec["h_sep"])

    def feat(role: str, geom: Any, **props: Any) -> dict[str, Any]:
        return {"type": "Feature", "properties": {"role": role, **props}, "geometry": geom}

    def poly(ring: list[list[float]], holes: list[list[list[float]]] = ()) -> dict[str, Any]:
        return {"type": "Polygon", "coordinates": [ring + ring[:1], *[h + h[:1] for h in holes]]}

    def ring(r: Any) -> list[list[float]]:
        return [[_r(x), _r(y)] for x, y in np.asarray(r.coords)[:-1]]

    geo = {
        "type": "FeatureCollection",
        "name": name,
        "features": [
            feat("bounds", poly(ring(free.exterior), [ring(r) for r in free.interiors])),
            feat("target", poly([[-a, -b], [a, -b], [a, b], [-a, b]]), frame="target"),
            feat("goal", poly(_pentagon(g, s))),
            feat("failure", poly(_pentagon(h, s))),
            feat("start", {"type": "Point", "coordinates": [st.x, st.y]}, theta=0.0),
        ],
    }
    scene = scene_from_geojson(geo)  # validates, holes -> obstacles
    edges = len(scene.bounds) + sum(len(o) for o in scene.obstacles)
    prov = {
        **SOURCE,
        "scene": name,
        "scene_what": spec["what"],
        **{k: spec[k] for k in ("level", "wall", "simplify", "h_sep")},
        "projection": "local equirectangular about the bounding-box centre, metres",
        **counts,
        "edges": edges,
        "obstacles": len(scene.obstacles),
        "generator": "python -m benchmarks.make_geojson_maps",
    }
    return geo, prov


def main(argv: list[str] | None = None) -> None:
    """(Re)write the GeoJSON floor plans and their provenance (``--check``: compare only)."""
    ap = argparse.ArgumentParser(
        prog="python -m benchmarks.make_geojson_maps",
        description=__doc__.split("\n\n")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=__doc__.split("\n\n", 1)[1],
    )
    ap.add_argument("--osm", type=Path, required=True, help="data.js (or the GeoJSON in it)")
    ap.add_argument("--out", type=Path, default=OUT, help=f"folder (default {OUT})")
    ap.add_argument("--check", action="store_true", help="compare with the files, write nothing")
    args = ap.parse_args(argv)
    raw = args.osm.read_bytes()
    digest = hashlib.sha256(raw).hexdigest()
    if digest != SOURCE["sha256"]:
        raise SystemExit(
            f"{args.osm}: SHA-256 {digest} is not the recorded {SOURCE['sha256']} of "
            f"{SOURCE['repository']} {SOURCE['path']} at {SOURCE['commit']}"
        )
    collection = read_osm_geojson(raw.decode("utf-8"))
    texts: dict[str, str] = {}
    provenance: dict[str, Any] = {}
    for name in SCENES:
        geo, prov = build(name, collection)
        provenance[name] = prov
        texts[f"{name}.geojson"] = json.dumps(geo, indent=1, ensure_ascii=False) + "\n"
        print(
            f"{name}: {prov['edges']} edges, {prov['obstacles']} obstacles, {prov['doors']} doors",
            flush=True,
        )
    texts[PROVENANCE] = json.dumps(provenance, indent=1, ensure_ascii=False) + "\n"
    write_or_check(texts, args.out, args.check)


if __name__ == "__main__":
    main()

"""``sensorplan view``: look at a scene and its exact regions in the browser.

    sensorplan view lab                      live viewer at http://localhost:5006/?token=...
    sensorplan view my_scene.json --model partial --motion stationary
    sensorplan view plan.geojson             GeoJSON and WKT scenes too (geometry.formats)
    sensorplan view lab --export view.html   one self-contained HTML file, no server
    sensorplan view lab --rollout ep.json    adds a Replay tab (record one: sensorplan record)
    sensorplan view lab --root scenes/       the page may save only inside scenes/

The live viewer listens on 127.0.0.1 only and serves only pages that carry its access
token, as Jupyter does: a random token is drawn at launch and the URL printed with
``?token=...`` (``--token`` or ``$SENSORPLAN_VIEW_TOKEN`` set one; the environment
variable keeps it out of the process list).  A page opened without it gets a 403 page.
The page's "save scene to" box writes only inside the root folder (the current
directory, or ``--root DIR``): paths are resolved (symlinks, ``..``) and anything
outside the root, or not ending in .json/.geojson/.wkt, is refused with a message in
the page.  Loading a scene uploads a file from the browser; the server opens no path.

Needs the ``viewer`` extra (Bokeh): ``pip install -e ".[viewer]"``.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

__all__ = ["build_parser", "main"]


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="sensorplan view",
        description="Show a scene and its exact sensor-placement regions in the browser: a "
        "live Bokeh app (default) or a self-contained HTML file (--export).",
        epilog="The live viewer listens on 127.0.0.1 and serves only URLs with its token "
        "(printed at launch: http://localhost:PORT/?token=...).  The page saves scene files "
        'only inside --root.  Needs the "viewer" extra: pip install -e ".[viewer]".',
    )
    p.add_argument(
        "scene",
        nargs="?",
        default="lab",
        help="bundled scene name (lab, edr, corridor, warehouse) or a scene file: scene "
        "JSON, GeoJSON (.geojson, or a FeatureCollection in .json) or .wkt (default: lab)",
    )
    p.add_argument("--export", metavar="FILE", help="write a self-contained HTML file and exit")
    p.add_argument("--model", choices=("complete", "partial"), default="complete")
    p.add_argument(
        "--motion", choices=("stationary", "translating", "rotating"), default="translating"
    )
    p.add_argument(
        "--eps-pos", type=float, default=None, help="placement error, scene units (default: scene)"
    )
    p.add_argument(
        "--eps-aim-deg", type=float, default=None, help="aim error, degrees (default: scene)"
    )
    p.add_argument(
        "--fov-deg", type=float, default=None, help="field of view, degrees (default: scene)"
    )
    p.add_argument("--port", type=int, default=5006, help="server port (0: any free port)")
    p.add_argument("--no-browser", action="store_true", help="do not open a browser tab")
    p.add_argument("--rollout", metavar="FILE", help="a saved rollout to replay in a second tab")
    p.add_argument(
        "--root",
        metavar="DIR",
        default=None,
        help="the folder the page may save scene files in; paths in the page's save box are "
        "relative to it, and paths outside it (symlinks and .. resolved) are refused "
        "(default: the current directory)",
    )
    p.add_argument(
        "--token",
        default=None,
        help="the access token the page URL must carry (?token=...), at least 16 characters "
        "of A-Z a-z 0-9 . _ ~ - (default: $SENSORPLAN_VIEW_TOKEN, else a random one printed "
        "with the URL; the variable keeps it out of the process list)",
    )
    return p


def main(argv: list[str] | None = None) -> int:
    """Run ``sensorplan view``; returns a process exit code."""
    args = build_parser().parse_args(argv)
    try:
        import bokeh  # noqa: F401
    except ImportError:
        print('sensorplan view: error: needs Bokeh: pip install -e ".[viewer]"', file=sys.stderr)
        return 2
    from geometry import SceneError
    from sensorplan_gym.core.scenes import load_scene

    from .auth import token_from
    from .layers import Settings

    try:
        token = root = None
        if not args.export:  # the live viewer's access rules, checked before any work
            token = token_from(args.token)
            root = Path.cwd() if args.root is None else Path(args.root)
            if not root.is_dir():
                raise ValueError(f"--root {args.root}: not a directory")
        scene = load_scene(args.scene)
        over = {
            "model": args.model,
            "motion": args.motion,
            "eps_pos": args.eps_pos,
            "eps_aim": None if args.eps_aim_deg is None else math.radians(args.eps_aim_deg),
            "fov": None if args.fov_deg is None else math.radians(args.fov_deg),
        }
        settings = Settings.from_scene(scene, **over)
        if args.rollout:
            from .replay import load_rollout

            args.rollout = load_rollout(args.rollout)  # fail early on a bad file
        if args.export:
            from .export import export_html

            path = export_html(scene, args.export, settings, rollout=args.rollout)
            print(f"wrote {path} ({path.stat().st_size / 1e6:.1f} MB, self-contained)")
            return 0
        from .app import serve

        serve(
            scene,
            settings,
            port=args.port,
            show=not args.no_browser,
            rollout=args.rollout,
            root=root,
            token=token,
        )
    except (SceneError, ValueError, FileNotFoundError) as e:
        print(f"sensorplan view: error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

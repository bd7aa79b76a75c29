"""Browser views of scenes and their exact regions (needs the ``viewer`` extra: Bokeh).

* :func:`export.export_html` -- one self-contained HTML file (``sensorplan view --export``);
* :mod:`.app` -- the live Bokeh server app (``sensorplan view [SCENE]``), on 127.0.0.1,
  reachable only with the token it prints (``http://localhost:5006/?token=...``;
  :mod:`.auth`), saving scene files only inside its root folder (``--root``; :mod:`.files`);
* :mod:`.layers` -- what both show, from the exact geometry (no Bokeh needed).

``SCENE`` is anything :func:`sensorplan_gym.core.scenes.load_scene` takes: a bundled
name, a scene JSON, GeoJSON or WKT file.
"""

from __future__ import annotations

__all__ = ["export_html", "serve"]


def export_html(*args, **kwargs):
    """See :func:`sensorplan_gym.viewer.export.export_html`."""
    from .export import export_html as f

    return f(*args, **kwargs)


def serve(*args, **kwargs):
    """See :func:`sensorplan_gym.viewer.app.serve`."""
    from .app import serve as f

    return f(*args, **kwargs)

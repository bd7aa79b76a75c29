"""A Griffe extension for the API pages: reads this project's docstrings as Markdown.

The docstrings use reStructuredText inline markup (``code``, :func:`name`) and NumPy-like
sections whose entries are ``name : description`` lines.  Before mkdocstrings renders a
docstring, this turns a section header underlined with dashes into a bold line, its
``name : description`` entries (with indented continuation lines) into a bullet list, and the
roles ``:func:`~a.b```, ``:class:``, ``:mod:``, ``:attr:``, ``:meth:`` into code spans.
Loaded by ``mkdocs.yml`` (``extensions: [docs/griffe_docstrings.py]``).
"""

from __future__ import annotations

import re
from typing import Any

import griffe

_ROLE = re.compile(r":(?:func|class|mod|attr|meth|data|exc|obj):`~?([^`]+)`")
_HEADER = re.compile(r"^(\s*)([A-Z][A-Za-z ]+)\n\1-{3,}\s*$", re.M)
_ENTRY = re.compile(r"^(\s*)([A-Za-z_*][\w*, ]*) : (.*)$")


def markdown(text: str) -> str:
    """The docstring ``text`` with NumPy-like sections as bold headers and bullet lists and
    reST roles as code spans."""
    text = _ROLE.sub(lambda m: f"`{m.group(1)}`", text)
    lines = text.split("\n")
    out: list[str] = []
    i = 0
    in_section = False
    indent = ""
    while i < len(lines):
        line = lines[i]
        nxt = lines[i + 1] if i + 1 < len(lines) else ""
        if (
            line.strip()
            and re.fullmatch(r"\s*-{3,}\s*", nxt)
            and len(nxt.strip()) >= len(line.strip()) - 1
        ):
            out += ["", f"**{line.strip()}**", ""]
            in_section, indent = True, line[: len(line) - len(line.lstrip())]
            i += 2
            continue
        m = _ENTRY.match(line) if in_section else None
        if m and m.group(1) == indent:
            names = ", ".join(f"`{n.strip()}`" for n in m.group(2).split(","))
            out.append(f"{indent}- {names}: {m.group(3)}")
        elif in_section and line.startswith(indent + " ") and line.strip() and out:
            out[-1] += " " + line.strip()
        else:
            if not line.strip():
                in_section = in_section and bool(nxt.strip()) and _ENTRY.match(nxt) is not None
            out.append(line)
        i += 1
    return "\n".join(out)


class MarkdownDocstrings(griffe.Extension):
    """Rewrite every docstring with :func:`markdown` as it is loaded."""

    def on_instance(self, *, node: Any, obj: griffe.Object, agent: Any, **kwargs: Any) -> None:
        if obj.docstring is not None:
            obj.docstring.value = markdown(obj.docstring.value)

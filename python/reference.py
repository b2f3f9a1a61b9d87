"""The book's Python API reference, written from the installed package's own signatures
and docstrings so that it cannot drift from them.

    python python/reference.py docs/src/reference/python.md

``python/tests/test_reference.py`` fails when the committed page differs from what this
writes.
"""

from __future__ import annotations

import inspect
import os
import re
import sys
from typing import List

# The installed package, not the source folder beside this script (it lacks the
# compiled extension).
_HERE = os.path.dirname(os.path.abspath(__file__))
sys.path = [p for p in sys.path if os.path.abspath(p or os.curdir) != _HERE]

import tapsim  # noqa: E402

HEADER = """# Python API

<!-- Written by `python python/reference.py docs/src/reference/python.md` from the
package's docstrings; python/tests/test_reference.py checks that it is current. -->

Each function runs the command of the same name (`tapsim.force_curve` runs
`tapsim force-curve`): its keyword arguments are that command's flags in snake case,
listed with their defaults and units in the [command reference](commands.md), and its
result is the command's `--json` document ([output keys](output.md)). How to use them
together: [Python](../how-to/python.md).
"""


def _markdown(doc: str) -> str:
    """A reStructuredText docstring as Markdown: ``code`` and roles as code spans, a
    paragraph ending in ``::`` followed by its indented block as a fenced block."""
    doc = inspect.cleandoc(doc)
    doc = re.sub(r":(?:class|func|meth|attr):`~?([^`]+)`", r"`\1`", doc)
    doc = doc.replace("``", "`")
    out: List[str] = []
    lines = doc.splitlines()
    i = 0
    while i < len(lines):
        line = lines[i]
        if line.rstrip().endswith("::") and not line.strip().startswith("`"):
            out.append(line.rstrip()[:-1])
            i += 1
            while i < len(lines) and not lines[i].strip():
                i += 1
            block = []
            while i < len(lines) and (not lines[i].strip() or lines[i].startswith("    ")):
                block.append(lines[i][4:])
                i += 1
            while block and not block[-1].strip():
                block.pop()
            out += ["", "```python", *block, "```", ""]
            continue
        out.append(line)
        i += 1
    return "\n".join(out).strip() + "\n"


class _Written:
    """An annotation shown as written in the source (they are strings there)."""

    def __init__(self, text: str):
        self.text = text.replace("'", "").replace('"', "").replace("_np.", "numpy.")

    def __repr__(self) -> str:
        return self.text


def _signature(name: str, obj) -> str:
    """``name(parameters) -> returns`` with the annotations as the source writes them."""
    sig = inspect.signature(obj)

    def written(a):
        return _Written(a) if isinstance(a, str) else a

    sig = sig.replace(
        parameters=[p.replace(annotation=written(p.annotation)) for p in sig.parameters.values()],
        return_annotation=written(sig.return_annotation),
    )
    return f"{name}{sig}"


def markdown() -> str:
    """The whole page."""
    parts = [HEADER, "## The package\n", _markdown(tapsim.__doc__)]
    functions = [n for n in tapsim.__all__ if inspect.isfunction(getattr(tapsim, n))]
    classes = [n for n in tapsim.__all__ if inspect.isclass(getattr(tapsim, n))]
    parts.append("## Functions\n")
    for name in functions:
        f = getattr(tapsim, name)
        parts.append(f"### `tapsim.{name}`\n")
        parts.append(f"```python\ntapsim.{_signature(name, f)}\n```\n")
        parts.append(_markdown(f.__doc__ or "(no description)"))
    parts.append("## Classes\n")
    for name in classes:
        cls = getattr(tapsim, name)
        parts.append(f"### `tapsim.{name}`\n")
        parts.append(_markdown(cls.__doc__ or ""))
        for attr, member in cls.__dict__.items():
            if attr.startswith("_") or not inspect.isfunction(member):
                continue
            parts.append(f"#### `{name}.{attr}`\n")
            parts.append(f"```python\n{_signature(attr, member)}\n```\n")
            parts.append(_markdown(member.__doc__ or "(no description)"))
    return "\n".join(parts)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: python python/reference.py OUT.md")
    with open(sys.argv[1], "w", encoding="utf-8") as f:
        f.write(markdown())

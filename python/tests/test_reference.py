"""The book's Python API reference is what python/reference.py writes from the package
now: a docstring or a signature that changes without the page fails here."""

import importlib.util
import pathlib

REPO = pathlib.Path(__file__).resolve().parents[2]


def _reference():
    spec = importlib.util.spec_from_file_location("reference", REPO / "python" / "reference.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_python_reference_page_is_current():
    page = REPO / "docs" / "src" / "reference" / "python.md"
    fresh = _reference().markdown()
    assert page.read_text(encoding="utf-8") == fresh, (
        "docs/src/reference/python.md is stale: run "
        "`python python/reference.py docs/src/reference/python.md`"
    )


def test_every_public_name_has_its_section():
    import tapsim

    page = _reference().markdown()
    for name in tapsim.__all__:
        assert f"### `tapsim.{name}`" in page, name
    assert "(no description)" not in page

"""The Python guide's worked example prints what the page shows (the `>>>` lines of
docs/src/how-to/python.md, run by doctest against the package as installed)."""

import doctest
import pathlib

REPO = pathlib.Path(__file__).resolve().parents[2]


def test_the_python_guide_prints_what_its_examples_show():
    page = REPO / "docs" / "src" / "how-to" / "python.md"
    result = doctest.testfile(
        str(page),
        module_relative=False,
        optionflags=doctest.NORMALIZE_WHITESPACE,
        report=True,
    )
    assert result.attempted >= 8, result
    assert result.failed == 0, result

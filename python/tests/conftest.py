"""Shared fixtures: the command-line binary the package is compared with."""

import json
import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def cli():
    """Run ``tapsim ARGS --json --quiet`` with the command-line binary (built here if
    missing: ``cargo build --release``; or $TAPSIM_BIN) and return its document."""
    binary = os.environ.get("TAPSIM_BIN")
    if not binary:
        subprocess.run(
            ["cargo", "build", "--release", "--quiet", "--bin", "tapsim"],
            cwd=REPO,
            check=True,
        )
        binary = str(REPO / "target" / "release" / "tapsim")

    def run(*args, expect_failure=False):
        out = subprocess.run(
            [binary, *args, "--json", "--quiet"], capture_output=True, text=True
        )
        if expect_failure:
            assert out.returncode != 0, out.stdout
            return out.stderr
        assert out.returncode == 0, out.stderr
        return json.loads(out.stdout)

    return run

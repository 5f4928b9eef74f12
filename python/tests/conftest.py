"""Fixtures of the atmos Python tests: the CLI next to the module (ATMOS_CLI,
set by the ctest entry) and a scratch directory."""

import os
import pathlib
import shutil
import subprocess

import pytest

# Hermetic: no test reads or writes the user's table cache (issue 33 item 4);
# the cache's own tests point XDG_CACHE_HOME at a scratch directory.
os.environ["ATMOS_NO_CACHE"] = "1"


def _cli_path():
    path = os.environ.get("ATMOS_CLI")
    if path:
        return path
    here = pathlib.Path(__file__).resolve().parents[2]
    return str(here / "build" / "atmos")


@pytest.fixture(scope="session")
def cli():
    """Runs the atmos CLI; returns (returncode, stdout, stderr)."""
    path = _cli_path()
    if not os.path.exists(path):
        pytest.fail(f"the atmos CLI is not at {path} (set ATMOS_CLI)")

    def run(*args, stdin=None):
        p = subprocess.run([path, *args], input=stdin, capture_output=True, text=True,
                           timeout=120)
        return p.returncode, p.stdout, p.stderr
    return run


@pytest.fixture
def tmp(request):
    base = os.environ.get("ATMOS_TEST_TMP")
    if not base:
        return pathlib.Path(request.getfixturevalue("tmp_path"))
    d = pathlib.Path(base) / request.node.name
    shutil.rmtree(d, ignore_errors=True)
    d.mkdir(parents=True)
    return d

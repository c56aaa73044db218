"""Shared paths: the repository, its fixtures and the command-line binary the package is
compared with (``ORBCLOUD_CLI``, else the debug build ``cargo test`` makes)."""

import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]
FIXTURES = REPO / "tests" / "fixtures"


@pytest.fixture(scope="session")
def cli():
    path = pathlib.Path(os.environ.get("ORBCLOUD_CLI", REPO / "target" / "debug" / "orbcloud"))
    if not path.is_file():
        raise FileNotFoundError(f"{path}: build the command first (cargo build) or set ORBCLOUD_CLI")

    def run(*args, **kw):
        return subprocess.run([str(path), *map(str, args)], check=True, capture_output=True, text=True, **kw)

    return run

"""The ``orbcloud`` command a wheel installs (``pip install orbcloud``), and ``python -m
orbcloud``: the same command line as the Rust binary, run in this process (the viewer with no
arguments, ``render``, ``scan compute`` …). Computing runs in this interpreter unless
``ORBCLOUD_PYTHON`` names another."""

from __future__ import annotations

import os
import sys

from . import _native


def command(argv: list[str] | None = None) -> int:
    os.environ.setdefault("ORBCLOUD_PYTHON", sys.executable)
    argv = sys.argv[1:] if argv is None else argv
    # `python -m orbcloud view FILE…` as orbcloud.view starts it.
    if argv[:1] == ["view"]:
        argv = ["viewer", *argv[1:]]
    try:
        _native.run_cli(list(argv))
    except RuntimeError as e:
        print(f"Error: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(command())

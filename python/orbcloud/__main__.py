"""``python -m orbcloud view FILE…``: the desktop viewer, as :func:`orbcloud.view` starts it."""

import sys

from . import _native


def main(argv: list[str]) -> int:
    if len(argv) < 1 or argv[0] != "view":
        print("usage: python -m orbcloud view FILE...", file=sys.stderr)
        return 2
    _native.run_viewer(argv[1:])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

"""The ``orbcloud`` command as the wheel installs it (``python -m orbcloud``, the entry point
``orbcloud.__main__:command``): the Rust command line, run in this process."""

import subprocess
import sys


def run(*args):
    return subprocess.run([sys.executable, "-m", "orbcloud", *args], capture_output=True, text=True, timeout=300)


def test_version_and_help_answer_without_error():
    r = run("--version")
    assert r.returncode == 0 and r.stdout.startswith("orbcloud "), r
    r = run("scan", "compute", "--help")
    assert r.returncode == 0 and "--relaxed" in r.stdout and "--dask" in r.stdout, r


def test_a_usage_error_is_reported_not_a_crash():
    r = run("render", "--no-such-option")
    assert r.returncode == 1 and "--no-such-option" in r.stderr and "Traceback" not in r.stderr, r


def test_the_entry_point_renders_the_demo(tmp_path):
    out = tmp_path / "demo.png"
    r = run("render", "--lavapipe", "--size", "96x72", "-o", str(out))
    assert r.returncode == 0, r.stderr
    assert out.stat().st_size > 0

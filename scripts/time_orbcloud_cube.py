#!/usr/bin/env python3
"""Times `orbcloud cube FILE OPTIONS -o OUT` (best of 3, one thread, the whole process), compares
OUT with a reference cube file of the same grid, and prints the speed ratio against the
reference's time. Used by scripts/bench_cube_vs_pyscf.sh and scripts/bench_esp_vs_pyscf.sh.
   time_orbcloud_cube.py REFERENCE.cube REFERENCE_SECONDS OUT.cube FILE [cube options…]
"""
import os
import subprocess
import sys
import time

import numpy as np


def values(path):
    lines = open(path).read().split("\n")
    natoms = abs(int(lines[2].split()[0]))
    n = [abs(int(lines[3 + i].split()[0])) for i in range(3)]
    return np.array(" ".join(lines[6 + natoms:]).split(), dtype=float).reshape(n)


def main():
    reference, seconds, out, file, options = sys.argv[1], float(sys.argv[2]), sys.argv[3], sys.argv[4], sys.argv[5:]
    ours = float("inf")
    for _ in range(3):
        t = time.perf_counter()
        subprocess.run(["target/release/orbcloud", "cube", file, *options, "-o", out], check=True,
                       stderr=subprocess.DEVNULL, env={**os.environ, "RAYON_NUM_THREADS": "1"})
        ours = min(ours, time.perf_counter() - t)
    a, b = values(reference), values(out)
    # Both files hold 6 significant digits.
    print(f"max |orbcloud - reference| = {np.abs(a - b).max():.1e}, relative to the largest value "
          f"{np.abs(a - b).max() / np.abs(a).max():.1e} (file precision)")
    print(f"reference_s={seconds:.3f} orbcloud_s={ours:.3f} ratio={seconds / ours:.1f}")


if __name__ == "__main__":
    main()

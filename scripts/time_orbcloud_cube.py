#!/usr/bin/env python3
"""Times `orbcloud cube FILE OPTIONS -o OUT` (best of 5, the whole process, one thread unless
--threads says otherwise), compares OUT with a reference cube file of the same grid, and prints
the speed ratio against the reference's time. Used by scripts/bench_cube_vs_pyscf.sh and
scripts/bench_esp_vs_pyscf.sh. ORBCLOUD names the binary (default target/release/orbcloud).
   time_orbcloud_cube.py [--threads N] REFERENCE.cube REFERENCE_SECONDS OUT.cube FILE [cube options…]
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
    args = sys.argv[1:]
    threads = "1"
    if args[0] == "--threads":
        threads, args = args[1], args[2:]
    reference, seconds, out, file, options = args[0], float(args[1]), args[2], args[3], args[4:]
    binary = os.environ.get("ORBCLOUD", "target/release/orbcloud")
    times = []
    for _ in range(5):
        # A new file each time: truncating the file the previous run has just written waits
        # for the kernel to write it back (a few ms for 6.7 MB), which is no part of the work.
        if os.path.exists(out):
            os.remove(out)
        t = time.perf_counter()
        subprocess.run([binary, "cube", file, *options, "-o", out], check=True,
                       stderr=subprocess.DEVNULL, env={**os.environ, "RAYON_NUM_THREADS": threads})
        times.append(time.perf_counter() - t)
    ours = min(times)
    a, b = values(reference), values(out)
    # Both files hold 6 significant digits.
    print(f"max |orbcloud - reference| = {np.abs(a - b).max():.1e}, relative to the largest value "
          f"{np.abs(a - b).max() / np.abs(a).max():.1e} (file precision)")
    print(f"orbcloud threads={threads} runs_s={' '.join(f'{t:.4f}' for t in sorted(times))}")
    print(f"reference_s={seconds:.3f} orbcloud_s={ours:.4f} ratio={seconds / ours:.1f}")


if __name__ == "__main__":
    main()

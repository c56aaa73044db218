#!/usr/bin/env bash
# `orbcloud cube` against PySCF's cubegen.orbital: the same SCF (PySCF writes it as Molden),
# the same orbital (HOMO), the same 80³ grid (atoms + 3 bohr), one thread each, in one run.
# Times the whole command for orbcloud (reading the Molden file, evaluating, writing the cube)
# and cubegen.orbital (evaluating, writing) for PySCF; then compares the two cube files.
#   scripts/bench_cube_vs_pyscf.sh [benzene|psb3]
# Needs a release build and `pip install -r scripts/requirements.txt` (PYTHON overrides python3).
set -euo pipefail
cd "$(dirname "$0")/.."
molecule=${1:-benzene}
python=${PYTHON:-python3}
out=target/bench
mkdir -p "$out"
"$python" scripts/bench_cube_vs_pyscf.py --molecule "$molecule" --molden "$out/$molecule.molden" \
    --cube "$out/${molecule}_pyscf.cube" | tee "$out/${molecule}_pyscf.txt"
pyscf=$(sed -n 's/^pyscf_s=//p' "$out/${molecule}_pyscf.txt")
"$python" - "$out/${molecule}_pyscf.cube" "$out/${molecule}_orbcloud.cube" "$pyscf" "$out/$molecule.molden" <<'PY'
import os
import subprocess
import sys
import time

import numpy as np

ours = float("inf")
for _ in range(3):
    t = time.perf_counter()
    subprocess.run(
        ["target/release/orbcloud", "cube", sys.argv[4], "--orbital", "homo", "--grid", "80", "--margin", "3",
         "-o", sys.argv[2]],
        check=True, stderr=subprocess.DEVNULL, env={**os.environ, "RAYON_NUM_THREADS": "1"},
    )
    ours = min(ours, time.perf_counter() - t)

def values(path):
    lines = open(path).read().split("\n")
    natoms = abs(int(lines[2].split()[0]))
    n = [abs(int(lines[3 + i].split()[0])) for i in range(3)]
    return np.array(" ".join(lines[6 + natoms:]).split(), dtype=float).reshape(n)

a, b = values(sys.argv[1]), values(sys.argv[2])
pyscf = float(sys.argv[3])
# Both files hold 5-6 significant digits: compare relative to the largest value.
print(f"max |orbcloud - pyscf| / max|psi| = {np.abs(a - b).max() / np.abs(a).max():.1e} (file precision)")
print(f"pyscf_cubegen_s={pyscf:.3f} orbcloud_cube_s={ours:.3f} ratio={pyscf / ours:.1f}")
PY

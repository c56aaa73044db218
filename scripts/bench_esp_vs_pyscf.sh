#!/usr/bin/env bash
# `orbcloud cube --esp` against PySCF's cubegen.mep: the same SCF (PySCF writes it as Molden),
# the same 40³ grid (atoms + 3 bohr, cubegen's box), one thread each, in one run. Times the whole
# command for orbcloud (reading the Molden file, building the potential, evaluating, writing the
# cube) and cubegen.mep (evaluating, writing) for PySCF; then compares the two cube files.
#   scripts/bench_esp_vs_pyscf.sh [psb3|benzene] [points per side]
# Needs a release build and `pip install -r scripts/requirements.txt` (PYTHON overrides python3).
set -euo pipefail
cd "$(dirname "$0")/.."
molecule=${1:-psb3}
n=${2:-40}
python=${PYTHON:-python3}
out=target/bench
mkdir -p "$out"
"$python" scripts/bench_esp_vs_pyscf.py --molecule "$molecule" --n "$n" --molden "$out/$molecule.molden" \
    --cube "$out/${molecule}_mep_pyscf.cube" | tee "$out/${molecule}_mep_pyscf.txt"
pyscf=$(sed -n 's/^pyscf_s=//p' "$out/${molecule}_mep_pyscf.txt")
"$python" - "$out/${molecule}_mep_pyscf.cube" "$out/${molecule}_esp_orbcloud.cube" "$pyscf" "$out/$molecule.molden" "$n" <<'PY'
import os
import subprocess
import sys
import time

import numpy as np

ours = float("inf")
for _ in range(3):
    t = time.perf_counter()
    subprocess.run(
        ["target/release/orbcloud", "cube", sys.argv[4], "--esp", "--grid", sys.argv[5], "--margin", "3",
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
# Both files hold 6 significant digits.
print(f"max |orbcloud - pyscf| = {np.abs(a - b).max():.1e} a.u. (values up to {np.abs(a).max():.1f}; file precision)")
print(f"pyscf_mep_s={pyscf:.3f} orbcloud_esp_s={ours:.3f} ratio={pyscf / ours:.1f}")
PY

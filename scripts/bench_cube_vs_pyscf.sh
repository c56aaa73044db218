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
"$python" scripts/time_orbcloud_cube.py "$out/${molecule}_pyscf.cube" "$pyscf" "$out/${molecule}_orbcloud.cube" \
    "$out/$molecule.molden" --orbital homo --grid 80 --margin 3

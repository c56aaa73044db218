#!/usr/bin/env bash
# `orbcloud cube --esp` against PySCF's cubegen.mep: the same SCF (PySCF writes it as Molden),
# the same 40³ grid (atoms + 3 bohr, cubegen's box), two threads each, in one run. Times the whole
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
"$python" scripts/bench_esp_vs_pyscf.py --molecule "$molecule" --n "$n" --repeat 1 --molden "$out/$molecule.molden" \
    --cube "$out/${molecule}_mep_pyscf.cube" | tee "$out/${molecule}_mep_pyscf.txt"
pyscf=$(sed -n 's/^pyscf_s=//p' "$out/${molecule}_mep_pyscf.txt")
"$python" scripts/time_orbcloud_cube.py --threads 2 "$out/${molecule}_mep_pyscf.cube" "$pyscf" "$out/${molecule}_esp_orbcloud.cube" \
    "$out/$molecule.molden" --esp --grid "$n" --margin 3

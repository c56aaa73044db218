#!/usr/bin/env bash
# A 10-frame rigid dihedral scan of n-butane (B3LYP/6-31G*) computed with 1 and then 2 local
# worker processes, on the cores of this machine; prints each run's seconds and the ratio.
# Needs PySCF in the Python that ORBCLOUD_PYTHON names (default python3) and a built orbcloud
# (ORBCLOUD, default target/release/orbcloud).
set -euo pipefail
cd "$(dirname "$0")/.."
orbcloud=${ORBCLOUD:-target/release/orbcloud}
python=${ORBCLOUD_PYTHON:-python3}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# The anti conformer from a Z-matrix (standard bond lengths and angles), written as XYZ.
"$python" - "$work/butane.xyz" <<'PY'
import sys
from pyscf import gto
zmatrix = """C
C 1 1.53
C 2 1.53 1 112.0
C 3 1.53 2 112.0 1 180.0
H 1 1.09 2 110.0 3 60.0
H 1 1.09 2 110.0 3 180.0
H 1 1.09 2 110.0 3 -60.0
H 2 1.09 1 109.5 3 121.0
H 2 1.09 1 109.5 3 -121.0
H 3 1.09 4 109.5 2 121.0
H 3 1.09 4 109.5 2 -121.0
H 4 1.09 3 110.0 2 60.0
H 4 1.09 3 110.0 2 180.0
H 4 1.09 3 110.0 2 -60.0"""
mol = gto.M(atom=zmatrix, basis="sto-3g")
c = mol.atom_coords(unit="Angstrom")
with open(sys.argv[1], "w") as f:
    f.write(f"{mol.natm}\nn-butane\n")
    for i in range(mol.natm):
        f.write(f"{mol.atom_pure_symbol(i)} {c[i][0]:.6f} {c[i][1]:.6f} {c[i][2]:.6f}\n")
PY
declare -A seconds
for workers in 1 2; do
    start=$(date +%s.%N)
    "$orbcloud" scan compute "$work/butane.xyz" --dihedral 1,2,3,4 --from 0 --to 180 --step 20 \
        --method b3lyp --basis 6-31g* --workers "$workers" -o "$work/scan$workers" 2>/dev/null >/dev/null
    seconds[$workers]=$(echo "$(date +%s.%N) - $start" | bc)
    printf 'workers %d: %.1f s\n' "$workers" "${seconds[$workers]}"
done
printf 'speed-up with 2 workers: %.2f×\n' "$(echo "${seconds[1]} / ${seconds[2]}" | bc -l)"

#!/usr/bin/env bash
# `orbcloud plane` (the whole process: a 500×500 map of the HOMO 1 bohr above the ring, PNG
# written) against PySCF evaluating the same points alone (eval_ao + the product with the
# orbital's coefficients), one thread each, in one run; prints both times, their ratio and the
# largest difference of the values.
#   scripts/bench_plane.sh [benzene|psb3] [points per side]
# Needs a release build and `pip install -r scripts/requirements.txt` (PYTHON overrides python3).
set -euo pipefail
cd "$(dirname "$0")/.."
molecule=${1:-benzene}
n=${2:-500}
python=${PYTHON:-python3}
"$python" scripts/bench_plane_vs_pyscf.py --molecule "$molecule" --n "$n" --out target/bench

#!/usr/bin/env bash
# orbcloud's isosurface extraction against VTK's flying edges on the same cube, in one run:
# both signs of the benzene HOMO at the same iso value, normals from the gradient.
#   scripts/bench_isosurface_vs_vtk.sh [ISO] [SIZES...]
# Needs a release build and `pip install -r scripts/requirements.txt` (PYTHON overrides python3).
set -euo pipefail
cd "$(dirname "$0")/.."
iso=${1:-0.02}
shift || true
sizes=${*:-80 128}
python=${PYTHON:-python3}
for n in $sizes; do
    cube=target/bench/benzene_homo_$n.cube
    [ -f "$cube" ] || "$python" scripts/make_bench_cube.py "$cube" --size "$n" >&2
    out=$(target/release/orbcloud bench isosurface "$cube" --iso "$iso" --runs 20)
    ours=$(sed -n 's/^extract_ms_median=\([0-9.]*\).*/\1/p' <<<"$out")
    tris=$(sed -n 's/^grid .*, \([0-9]*\) triangles.*/\1/p' <<<"$out")
    peer=$("$python" scripts/peer_vtk_isosurface.py "$cube" --iso "$iso" --runs 20)
    vtk_ms=$(sed -n 's/^vtk_extract_ms=//p' <<<"$peer")
    vtk_tris=$(sed -n 's/^vtk_triangles=//p' <<<"$peer")
    ratio=$("$python" -c "print(f'{$vtk_ms / $ours:.2f}')")
    echo "grid=${n}^3 iso=$iso orbcloud_ms=$ours ($tris triangles) vtk_ms=$vtk_ms ($vtk_tris triangles) vtk/orbcloud=$ratio"
done

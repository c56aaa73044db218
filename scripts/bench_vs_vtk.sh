#!/usr/bin/env bash
# orbcloud's slice renderer against VTK's GPU ray-cast mapper on the same cube, the same
# camera, the same image size and the same sample spacing along the rays, in one run.
#   scripts/bench_vs_vtk.sh [CUBE] [SLICES...]
# Needs a release build and `pip install -r scripts/requirements.txt` (PYTHON overrides python3).
set -euo pipefail
cd "$(dirname "$0")/.."
cube=${1:-target/bench/benzene_homo_80.cube}
shift || true
slices=${*:-96 192 384}
python=${PYTHON:-python3}
[ -f "$cube" ] || "$python" scripts/make_bench_cube.py "$cube"
export NODEVICE_SELECT=1
for n in $slices; do
    out=$(target/release/orbcloud bench render "$cube" --size 800x600 --slices "$n" --frames 8 --lavapipe --atoms hidden)
    ours=$(sed -n 's/^ms_per_frame_median=\([0-9.]*\).*/\1/p' <<<"$out")
    # The same frames with every slice whole (no empty space skipped), for comparison.
    whole=$(target/release/orbcloud bench render "$cube" --size 800x600 --slices "$n" --frames 8 --lavapipe \
        --atoms hidden --full-slices | sed -n 's/^ms_per_frame_median=\([0-9.]*\).*/\1/p')
    eye=$(sed -n 's/^camera: eye=\([^ ]*\) .*/\1/p' <<<"$out")
    target=$(sed -n 's/^camera: .* target=\([^ ]*\) .*/\1/p' <<<"$out")
    fov=$(sed -n 's/^camera: .* fov_deg=\([^ ]*\)$/\1/p' <<<"$out")
    spacing=$(sed -n 's/^slice_spacing_bohr=\(.*\)$/\1/p' <<<"$out")
    vtk=$("$python" scripts/peer_vtk.py "$cube" --size 800x600 --frames 8 --eye="$eye" --target="$target" \
        --fov "$fov" --sample-distance "$spacing" | sed -n 's/^vtk_ms_per_frame=//p')
    ratio=$("$python" -c "print(f'{$vtk / $ours:.2f}')")
    echo "slices=$n spacing_bohr=$spacing orbcloud_ms=$ours orbcloud_full_slices_ms=$whole vtk_ms=$vtk vtk/orbcloud=$ratio"
done

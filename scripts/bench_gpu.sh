#!/usr/bin/env bash
# Absolute figures on a real GPU, in one run: orbital grid points per second (the GPU's fill pass
# against the CPU evaluator), electrostatic-potential points per second (`cube --esp`, on the
# CPU's every core), a cloud frame at 1920×1080, a million atoms, the NCI field of a 52-atom
# complex and its isovalue change, and the scene of three molecules. Each figure is printed by
# an `orbcloud bench` command or by `cube`, named above its output.
#   scripts/bench_gpu.sh [LOG]
# Needs a release build (ORBCLOUD overrides target/release/orbcloud) and the complex made by
# `python3 scripts/make_nci_complex.py` (target/bench/octane_dimer_631gs.molden).
set -uo pipefail
cd "$(dirname "$0")/.."
bin=${ORBCLOUD:-target/release/orbcloud}
log=${1:-target/bench/gpu.txt}
complex=target/bench/octane_dimer_631gs.molden
benzene=tests/fixtures/wavefunctions/benzene_631gs.fchk
scratch=$(mktemp -d)
mkdir -p "$(dirname "$log")"
: >"$log"
export NODEVICE_SELECT=1

step() { # step TITLE COMMAND…: runs one figure's command (2 minutes at most), its output logged
    local title=$1
    shift
    echo "== $title: $*" | tee -a "$log"
    local start=$SECONDS
    timeout 120 "$@" 2>&1 | tee -a "$log"
    echo "   (rc ${PIPESTATUS[0]}, $((SECONDS - start)) s)" | tee -a "$log"
}

{
    echo "date: $(date -u +%FT%TZ)"
    nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm --format=csv,noheader 2>/dev/null
    echo "cpu: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2)"
    "$bin" --version
} 2>&1 | tee -a "$log"

step "orbital, benzene HOMO, 128³" "$bin" bench orbital "$benzene" --points 128
step "orbital, benzene HOMO, 256³" "$bin" bench orbital "$benzene" --points 256 --runs 2
step "orbital, octane dimer HOMO, 128³" "$bin" bench orbital "$complex" --points 128
step "orbital, octane dimer HOMO, 256³" "$bin" bench orbital "$complex" --points 256 --runs 2
step "orbital cube 80³, whole process" bash -c "time $bin cube $benzene --grid 80 -o $scratch/homo.cube"
step "ESP cube 40³, benzene" bash -c "time $bin cube $benzene --esp --grid 40 --margin 3 -o $scratch/esp40.cube"
step "ESP cube 80³, benzene" bash -c "time $bin cube $benzene --esp --grid 80 --margin 3 -o $scratch/esp80.cube"
step "ESP cube 64³, octane dimer" bash -c "time $bin cube $complex --esp --grid 64 --margin 3 -o $scratch/esp_dimer.cube"
step "cloud frame 800×600, demo cube, 192 slices" "$bin" bench render --size 800x600 --frames 50
step "cloud frame 1920×1080, demo cube, 192 slices" "$bin" bench render --size 1920x1080 --frames 50
step "cloud frame 1920×1080, benzene HOMO evaluated per sample (direct)" \
    "$bin" bench render "$benzene" --direct --size 1920x1080 --frames 20
step "a million atoms, space filling, 1920×1080" "$bin" bench spheres --atoms 1000000 --size 1920x1080 --frames 50
step "a million atoms, ball-and-stick, 1920×1080" \
    "$bin" bench spheres --atoms 1000000 --style ball-and-stick --size 1920x1080 --frames 50
step "NCI of the octane dimer (52 atoms), 80³" "$bin" bench nci "$complex" --points 80
step "NCI of the octane dimer (52 atoms), 128³" "$bin" bench nci "$complex" --points 128 --runs 2
step "three molecules with clouds and surfaces, 800×600" "$bin" bench scene
step "three molecules with clouds and surfaces, 1920×1080" "$bin" bench scene --size 1920x1080
step "key volumes of the PSB3 scan" "$bin" bench keyvolumes --size 1920x1080
rm -rf "$scratch"

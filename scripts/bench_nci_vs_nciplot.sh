#!/usr/bin/env bash
# orbcloud nci against NCIPLOT 4.2 on the same files and the same grid: times both whole
# processes (best of 3, 2 threads each), compares the cubes at the points NCIPLOT kept, prints
# the ratio.
#
# usage: scripts/bench_nci_vs_nciplot.sh [--promolecular] [--step Å] FILE [FILE…]
#   NCIPLOT_HOME  NCIPLOT's folder (its dat/ holds the promolecular fits); the binary is
#                 $NCIPLOT_HOME/src_nciplot_4.2/nciplot unless NCIPLOT_BIN names it
#   ORBCLOUD      the orbcloud binary (default target/release/orbcloud)
#   THREADS       threads for each program (default 2)
#   RUNS          runs of each, the best counted (default 3)
# FILEs are .wfn/.wfx wavefunctions (fragments whose densities add) or, with --promolecular,
# .xyz structures. Both programs use NCIPLOT's automatic box: the atoms' box plus 0.75 Å,
# ⌈extent/step⌉ points per axis, step 0.1 Å unless --step says.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
promolecular=0
step=0.1
files=()
while [ $# -gt 0 ]; do
    case "$1" in
    --promolecular) promolecular=1 ;;
    --step) step=$2; shift ;;
    -h | --help) sed -n 2,14p "$0"; exit 0 ;;
    *) files+=("$(realpath "$1")") ;;
    esac
    shift
done
[ ${#files[@]} -gt 0 ] || { sed -n 2,14p "$0"; exit 2; }
: "${NCIPLOT_HOME:?set NCIPLOT_HOME to the folder of NCIPLOT 4.2}"
export NCIPLOT_HOME
nciplot=${NCIPLOT_BIN:-$NCIPLOT_HOME/src_nciplot_4.2/nciplot}
orbcloud=${ORBCLOUD:-$root/target/release/orbcloud}
threads=${THREADS:-2}
runs=${RUNS:-3}
[ -x "$nciplot" ] || { echo "no NCIPLOT binary at $nciplot (make in src_nciplot_4.2, or NCIPLOT_BIN)"; exit 2; }
[ -x "$orbcloud" ] || { echo "no orbcloud at $orbcloud (cargo build --release)"; exit 2; }
python=${PYTHON:-python3}

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/nciplot" "$work/orbcloud"
{
    echo ${#files[@]}
    for f in "${files[@]}"; do
        cp "$f" "$work/nciplot/"
        basename "$f"
    done
    echo "INCREMENTS $step $step $step"
    echo "ONAME nciplot"
} >"$work/nciplot/input.nci"

# The best wall time of $runs runs of a command, in seconds.
best_of() {
    local best="" t
    for _ in $(seq "$runs"); do
        /usr/bin/time -f %e -o "$work/time" "$@" >/dev/null 2>&1
        t=$(tail -1 "$work/time")
        if [ -z "$best" ] || awk "BEGIN{exit !($t < $best)}"; then best=$t; fi
    done
    echo "$best"
}

echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')"
echo "load: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "files: ${files[*]##*/}; step $step Å; $threads threads each; best of $runs"

cd "$work/nciplot"
t_nciplot=$(OMP_NUM_THREADS=$threads best_of sh -c 'exec "$0" < input.nci > output.nco' "$nciplot")
echo "NCIPLOT:  $t_nciplot s   (OMP_NUM_THREADS=$threads $nciplot < input.nci)"

cd "$work/orbcloud"
args=(nci "${files[@]}" --step "$step" -o orbcloud)
[ $promolecular = 1 ] && args+=(--promolecular)
t_orbcloud=$(RAYON_NUM_THREADS=$threads best_of "$orbcloud" "${args[@]}")
echo "orbcloud: $t_orbcloud s   (RAYON_NUM_THREADS=$threads orbcloud ${args[*]##*/})"
awk "BEGIN{printf \"ratio: orbcloud is %.1fx faster\n\", $t_nciplot / $t_orbcloud}"

"$python" "$here/nci_compare.py" "$work/nciplot/nciplot" "$work/orbcloud/orbcloud"

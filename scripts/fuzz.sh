#!/usr/bin/env bash
# Fuzzes every reader with AFL++ (cargo-afl, stable toolchain), seeded with the test fixtures.
#   scripts/fuzz.sh [EXECUTIONS_PER_TARGET] [TARGET …]     (default 10000000, every target)
# Installs cargo-afl when missing. Each target runs until it has made that many executions;
# two run at a time. Findings land in fuzz/out/TARGET/default/{crashes,hangs}; the summary
# line per target gives executions, seconds, crashes and hangs. A finding becomes a regression
# test in tests/hostile_inputs.rs.
set -euo pipefail
cd "$(dirname "$0")/.."
execs="${1:-10000000}"
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(cube cube_gz molden fchk wfn wfx mkl json scan_manifest session pdb mmcif xyz gaussian_log)

command -v cargo-afl >/dev/null || cargo install cargo-afl --locked
# Seeds: the fixtures each reader is tested with, kept small (AFL slows on big inputs).
seed() {
    local target=$1; shift
    mkdir -p "fuzz/seeds/$target"
    for f in "$@"; do
        [ -f "$f" ] && [ "$(stat -c %s "$f")" -lt 60000 ] && cp "$f" "fuzz/seeds/$target/" || true
    done
}
# Two small cubes: bohr with one orbital; ångström (negative voxel counts) with two orbitals.
mkdir -p fuzz/seeds/cube
cat > fuzz/seeds/cube/water.cube <<'CUBE'
water
 SCF density
    3   -1.000000   -1.000000   -1.000000
    3    1.000000    0.000000    0.000000
    3    0.000000    1.000000    0.000000
    3    0.000000    0.000000    1.000000
    8    8.000000    0.000000    0.000000    0.221665
    1    1.000000    0.000000    1.430901   -0.886659
    1    1.000000    0.000000   -1.430901   -0.886659
 1.0E-01 2.0E-01 3.0E-01 4.0E-01 5.0E-01 6.0E-01
 7.0E-01 8.0E-01 9.0E-01 1.0E+00 1.1E+00 1.2E+00
 1.3E+00 1.4E+00 1.5E+00 1.6E+00 1.7E+00 1.8E+00
 1.9E+00 2.0E+00 2.1E+00 2.2E+00 2.3E+00 2.4E+00
 2.5E+00 2.6E+00 2.7E+00
CUBE
cat > fuzz/seeds/cube/two_orbitals.cube <<'CUBE'
h2
 MO 1 and 2, angstrom
   -2   -0.500000   -0.500000   -0.500000
   -2    0.500000    0.000000    0.000000
   -2    0.000000    0.500000    0.000000
   -2    0.000000    0.000000    0.500000
    1    1.000000    0.000000    0.000000    0.370000
    1    1.000000    0.000000    0.000000   -0.370000
    2    1    2
 1.0E-02 -2.0E-02 3.0E-02 -4.0E-02 5.0E-02 -6.0E-02
 7.0E-02 -8.0E-02 9.0E-02 -1.0E-01 1.1E-01 -1.2E-01
 1.3E-01 -1.4E-01 1.5E-01 -1.6E-01
CUBE
seed molden tests/fixtures/wavefunctions/h2o_cart_631gs.molden tests/fixtures/wavefunctions/h2o_cation_uhf_631gs.molden tests/fixtures/wavefunctions/h2_spdfgh.molden
seed fchk tests/fixtures/wavefunctions/h2o_cart_631gs.fchk tests/fixtures/wavefunctions/h2o_cation_uhf_631gs.fchk tests/fixtures/excited/formaldehyde_qchem_tda.fchk
# wfn, wfx, MKL: the fixtures' layouts for H2 and OH (1–3 kB), written by PySCF when it is
# there: AFL ran the 8–60 kB fixtures at 1 400 executions a second.
python=${PYTHON:-python3}
rm -rf fuzz/seeds/wfn fuzz/seeds/wfx fuzz/seeds/mkl
if ! "$python" scripts/make_wfn_wfx_mkl_fixtures.py --seeds fuzz/seeds 2>/dev/null; then
    seed wfn tests/fixtures/wfn_wfx_mkl/*.wfn
    seed wfx tests/fixtures/wfn_wfx_mkl/*.wfx
    seed mkl tests/fixtures/wfn_wfx_mkl/*.mkl
fi
# JSON: H2 in ORCA's orca_2json layout and as a Psi4 QCSchema result (under 1 kB each; the
# fixtures are 20–130 kB).
rm -rf fuzz/seeds/json
mkdir -p fuzz/seeds/json
cat > fuzz/seeds/json/h2.orca.json <<'JSON'
{
    "Molecule": {
        "Atoms": [
            {"BasisFunctions": [{"Coefficients": [0.15432897, 0.53532814, 0.44463454], "Exponents": [3.42525091, 0.62391373, 0.1688554], "Shell": "s"}],
             "Coords": [0.0, 0.0, 0.0], "ElementLabel": "H", "ElementNumber": 1, "Idx": 0, "NuclearCharge": 1.0},
            {"BasisFunctions": [{"Coefficients": [0.15432897, 0.53532814, 0.44463454], "Exponents": [3.42525091, 0.62391373, 0.1688554], "Shell": "s"}],
             "Coords": [0.0, 0.0, 1.4], "ElementLabel": "H", "ElementNumber": 1, "Idx": 1, "NuclearCharge": 1.0}
        ],
        "BaseName": "h2", "Charge": 0, "CoordinateUnits": "Bohrs", "HFTyp": "RHF", "Multiplicity": 1,
        "MolecularOrbitals": {
            "EnergyUnit": "Eh",
            "MOs": [
                {"MOCoefficients": [0.54893, 0.54893], "Occupancy": 2.0, "OrbitalEnergy": -0.57823},
                {"MOCoefficients": [1.21146, -1.21146], "Occupancy": 0.0, "OrbitalEnergy": 0.67029}
            ],
            "OrbitalLabels": ["0H   1s", "1H   1s"]
        }
    },
    "ORCA Header": {"Version": "5.0 - current"}
}
JSON
cat > fuzz/seeds/json/h2.qcschema.json <<'JSON'
{"schema_name": "qcschema_output", "provenance": {"creator": "Psi4", "version": "1.10", "routine": "psi4.schema_runner.run_qcschema"},
 "molecule": {"symbols": ["H", "H"], "geometry": [0.0, 0.0, 0.0, 0.0, 0.0, 1.4], "molecular_charge": 0.0, "molecular_multiplicity": 1},
 "properties": {"calcinfo_nalpha": 1, "calcinfo_nbeta": 1},
 "wavefunction": {"basis": {"name": "STO-3G", "center_data": {"STO-3G_H1": {"electron_shells": [
   {"angular_momentum": [0], "harmonic_type": "spherical", "exponents": [3.42525091, 0.62391373, 0.1688554],
    "coefficients": [[0.2769343609526476, 0.2678388517525271, 0.0834736696169253]]}]}},
   "atom_map": ["STO-3G_H1", "STO-3G_H1"]},
  "restricted": true, "scf_orbitals_a": [0.54893, 1.21146, 0.54893, -1.21146], "scf_eigenvalues_a": [-0.57823, 0.67029],
  "scf_occupations_a": [1.0, 0.0], "orbitals_a": "scf_orbitals_a", "eigenvalues_a": "scf_eigenvalues_a",
  "occupations_a": "scf_occupations_a"}}
JSON
seed gaussian_log tests/fixtures/logs/*.log tests/fixtures/logs/*.out
seed scan_manifest assets/psb3/*.scan.toml tests/fixtures/*/*.scan.toml
# A session: a camera, two panes, an object with a cloud, an isosurface and a clipping plane.
mkdir -p fuzz/seeds/session
cat > fuzz/seeds/session/water.orbcloud.toml <<'SESSION'
background = [0.02, 0.02, 0.03]

[camera]
target = [0.0, 0.0, 0.0]
yaw = 0.3
pitch = -0.2
distance = 20.0
fov_y = 0.5235988
orientation = [0.0, 0.0, 0.0, 1.0]

[panes]
count = 2
linked = false

[[objects]]
path = "water.cube"
selected = 0

[objects.placement]
offset = [1.0, 0.0, -2.0]
rotation_deg = [0.0, 90.0, 0.0]

[objects.clip]
enabled = true
normal = [0.0, 0.0, 1.0]
offset = 0.5

[[objects.quantities]]
visible = true
pane = 1

[objects.quantities.source]
Volume = 0

[objects.quantities.cloud]
visible = true
mode = "ViewAligned"
slices = 192
k1 = 0.2
k2 = 0.6
positive_color = [0.9, 0.12, 0.1]
negative_color = [0.1, 0.3, 0.95]

[objects.quantities.cloud.transfer]
kind = "PowerLaw"
gradient_power = 0.0
shading = false
boundary = 0.0

[objects.quantities.cloud.transfer.positive]
shape = "Gaussian"
center = 0.25
width = 0.08
opacity = 0.9

[objects.quantities.cloud.transfer.negative]
shape = "Gaussian"
center = 0.25
width = 0.08
opacity = 0.9

[[objects.quantities.isosurfaces]]
visible = true
positive_color = [0.85, 0.1, 0.08]
negative_color = [0.08, 0.25, 0.85]
density_color = [0.55, 0.62, 0.75]

[objects.quantities.isosurfaces.level]
Absolute = 0.05
SESSION
# Structures: every record kind of the fixtures but only their first 30 atoms, since AFL's
# speed falls with the input's size (the 18 kB excerpts ran at a fifth of the speed).
seed_short() {
    local target=$1; shift
    mkdir -p "fuzz/seeds/$target"
    for f in "$@"; do
        awk '/^(ATOM|HETATM)/ { if (++n > 30) next } { print }' "$f" > "fuzz/seeds/$target/$(basename "$f")"
    done
}
seed_short pdb tests/fixtures/structures/*.pdb
seed_short mmcif tests/fixtures/structures/*.cif
seed xyz tests/fixtures/structures/*.xyz
mkdir -p fuzz/seeds/cube_gz
for f in fuzz/seeds/cube/*; do gzip -c "$f" > "fuzz/seeds/cube_gz/$(basename "$f").gz"; done

(cd fuzz && cargo afl build --release)
export AFL_SKIP_CPUFREQ=1 AFL_I_DONT_CARE_ABOUT_MISSING_CRASHES=1 AFL_NO_UI=1
run() {
    local target=$1 start=$SECONDS
    rm -rf "fuzz/out/$target"
    mkdir -p fuzz/out
    # -E: stop after about this many executions; -t: a hang is an input taking over 1 s;
    # -m: at most 1 GiB of memory per execution.
    cargo afl fuzz -i "fuzz/seeds/$target" -o "fuzz/out/$target" -E "$execs" -t 1000 -m 1024 \
        "fuzz/target/release/$target" > "fuzz/out/$target.log" 2>&1 || true
    local stats="fuzz/out/$target/default/fuzzer_stats"
    local done crashes hangs
    done=$(awk -F': *' '/^execs_done/ {print $2}' "$stats")
    crashes=$(awk -F': *' '/^saved_crashes/ {print $2}' "$stats")
    hangs=$(awk -F': *' '/^saved_hangs/ {print $2}' "$stats")
    echo "$target: $done executions in $((SECONDS - start)) s, $crashes crashes, $hangs hangs"
}
for ((i = 0; i < ${#targets[@]}; i += 2)); do
    run "${targets[i]}" &
    [ $((i + 1)) -lt ${#targets[@]} ] && run "${targets[i + 1]}" &
    wait
done

"""``orbcloud compute`` and ``orbcloud scan compute``: frames at the values asked, with the
orbitals a direct PySCF calculation gives at each frame's geometry; relaxed frames, Dask, a
killed run resumed, a frame that does not converge, and the Python functions."""

import json
import math
import os
import pathlib
import subprocess
import sys
import time

import numpy as np
import pytest
from pyscf import gto, scf

import orbcloud

from conftest import REPO

BOHR = 0.529177210903

# Hydrogen peroxide, H–O–O–H dihedral 3-1-2-4 near 115°.
H2O2 = """4
hydrogen peroxide
O 0.000000 0.727000 -0.060000
O 0.000000 -0.727000 -0.060000
H 0.839000 0.880000 0.480000
H -0.839000 -0.880000 0.480000
"""

WATER = """3
water
O 0.000000 0.000000 0.000000
H 0.960000 0.000000 0.000000
H -0.240000 0.930000 0.000000
"""


@pytest.fixture(scope="module")
def command():
    path = pathlib.Path(os.environ.get("ORBCLOUD_CLI", REPO / "target" / "debug" / "orbcloud"))
    env = dict(os.environ, ORBCLOUD_PYTHON=sys.executable)

    def run(*args, check=True):
        r = subprocess.run([str(path), *map(str, args)], capture_output=True, text=True, env=env, timeout=600)
        if check and r.returncode != 0:
            raise AssertionError(f"orbcloud {' '.join(map(str, args))} failed:\n{r.stderr}")
        return r

    run.path, run.env = path, env
    return run


def write(folder, name, text):
    path = pathlib.Path(folder) / name
    path.write_text(text)
    return path


def dihedral(p):
    b0, b1, b2 = p[0] - p[1], p[2] - p[1], p[3] - p[2]
    b1 = b1 / np.linalg.norm(b1)
    v, w = b0 - np.dot(b0, b1) * b1, b2 - np.dot(b2, b1) * b1
    return math.degrees(math.atan2(np.dot(np.cross(b1, v), w), np.dot(v, w)))


def distances(p):
    return np.linalg.norm(p[:, None, :] - p[None, :, :], axis=-1)


def log(folder):
    """The first record per file of a scan's compute log (a later run into the folder with
    other settings adds records)."""
    out = {}
    for line in (pathlib.Path(folder) / "compute-log.jsonl").read_text().splitlines():
        r = json.loads(line)
        out.setdefault(r["file"], r)
    return out


def direct_rhf(doc):
    """PySCF's RHF/STO-3G orbital energies at the geometry of ``doc`` (bohr)."""
    z = doc.atoms.numbers
    mol = gto.M(atom=[(int(a), tuple(p)) for a, p in zip(z, doc.atoms.positions)], basis="sto-3g", unit="Bohr", verbose=0)
    mf = scf.RHF(mol)
    mf.conv_tol = 1e-11
    mf.kernel()
    return mf.mo_energy, mf.e_tot


@pytest.fixture(scope="module")
def rigid(command, tmp_path_factory):
    folder = tmp_path_factory.mktemp("rigid")
    xyz = write(folder, "h2o2.xyz", H2O2)
    out = folder / "scan"
    r = command("scan", "compute", xyz, "--dihedral", "3,1,2,4", "--from", 60, "--to", 180, "--step", 30,
                "--method", "hf", "--basis", "sto-3g", "--workers", 1, "-o", out)
    return xyz, out, r


def test_a_rigid_dihedral_scan_has_each_value_and_pyscf_s_orbitals(rigid):
    xyz, out, r = rigid
    scan = orbcloud.load_scan(out / "h2o2.scan.toml")
    assert scan.values == [60.0, 90.0, 120.0, 150.0, 180.0]
    start = np.array([[float(x) for x in line.split()[1:]] for line in H2O2.splitlines()[2:]]) / BOHR
    for value, doc in zip(scan.values, scan.frames):
        p = doc.atoms.positions
        assert abs((dihedral(p[[2, 0, 1, 3]]) - value + 180) % 360 - 180) < 1e-6, value
        # Every other coordinate is the input's: the bonds and the angles at the O–O bond.
        d, d0 = distances(p), distances(start)
        for i, j in [(0, 1), (0, 2), (1, 3), (1, 2), (0, 3)]:
            assert abs(d[i, j] - d0[i, j]) < 1e-6, (value, i, j)
        energies, total = direct_rhf(doc)
        assert np.abs(doc.energies() - energies).max() < 1e-6, value
    manifest = (out / "h2o2.scan.toml").read_text()
    assert "[computed]" in manifest and 'method = "hf"' in manifest and "pyscf" in manifest
    # Each SCF after the first started from its neighbour's density.
    cycles = [json.loads(line)["cycles"] for line in (out / "compute-log.jsonl").read_text().splitlines()]
    assert len(cycles) == 5 and "5 computed" in r.stderr, r.stderr


def test_the_scan_opens_in_scan_info_with_its_record(rigid, command):
    _, out, _ = rigid
    info = command("scan", "info", out / "h2o2.scan.toml").stdout
    assert "dihedral 3-1-2-4, 5 frames" in info, info


def test_a_rerun_keeps_every_frame(rigid, command):
    xyz, out, _ = rigid
    before = {f: (out / f).stat().st_mtime_ns for f in os.listdir(out) if f.endswith(".molden")}
    r = command("scan", "compute", xyz, "--dihedral", "3,1,2,4", "--from", 60, "--to", 180, "--step", 30,
                "--method", "hf", "--basis", "sto-3g", "-o", out)
    assert "0 computed, 5 kept" in r.stderr, r.stderr
    assert before == {f: (out / f).stat().st_mtime_ns for f in before}
    # Other settings compute anew.
    r = command("scan", "compute", xyz, "--dihedral", "3,1,2,4", "--from", 60, "--to", 90, "--step", 30,
                "--method", "hf", "--basis", "3-21g", "--workers", 1, "-o", out)
    assert "2 computed, 0 kept" in r.stderr, r.stderr


def test_a_relaxed_scan_holds_the_coordinate_below_the_rigid_energies(rigid, command, tmp_path):
    xyz, rigid_out, _ = rigid
    out = tmp_path / "relaxed"
    command("scan", "compute", xyz, "--dihedral", "3,1,2,4", "--from", 90, "--to", 150, "--step", 30, "--relaxed",
            "--method", "hf", "--basis", "sto-3g", "--workers", 2, "-o", out)
    scan = orbcloud.load_scan(out / "h2o2.scan.toml")
    assert scan.values == [90.0, 120.0, 150.0]
    relaxed, rigid_log = log(out), log(rigid_out)
    for value, doc in zip(scan.values, scan.frames):
        p = doc.atoms.positions
        assert abs(dihedral(p[[2, 0, 1, 3]]) - value) < 0.02, (value, dihedral(p[[2, 0, 1, 3]]))
        name = f"h2o2_dihedral{value:.2f}.molden"
        assert relaxed[name]["energy"] <= rigid_log[name]["energy"] + 1e-8, value
        assert relaxed[name]["energy"] < rigid_log[name]["energy"] - 1e-5, "the geometry relaxed"
        # The file's orbitals are those of its (optimised) geometry.
        energies, total = direct_rhf(doc)
        assert abs(total - relaxed[name]["energy"]) < 1e-6
        assert np.abs(doc.energies() - energies).max() < 1e-6


def test_a_dask_cluster_computes_the_same_frames(rigid, command, tmp_path):
    distributed = pytest.importorskip("distributed", reason="dask[distributed] is in requirements-test.txt")
    xyz, rigid_out, _ = rigid
    out = tmp_path / "dask"
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        command("scan", "compute", xyz, "--dihedral", "3,1,2,4", "--from", 60, "--to", 180, "--step", 30,
                "--method", "hf", "--basis", "sto-3g", "--dask", cluster.scheduler_address, "-o", out)
        with distributed.Client(cluster) as client:
            # Every task the scheduler ran, by name: each frame was one.
            ran = client.run_on_scheduler(
                lambda dask_scheduler: {k: v.state_counts["memory"] for k, v in dask_scheduler.task_prefixes.items()}
            )
    assert ran.get("compute_frame") == 5, ran
    a, b = log(out), log(rigid_out)
    for name, record in a.items():
        assert abs(record["energy"] - b[name]["energy"]) < 1e-8, name


def test_a_killed_run_resumes(command, tmp_path):
    xyz = write(tmp_path, "h2o2.xyz", H2O2)
    out = tmp_path / "killed"
    args = ["scan", "compute", xyz, "--dihedral", "3,1,2,4", "--from", 0, "--to", 180, "--step", 20,
            "--method", "hf", "--basis", "6-31g", "--workers", 1, "-o", out]
    p = subprocess.Popen([str(command.path), *map(str, args)], stderr=subprocess.PIPE, text=True, env=command.env)
    seen = 0
    for line in p.stderr:
        if " E = " in line:
            seen += 1
            if seen == 3:
                break
    p.kill()
    p.wait()
    assert seen == 3
    # The computing process ends with the command: nothing writes into the folder after it.
    time.sleep(2)
    files = sorted(f for f in os.listdir(out) if f.endswith(".molden"))
    time.sleep(2)
    assert files == sorted(f for f in os.listdir(out) if f.endswith(".molden"))
    assert 3 <= len(files) < 10 and not (out / "h2o2.scan.toml").exists()
    r = command(*args)
    kept = int(r.stderr.split(" kept,")[0].split()[-1])
    assert kept == len(files), r.stderr
    assert len(orbcloud.load_scan(out / "h2o2.scan.toml").values) == 10


def test_a_frame_that_does_not_converge_is_named_and_left_out(command, tmp_path):
    # RHF of water with one O–H at 3 Å does not converge from PySCF's initial guess in 40
    # cycles; three workers start each frame from that guess.
    xyz = write(tmp_path, "water.xyz", WATER)
    out = tmp_path / "stretch"
    r = command("scan", "compute", xyz, "--distance", "1,2", "--from", 1.0, "--to", 3.0, "--step", 1.0,
                "--method", "hf", "--basis", "sto-3g", "--workers", 3, "--max-cycles", 40, "-o", out)
    assert "frame at 3.000 Å left out: the SCF did not converge in 40 cycles" in r.stderr, r.stderr
    scan = orbcloud.load_scan(out / "water.scan.toml")
    assert scan.values == [1.0, 2.0]
    assert "failed = [3.0000]" in (out / "water.scan.toml").read_text()


def test_an_angle_scan_and_a_trajectory(command, tmp_path):
    xyz = write(tmp_path, "water.xyz", WATER)
    r = command("scan", "compute", xyz, "--angle", "2,1,3", "--from", 95, "--to", 115, "--step", 10,
                "--method", "hf", "--basis", "sto-3g", "-o", tmp_path / "bend")
    scan = orbcloud.load_scan(tmp_path / "bend" / "water.scan.toml")
    assert scan.values == [95.0, 105.0, 115.0] and scan.coordinate == "angle 2-1-3", r.stderr
    for value, doc in zip(scan.values, scan.frames):
        p = doc.atoms.positions
        u, v = p[1] - p[0], p[2] - p[0]
        assert abs(math.degrees(math.acos(np.dot(u, v) / np.linalg.norm(u) / np.linalg.norm(v))) - value) < 1e-6
    frames = "".join(
        f"3\nframe {i}\nO 0 0 0\nH {0.96 + 0.05 * i:.3f} 0 0\nH -0.24 0.93 0\n" for i in range(3)
    )
    path = write(tmp_path, "path.xyz", frames)
    command("scan", "compute", path, "--frames", "--method", "hf", "--basis", "sto-3g", "-o", tmp_path / "path")
    scan = orbcloud.load_scan(tmp_path / "path" / "path.scan.toml")
    assert scan.coordinate == "path" and len(scan.frames) == 3
    for i, doc in enumerate(scan.frames):
        assert abs(doc.atoms.positions[1][0] * BOHR - (0.96 + 0.05 * i)) < 1e-6


def test_a_single_point_with_normal_modes(command, tmp_path):
    xyz = write(tmp_path, "water.xyz", WATER)
    r = command("compute", xyz, "--method", "hf", "--basis", "sto-3g", "--freq")
    path = tmp_path / "water.molden"
    assert r.stdout.strip() == str(path)
    doc = orbcloud.load(path)
    energies, total = direct_rhf(doc)
    assert np.abs(doc.energies() - energies).max() < 1e-6
    info = json.loads(command("info", path, "--json").stdout)
    text = json.dumps(info)
    assert "vibrations" in text or "modes" in text, text[:400]
    # PySCF's own harmonic analysis at the file's geometry.
    from pyscf.hessian import thermo

    mol = gto.M(atom=[(int(a), tuple(p)) for a, p in zip(doc.atoms.numbers, doc.atoms.positions)], basis="sto-3g", unit="Bohr", verbose=0)
    mf = scf.RHF(mol).run()
    wavenumbers = np.sort(np.real(thermo.harmonic_analysis(mol, mf.Hessian().kernel())["freq_wavenumber"]))
    molden = path.read_text()
    written = [float(x) for x in molden.split("[FREQ]")[1].split("[FR-COORD]")[0].split()]
    assert len(written) == 3 and np.abs(np.sort(written) - wavenumbers).max() < 1e-2, (written, wavenumbers)
    # orbcloud reads the intensities as the spectrum's heights.
    modes = json.loads(command("info", path, "--json").stdout)["modes"]
    assert all(m["ir_intensity"] is not None and m["ir_intensity"] > 1.0 for m in modes), modes


def intensities_along_modes(mol, mf, step=1e-3):
    """IR intensities (km/mol) from the dipole displaced along each normal mode itself, a
    different route from the file's (Cartesian derivatives projected on the modes)."""
    from pyscf.hessian import thermo

    modes = thermo.harmonic_analysis(mol, mf.Hessian().kernel())["norm_mode"]
    scanner, out = mf.as_scanner(), []
    for mode in modes:
        mu = []
        for sign in (1, -1):
            scanner(mol.set_geom_(mol.atom_coords() + sign * step * mode, unit="Bohr", inplace=False))
            mu.append(scanner.dip_moment(unit="AU", verbose=0))
        out.append(974.8801 * (((mu[0] - mu[1]) / (2 * step)) ** 2).sum())
    return np.array(out)


def test_ir_intensities_follow_the_dipole_and_vanish_where_symmetry_forbids(command, tmp_path):
    # CO2: the symmetric stretch leaves the dipole zero (IR-inactive); the bends and the
    # asymmetric stretch are active.
    xyz = write(tmp_path, "co2.xyz", "3\ncarbon dioxide\nO 0 0 0\nC 0 0 1.16\nO 0 0 2.32\n")
    command("compute", xyz, "--method", "hf", "--basis", "sto-3g", "--freq")
    molden = (tmp_path / "co2.molden").read_text()
    freq = [float(x) for x in molden.split("[FREQ]")[1].split("[FR-COORD]")[0].split()]
    inten = np.array([float(x) for x in molden.split("[INT]")[1].split()])
    assert len(freq) == len(inten) == 4
    doc = orbcloud.load(tmp_path / "co2.molden")
    mol = gto.M(atom=[(int(a), tuple(p)) for a, p in zip(doc.atoms.numbers, doc.atoms.positions)], basis="sto-3g", unit="Bohr", verbose=0)
    mf = scf.RHF(mol)
    mf.conv_tol = 1e-11
    mf.run()
    reference = intensities_along_modes(mol, mf)
    # Both lists in PySCF's order of wavenumbers: the bends (a degenerate pair, any rotation of
    # it: compared as a pair), the symmetric stretch, the asymmetric stretch.
    assert list(np.argsort(freq)) == [0, 1, 2, 3], freq
    assert inten[2] < 0.01 and reference[2] < 0.01, (inten, reference)
    assert inten[3] > 100, inten
    assert abs(inten[:2].sum() - reference[:2].sum()) < 0.01 * reference[:2].sum(), (inten, reference)
    assert abs(inten[3] - reference[3]) < 0.01 * reference[3], (inten, reference)


def test_the_python_functions_compute_and_scan(tmp_path):
    mol = gto.M(atom="O 0 0 0; H 0.96 0 0; H -0.24 0.93 0", basis="sto-3g", verbose=0)
    doc = orbcloud.compute(mol, method="hf", basis="sto-3g", output=tmp_path / "w.molden")
    mf = scf.RHF(mol).run(verbose=0)
    assert np.abs(doc.energies() - mf.mo_energy).max() < 1e-6
    scan = orbcloud.scan_compute(mol, tmp_path / "scan", angle=(2, 1, 3), start=100, stop=110, step=10, method="hf", basis="sto-3g")
    assert scan.values == [100.0, 110.0] and len(scan.frames) == 2


def test_missing_pyscf_says_what_to_install(command, tmp_path):
    # An interpreter that sees no site packages stands for one without PySCF.
    wrapper = write(tmp_path, "python-bare", f"#!/bin/sh\nexec {sys.executable} -S \"$@\"\n")
    wrapper.chmod(0o755)
    xyz = write(tmp_path, "water.xyz", WATER)
    env = dict(command.env, ORBCLOUD_PYTHON=str(wrapper))
    r = subprocess.run([str(command.path), "compute", str(xyz)], capture_output=True, text=True, env=env)
    assert r.returncode != 0
    assert "pip install pyscf" in r.stderr and "ORBCLOUD_PYTHON" in r.stderr, r.stderr

"""``load`` reads every fixture as the command does: the same values as ``orbcloud eval``,
the same atoms as ``orbcloud info``; errors carry the file and line."""

import json

import numpy as np
import pytest

import orbcloud
from conftest import FIXTURES

WAVEFUNCTIONS = (".molden", ".fchk", ".wfn", ".wfx", ".mkl")
STRUCTURES = (".cube", ".pdb", ".cif", ".xyz")


def kind(path):
    name = path.name.removesuffix(".gz")
    return next((k for k in WAVEFUNCTIONS + STRUCTURES if name.endswith(k)), None)


ALL = sorted(p for p in FIXTURES.rglob("*") if p.is_file() and kind(p))


def test_there_are_fixtures():
    assert sum(kind(p) in WAVEFUNCTIONS for p in ALL) >= 30, ALL


def points_near(doc, n=40, seed=3):
    """Points around the atoms, rounded as the command reads them from text."""
    rng = np.random.default_rng(seed)
    positions = doc.atoms.positions
    points = positions[rng.integers(0, len(positions), n)] + rng.normal(scale=1.2, size=(n, 3))
    return np.array([[float(f"{x:.10f}") for x in p] for p in points])


def cli_eval(cli, path, points, tmp_path, *what):
    points_file = tmp_path / "points.txt"
    np.savetxt(points_file, points, fmt="%.10f")
    out = cli("eval", path, "--points", points_file, *what).stdout
    rows = np.loadtxt(out.splitlines(), ndmin=2)
    return rows[:, 3]


@pytest.mark.parametrize("path", ALL, ids=lambda p: str(p.relative_to(FIXTURES)))
def test_load_matches_the_command(path, cli, tmp_path):
    doc = orbcloud.load(path)
    info = json.loads(cli("info", "--json", path).stdout)
    assert [a["z"] for a in info["atoms"]] == list(doc.atoms.numbers)
    np.testing.assert_allclose(doc.atoms.positions, [a["position_bohr"] for a in info["atoms"]], rtol=0, atol=1e-12)
    if kind(path) not in WAVEFUNCTIONS:
        return
    # A file of geometries without orbitals (a relaxed scan's fchk): neither reads any.
    assert doc.has_wavefunction == (info["wavefunction"] is not None)
    if not doc.has_wavefunction:
        return
    points = points_near(doc)
    for what, mine in [
        (("--orbital", "homo"), doc.evaluate(points, "homo")),
        (("--orbital", "lumo", "--spin", "beta"), doc.evaluate(points, "lumo", spin="beta"))
        if not doc.restricted and any(o.spin == "beta" for o in doc.orbitals)
        else (("--orbital", "1"), doc.evaluate(points, 0)),
        (("--density",), doc.density(points)),
    ]:
        theirs = cli_eval(cli, path, points, tmp_path, *what)
        scale = max(1.0, np.abs(theirs).max())
        assert np.abs(mine - theirs).max() <= 1e-12 * scale, what


def test_document_describes_the_file():
    doc = orbcloud.load(FIXTURES / "wavefunctions" / "h2o_ccpvtz.molden")
    assert doc.has_wavefunction and doc.restricted
    assert doc.repair == "none" and doc.residual < 1e-8
    orbitals = doc.orbitals
    assert len(orbitals) == 58 and orbitals[0].spin == "alpha"
    assert orbitals[4].occupation == 2.0 and orbitals[5].occupation == 0.0
    assert doc.orbital_index("homo") == 4 and doc.orbital_index("lumo+1") == 6
    assert doc.basis_functions[0].startswith("O1")


def test_esp_matches_pyscf():
    # The references of tests/fixtures/esp (PySCF's int1e_rinv at points).
    for name in ["h2o_ccpvtz", "h2o_cation_uhf_631gs", "h2_spdfgh"]:
        ref = json.loads((FIXTURES / "esp" / f"{name}.json").read_text())
        doc = orbcloud.load(FIXTURES / ref["source"])
        got = doc.esp(np.array(ref["points"]))
        assert np.abs(got - np.array(ref["esp"])).max() < 1e-6, name


def test_errors_carry_file_and_line(tmp_path):
    bad = tmp_path / "broken.cube"
    bad.write_text("title\ncomment\n    3    0.0 0.0 0.0\n    2 0.5 0.0 0.0\n    2 0.0 0.5 0.0\n    2 0.0 0.0 0.5\n")
    with pytest.raises(orbcloud.LoadError) as e:
        orbcloud.load(bad)
    # The header's atom count (line 3) promises atom lines the file does not have.
    assert e.value.file == str(bad) and e.value.line == 3, (e.value, e.value.file, e.value.line)
    assert str(e.value).startswith(f"{bad}:3: expected an atom count")
    with pytest.raises(orbcloud.LoadError) as e:
        orbcloud.load(tmp_path / "missing.molden")
    assert e.value.file.endswith("missing.molden") and e.value.line is None
    doc = orbcloud.load(FIXTURES / "wavefunctions" / "h2o_ccpvtz.molden")
    with pytest.raises(ValueError, match="lumo\\+99"):
        doc.evaluate(np.zeros((1, 3)), "lumo+99")
    with pytest.raises(ValueError, match="shape"):
        doc.evaluate(np.zeros((4, 2)))


def test_view_returns_at_once():
    """The desktop viewer runs in a process of its own; a PySCF document goes through a Molden
    file that orbcloud reads back as the same orbitals."""
    import time

    from pyscf import gto, scf

    mol = gto.M(atom="H 0 0 0; H 0 0 1.4", basis="6-31g", unit="Bohr", verbose=0)
    doc = orbcloud.from_pyscf(scf.RHF(mol).run())
    start = time.monotonic()
    process = doc.view()
    try:
        assert time.monotonic() - start < 5
        assert process.args[1:4] == ["-m", "orbcloud", "view"]
        written = orbcloud.load(process.args[4])
        points = np.random.default_rng(0).normal(size=(50, 3))
        np.testing.assert_allclose(np.abs(written.evaluate(points, "homo")), np.abs(doc.evaluate(points, "homo")), atol=1e-8)
    finally:
        process.kill()
        process.wait()

"""``from_pyscf`` gives PySCF's own orbitals: values equal ``eval_gto`` × coefficients."""

import numpy as np
import pytest
from pyscf import gto, scf

import orbcloud

TOLERANCE = 1e-10


def points_near(mol, n=400, seed=1):
    rng = np.random.default_rng(seed)
    centres = mol.atom_coords()[rng.integers(0, mol.natm, n)]
    return centres + rng.normal(scale=1.5, size=(n, 3))


def orthonormal(mol):
    """Löwdin orbitals S^-1/2: orthonormal over any basis, no SCF needed."""
    s = mol.intor_symmetric("int1e_ovlp")
    w, v = np.linalg.eigh(s)
    return v @ np.diag(w**-0.5) @ v.T


def check(doc, mol, coefficients, spin="alpha"):
    points = points_near(mol)
    reference = mol.eval_gto("GTOval", points) @ coefficients
    for i in range(coefficients.shape[1]):
        got = doc.evaluate(points, i, spin=spin)
        err = np.abs(got - reference[:, i]).max()
        assert err <= TOLERANCE, f"orbital {i} ({spin}): max error {err:.3g}"


# Up to g functions, cartesian and pure: N₂ in cc-pVQZ has s…g on each atom; the second
# molecule has general contractions (several per shell) and diffuse functions.
@pytest.mark.parametrize("cart", [False, True], ids=["pure", "cartesian"])
@pytest.mark.parametrize(
    "atom,basis",
    [("N 0 0 -1.04; N 0 0 1.04", "cc-pvqz"), ("O 0 0 0.12; H 0 0.76 -0.47; H 0.1 -0.77 -0.46", "aug-cc-pvtz")],
    ids=["n2_ccpvqz", "h2o_augccpvtz"],
)
def test_values_equal_pyscf_up_to_g(atom, basis, cart):
    mol = gto.M(atom=atom, basis=basis, cart=cart, unit="Bohr", verbose=0)
    assert max(mol.bas_angular(i) for i in range(mol.nbas)) == (4 if "qz" in basis else 3)
    assert max(mol.bas_nctr(i) for i in range(mol.nbas)) >= 2
    c = orthonormal(mol)
    n = c.shape[1]
    doc = orbcloud.from_pyscf(mol, c, np.r_[np.full(n // 2, 2.0), np.zeros(n - n // 2)], np.arange(n, dtype=float))
    assert doc.writer == "PySCF" and doc.repair == "none" and doc.residual < 1e-8
    assert doc._native.n_basis == mol.nao_nr()
    check(doc, mol, c)


def test_restricted_scf_object():
    mol = gto.M(atom="O 0 0 0.1; H 0 0.75 -0.5; H 0 -0.8 -0.45", basis="6-31g*", verbose=0)
    mf = scf.RHF(mol).run()
    doc = orbcloud.from_pyscf(mf)
    check(doc, mol, mf.mo_coeff)
    assert doc.restricted
    np.testing.assert_allclose(doc.energies(), mf.mo_energy)
    np.testing.assert_allclose(doc.occupations(), mf.mo_occ)
    np.testing.assert_allclose(doc.atoms.positions, mol.atom_coords())
    assert list(doc.atoms.numbers) == [8, 1, 1]
    homo = int(np.flatnonzero(mf.mo_occ > 0)[-1])
    assert doc.orbital_index("homo") == homo
    points = points_near(mol)
    np.testing.assert_allclose(doc.evaluate(points, "lumo"), doc.evaluate(points, homo + 1))
    ao = mol.eval_gto("GTOval", points)
    rho = np.einsum("pi,ij,pj->p", ao, mf.make_rdm1(), ao)
    np.testing.assert_allclose(doc.density(points), rho, atol=TOLERANCE)


def test_unrestricted_scf_object():
    mol = gto.M(atom="O 0 0 0.1; H 0 0.75 -0.5; H 0 -0.8 -0.45", basis="6-31g", charge=1, spin=1, verbose=0)
    mf = scf.UHF(mol).run()
    doc = orbcloud.from_pyscf(mf)
    assert doc.restricted is False
    check(doc, mol, mf.mo_coeff[0], "alpha")
    check(doc, mol, mf.mo_coeff[1], "beta")
    points = points_near(mol)
    ao = mol.eval_gto("GTOval", points)
    da, db = mf.make_rdm1()
    spin = np.einsum("pi,ij,pj->p", ao, da - db, ao)
    np.testing.assert_allclose(doc.density(points, spin_density=True), spin, atol=TOLERANCE)


def test_grid_and_cube(tmp_path):
    mol = gto.M(atom="H 0 0 0; H 0 0 1.4", basis="sto-3g", unit="Bohr", verbose=0)
    mf = scf.RHF(mol).run()
    doc = orbcloud.from_pyscf(mf)
    grid = doc.grid("homo", points=12)
    assert grid.values.shape == (12, 12, 12)
    reference = mol.eval_gto("GTOval", grid.points()) @ mf.mo_coeff[:, 0]
    np.testing.assert_allclose(grid.values.ravel(), reference, atol=TOLERANCE)
    doc.write_cube(tmp_path / "h2.cube", "homo", points=12)
    cube = orbcloud.load(tmp_path / "h2.cube")
    assert len(cube.volumes) == 1 and len(cube.atoms.numbers) == 2


@pytest.mark.parametrize("cart", [False, True], ids=["pure", "cartesian"])
def test_esp_of_a_pyscf_calculation_matches_pyscf(cart):
    # V(C) = Σ Z/|C − R| − Σ P_μν (μ|1/r_C|ν), PySCF's int1e_rinv per point, d and f functions.
    mol = gto.M(atom="O 0 0 0.12; H 0 0.76 -0.47; H 0.1 -0.77 -0.46", basis="cc-pvtz", cart=cart, verbose=0)
    mf = scf.RHF(mol).run(conv_tol=1e-10)
    dm = mf.make_rdm1()
    points = points_near(mol, n=30, seed=4)
    reference = []
    for c in points:
        with mol.with_rinv_origin(c):
            v = mol.intor("int1e_rinv")
        nuclear = sum(q / np.linalg.norm(c - r) for q, r in zip(mol.atom_charges(), mol.atom_coords()))
        reference.append(nuclear - np.einsum("ij,ij", dm, v))
    got = orbcloud.from_pyscf(mf).esp(points)
    assert np.abs(got - np.array(reference)).max() < 1e-6

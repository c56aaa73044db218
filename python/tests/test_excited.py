"""``from_pyscf(td)``: a TD calculation's states, natural transition orbitals and densities
equal what PySCF computes of the same amplitudes (``get_nto``, ``eval_gto``, the unrelaxed
difference density its TDDFT gradients build)."""

import copy
import os
import pathlib

import numpy as np
import pytest
from pyscf import dft, gto, scf, tdscf
from pyscf.data import nist

import orbcloud

from conftest import REPO

WATER = "O 0 0 0.1173; H 0 0.7572 -0.4692; H 0 -0.7572 -0.4692"
STATES = 4
TOLERANCE = 1e-6
# How far orbcloud's values are from PySCF's (printed with -s): the tests hold them under TOLERANCE.
DEVIATIONS: dict[str, float] = {}


def note(what: str, deviation: float) -> float:
    DEVIATIONS[what] = max(DEVIATIONS.get(what, 0.0), float(deviation))
    return float(deviation)


def points_near(mol, n=300, seed=3):
    rng = np.random.default_rng(seed)
    centres = mol.atom_coords()[rng.integers(0, mol.natm, n)]
    return centres + rng.normal(scale=1.2, size=(n, 3))


@pytest.fixture(scope="module")
def rhf():
    mol = gto.M(atom=WATER, basis="6-31g", verbose=0)
    return scf.RHF(mol).run(conv_tol=1e-11)


@pytest.fixture(scope="module")
def rks():
    mol = gto.M(atom=WATER, basis="6-31g", verbose=0)
    return dft.RKS(mol, xc="b3lyp").run(conv_tol=1e-11)


def run(kind, rhf, rks, singlet=True):
    make = {"tda": lambda: tdscf.TDA(rhf), "tdhf": lambda: tdscf.TDHF(rhf), "tddft": lambda: tdscf.TDDFT(rks)}[kind]
    td = make()
    td.nstates = STATES
    td.singlet = singlet
    td.conv_tol = 1e-10
    return td.run()


@pytest.fixture(scope="module", params=["tda", "tdhf", "tddft"])
def calculation(request, rhf, rks):
    """A TD calculation and its document, made before any ``get_nto`` (which rescales X in place)."""
    td = run(request.param, rhf, rks)
    return request.param, td, orbcloud.from_pyscf(td)


def reference_nto(td, state):
    """PySCF's ``get_nto`` of a copy of the amplitudes (it rescales ``td.xy`` in place)."""
    saved = td.xy
    td.xy = copy.deepcopy(saved)
    try:
        return td.get_nto(state=state, verbose=0)
    finally:
        td.xy = saved


def amplitudes(td, state):
    x, y = td.xy[state - 1]
    return np.asarray(x), (np.asarray(y) if isinstance(y, np.ndarray) else np.zeros_like(x))


def test_states_carry_pyscf_energies_strengths_and_transitions(calculation):
    kind, td, doc = calculation
    states = doc.states
    assert [s.number for s in states] == list(range(1, STATES + 1))
    energies = np.array([s.energy_ev for s in states])
    assert note("state energy (eV)", np.abs(energies - td.e * nist.HARTREE2EV).max()) < 1e-9
    np.testing.assert_allclose([s.wavelength_nm for s in states], 1239.841984 / energies, rtol=1e-12)
    np.testing.assert_allclose([s.oscillator_strength for s in states], td.oscillator_strength(), atol=1e-12)
    np.testing.assert_allclose([s.total_energy for s in states], td._scf.e_tot + td.e, atol=1e-12)
    assert all(s.spin == "Singlet" for s in states)
    assert doc.excitation_method == {"tda": "PySCF TDA (HF)", "tdhf": "PySCF TDHF (HF)", "tddft": "PySCF TDDFT (B3LYP)"}[kind]
    nocc = int((td._scf.mo_occ > 0).sum())
    for s in states:
        x, _ = amplitudes(td, s.number)
        main = s.transitions[0]
        i, a = np.unravel_index(np.abs(x).argmax(), x.shape)
        assert (main.from_orbital, main.to_orbital, main.deexcitation) == (i + 1, nocc + a + 1, False)
        assert main.coefficient == pytest.approx(x[i, a], abs=1e-12)
        assert all(abs(t.coefficient) >= 0.1 for t in s.transitions)
    # The command line's description lists them.
    text = doc.info()
    assert f"{STATES} excited states" in text and "PySCF" in text


def test_nto_weights_equal_get_nto(calculation):
    _, td, doc = calculation
    for state in range(1, STATES + 1):
        nto = doc.nto(state)
        weights, _ = reference_nto(td, state)
        n = min(len(weights), len(nto.weights))
        assert note("NTO weights", np.abs(nto.weights[:n] - weights[:n]).max()) < TOLERANCE
        assert np.all(np.diff(nto.weights) <= 1e-15)
        assert abs(nto.weights.sum() - 1) < 1e-12
        assert nto.state_number == state


def test_dominant_nto_pair_values_equal_get_nto(calculation):
    # Sign convention (get_nto's): each NTO's largest coefficient over the MOs is positive, so
    # the values are compared with their signs.
    _, td, doc = calculation
    mol = td.mol
    nocc = int((td._scf.mo_occ > 0).sum())
    points = points_near(mol)
    ao = mol.eval_gto("GTOval", points)
    for state in range(1, STATES + 1):
        nto = doc.nto(state)
        weights, coefficients = reference_nto(td, state)
        hole, particle = ao @ coefficients[:, 0], ao @ coefficients[:, nocc]
        assert note("hole 1 values", np.abs(nto.evaluate(points, "hole 1") - hole).max()) < TOLERANCE
        assert note("particle 1 values", np.abs(nto.evaluate(points, "particle 1") - particle).max()) < TOLERANCE
        # By index too: hole k is orbital 2(k − 1), particle k orbital 2k − 1.
        np.testing.assert_array_equal(nto.evaluate(points, 1), nto.evaluate(points, "particle 1"))
        orbitals = nto.orbitals
        assert [o.label for o in orbitals[:4]] == ["hole 1", "particle 1", "hole 2", "particle 2"]
        assert all(np.isnan(o.energy) for o in orbitals)
        np.testing.assert_allclose([o.occupation for o in orbitals[::2]], nto.weights)
        np.testing.assert_allclose([o.occupation for o in orbitals[1::2]], nto.weights)
        assert nto.residual < 1e-8


def unrelaxed_difference(td, state):
    """ΔP (AO) as PySCF's TDDFT gradients build it (pyscf/grad/tdrhf.py: dmzoo)."""
    x, y = amplitudes(td, state)
    mo, occ = td._scf.mo_coeff, td._scf.mo_occ
    orbo, orbv = mo[:, occ > 0], mo[:, occ == 0]
    xpy, xmy = (x + y).T, (x - y).T
    dvv = xpy @ xpy.T + xmy @ xmy.T
    doo = -(xpy.T @ xpy) - xmy.T @ xmy
    return orbo @ doo @ orbo.T + orbv @ dvv @ orbv.T


def test_difference_attachment_and_detachment_densities(calculation):
    kind, td, doc = calculation
    mol = td.mol
    points = points_near(mol, n=200, seed=5)
    ao = mol.eval_gto("GTOval", points)
    ground = np.einsum("pi,ij,pj->p", ao, td._scf.make_rdm1(), ao)
    for state in range(1, STATES + 1):
        x, y = amplitudes(td, state)
        delta = np.einsum("pi,ij,pj->p", ao, unrelaxed_difference(td, state), ao)
        got = doc.evaluate(points, quantity="difference density", state=state)
        assert note("difference density values", np.abs(got - delta).max()) < TOLERANCE
        attachment = doc.evaluate(points, quantity="attachment", state=state)
        detachment = doc.evaluate(points, quantity="detachment", state=state)
        assert attachment.min() >= -1e-12 and detachment.min() >= -1e-12
        assert np.abs(attachment - detachment - got).max() < 1e-10
        excited = doc.evaluate(points, quantity="excited density", state=state)
        assert np.abs(excited - ground - got).max() < 1e-9
        # The attachment holds the electrons the amplitudes move: 2(|X|² + |Y|²), 1 for TDA.
        moved = 2 * (np.sum(x**2) + np.sum(y**2))
        held = doc.state(state)
        assert held.density_state == state
        attached, detached = held.electrons_moved
        assert note("attachment trace − electrons moved", abs(attached - moved)) < 1e-9
        assert abs(detached - moved) < 1e-9
        if kind == "tda":
            assert abs(attached - 1) < 1e-9
        else:
            assert attached > 1
    # The same through the state's document and on a grid.
    held = doc.state(1)
    np.testing.assert_array_equal(held.evaluate(points, quantity="attachment"), doc.evaluate(points, quantity="attachment", state=1))
    grid = doc.grid(quantity="detachment", state=1, points=10)
    assert grid.values.shape == (10, 10, 10) and grid.values.min() >= -1e-12
    assert "electrons moved" in held.info()


def test_triplets(rhf, rks):
    td = run("tddft", rhf, rks, singlet=False)
    doc = orbcloud.from_pyscf(td)
    assert all(s.spin == "Triplet" and s.oscillator_strength == 0 for s in doc.states)
    np.testing.assert_allclose([s.energy_ev for s in doc.states], td.e * nist.HARTREE2EV, atol=1e-9)
    weights, _ = reference_nto(td, 1)
    n = len(doc.nto(1).weights)
    assert np.abs(doc.nto(1).weights - weights[:n]).max() < TOLERANCE
    # The total density of the triplet's M_S = 0 component moves the same way.
    assert abs(doc.state(1).electrons_moved[0] - 2 * sum(np.sum(a**2) for a in amplitudes(td, 1))) < 1e-9


def test_unrestricted_tda():
    mol = gto.M(atom=WATER, basis="6-31g", charge=1, spin=1, verbose=0)
    mf = scf.UHF(mol).run(conv_tol=1e-11)
    td = tdscf.TDA(mf)
    td.nstates = 3
    td.run(conv_tol=1e-10)
    doc = orbcloud.from_pyscf(td)
    np.testing.assert_allclose([s.energy_ev for s in doc.states], td.e * nist.HARTREE2EV, atol=1e-9)
    assert all(t.spin in ("alpha", "beta") for s in doc.states for t in s.transitions)
    points = points_near(mol, n=100)
    ao = mol.eval_gto("GTOval", points)
    for state in (1, 2, 3):
        nto = doc.nto(state)
        (wa, wb), (ca, cb) = reference_nto(td, state)
        assert nto.restricted is False
        assert np.abs(nto.weights[0] - wa[: len(nto.weights[0])]).max() < TOLERANCE
        assert np.abs(nto.weights[1] - wb[: len(nto.weights[1])]).max() < TOLERANCE
        assert abs(sum(w.sum() for w in nto.weights) - 1) < 1e-12
        spin = "alpha" if wa[0] >= wb[0] else "beta"
        c, nocc = (ca, mol.nelec[0]) if spin == "alpha" else (cb, mol.nelec[1])
        assert np.abs(nto.evaluate(points, "hole 1", spin=spin) - ao @ c[:, 0]).max() < TOLERANCE
        assert np.abs(nto.evaluate(points, "particle 1", spin=spin) - ao @ c[:, nocc]).max() < TOLERANCE
        # ΔP = Σ_σ C_vir,σ XσᵀXσ C_vir,σᵀ − C_occ,σ XσXσᵀ C_occ,σᵀ. Its attachment holds |X|² = 1
        # electron only where the alpha and beta spaces coincide: the two spins' parts of the
        # total density partly cancel, so a little less, as much as the detachment.
        delta = 0
        for s, x in enumerate(td.xy[state - 1][0]):
            c, occ = mf.mo_coeff[s], mf.mo_occ[s]
            orbo, orbv = c[:, occ > 0], c[:, occ == 0]
            delta = delta + orbv @ x.T @ x @ orbv.T - orbo @ x @ x.T @ orbo.T
        reference = np.einsum("pi,ij,pj->p", ao, delta, ao)
        got = doc.evaluate(points, quantity="difference density", state=state)
        assert note("difference density values", np.abs(got - reference).max()) < TOLERANCE
        attached, detached = doc.state(state).electrons_moved
        assert abs(attached - detached) < 1e-9 and 0.99 < attached <= 1 + 1e-12


def test_symmetry_labels_and_frozen_core():
    mol = gto.M(atom=WATER, basis="6-31g", symmetry=True, verbose=0)
    mf = scf.RHF(mol).run()
    td = tdscf.TDA(mf).run(nstates=3)
    doc = orbcloud.from_pyscf(td)
    assert [s.symmetry for s in doc.states] == ["B1", "A2", "A1"]
    for state in (1, 2, 3):
        weights, _ = reference_nto(td, state)
        assert np.abs(doc.nto(state).weights - weights[: len(doc.nto(state).weights)]).max() < TOLERANCE
    td = tdscf.TDA(mf)
    td.frozen = 1
    td.run(nstates=2)
    doc = orbcloud.from_pyscf(td)
    assert doc.states[0].transitions[0].from_orbital == 5  # numbered among all orbitals
    weights, _ = reference_nto(td, 1)
    assert np.abs(doc.nto(1).weights - weights[: len(doc.nto(1).weights)]).max() < TOLERANCE
    assert abs(doc.state(1).electrons_moved[0] - 1) < 1e-9


def test_document_made_after_get_nto_is_the_same():
    # get_nto rescales X to 1 in place; the document's amplitudes are rescaled back.
    mol = gto.M(atom=WATER, basis="sto-3g", verbose=0)
    td = tdscf.TDA(scf.RHF(mol).run()).run(nstates=2)
    before = orbcloud.from_pyscf(td)
    td.get_nto(state=1, verbose=0)
    after = orbcloud.from_pyscf(td)
    np.testing.assert_allclose(after.nto(1).weights, before.nto(1).weights, atol=1e-14)
    assert abs(after.state(1).electrons_moved[0] - 1) < 1e-12


def test_refusals(rhf):
    td = tdscf.TDA(rhf).run(nstates=2)
    doc = orbcloud.from_pyscf(td)
    points = np.zeros((1, 3))
    with pytest.raises(ValueError, match="state=k"):
        doc.evaluate(points, quantity="attachment")
    with pytest.raises(ValueError, match="states 1 to 2"):
        doc.state(3)
    with pytest.raises(ValueError, match="states 1 to 2"):
        doc.nto(0)
    with pytest.raises(ValueError, match="quantity"):
        doc.evaluate(points, quantity="hole density", state=1)
    ground = orbcloud.from_pyscf(rhf)
    assert ground.states == [] and ground.weights is None
    with pytest.raises(ValueError, match="amplitudes"):
        ground.nto(1)
    with pytest.raises(ValueError, match="holds none|not known"):
        ground.evaluate(points, quantity="attachment", state=1)
    with pytest.raises(ValueError):
        orbcloud.from_pyscf(tdscf.TDA(rhf))  # not run


def test_render_of_states_and_ntos(rhf):
    td = tdscf.TDA(rhf).run(nstates=2)
    doc = orbcloud.from_pyscf(td)
    img = orbcloud.render(doc, size=(64, 48), attachment=True, state=2, iso=0.01, lavapipe=True)
    assert img.shape == (48, 64, 4)
    nto = doc.nto(1)
    img = nto.render(size=(64, 48), orbital="particle 1", iso=0.05, lavapipe=True)
    assert img.shape == (48, 64, 4) and img[..., :3].std() > 0
    with pytest.raises(ValueError, match="state"):
        orbcloud.render(doc, size=(32, 32), attachment=True, lavapipe=True)


REFDATA = pathlib.Path(os.environ.get("ORBCLOUD_REFDATA", REPO.parent / "shared" / "refdata" / "real-world"))


@pytest.mark.skipif(not (REFDATA / "logs").is_dir(), reason="the reference corpus is absent")
def test_states_of_a_gaussian_td_fchk():
    doc = orbcloud.load(REFDATA / "logs" / "basicGaussian09_dvb_td.fchk")
    assert doc.states and doc.density_state is not None
    held = doc.state(doc.density_state)
    assert held is doc
    value = doc.evaluate([[0.0, 0.0, 0.0]], quantity="attachment", state=doc.density_state)
    assert value.shape == (1,) and value[0] >= 0
    with pytest.raises(ValueError, match="not known"):
        doc.state(doc.density_state + 1)


def teardown_module():
    for what, deviation in sorted(DEVIATIONS.items()):
        print(f"max |orbcloud − PySCF| {what}: {deviation:.2e}")

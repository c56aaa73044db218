"""NCI from Python: ``orbcloud.nci`` / ``Document.nci`` give NCIPLOT's two grids exactly as
``orbcloud nci`` writes them as cubes, ``render(doc, nci=True)`` draws the NCI surface, and
``orbcloud eval A B`` sums the fragments' densities as PySCF's densities summed do."""

import numpy as np
import pytest

import orbcloud
from conftest import FIXTURES

DIMER = FIXTURES / "nci" / "water_dimer_631gs.molden"
WATER = FIXTURES / "wfn_wfx_mkl" / "h2o_rhf.wfn"


def read_cube(path):
    """A cube file's values (nx × ny × nz) and its 4 × 4 world-from-grid matrix (bohr)."""
    lines = open(path).read().splitlines()
    head = lines[2].split()
    natoms, origin = abs(int(head[0])), np.array([float(v) for v in head[1:4]])
    dims, axes = [], []
    for line in lines[3:6]:
        words = line.split()
        dims.append(int(words[0]))
        axes.append([float(v) for v in words[1:4]])
    start = 6 + natoms + (1 if int(head[0]) < 0 else 0)
    values = np.array(" ".join(lines[start:]).split(), dtype=float).reshape(dims)
    matrix = np.eye(4)
    matrix[:3, :3] = np.array(axes).T
    matrix[:3, 3] = origin
    return values, matrix


@pytest.mark.parametrize(
    "files, options, flags",
    [
        ([DIMER], dict(step=0.2), ["--step", "0.2"]),
        ([DIMER], dict(step=0.25, margin=0.5, rdg_cut=100, cut=0.04), ["--step", "0.25", "--margin", "0.5", "--rdg-cut", "100", "--cut", "0.04"]),
        ([DIMER, WATER], dict(step=0.3), ["--step", "0.3"]),
        ([DIMER], dict(step=0.25, promolecular=True), ["--step", "0.25", "--promolecular"]),
    ],
)
def test_nci_grids_equal_the_commands_cubes(files, options, flags, cli, tmp_path):
    prefix = tmp_path / "nci"
    cli("nci", *files, *flags, "-o", prefix)
    docs = [orbcloud.load(f) for f in files]
    got = docs[0].nci(**options) if len(docs) == 1 else orbcloud.nci(docs, **options)
    assert isinstance(got, orbcloud.NciGrids)
    for values, suffix in ((got.dens, "-dens.cube"), (got.grad, "-grad.cube")):
        expected, matrix = read_cube(f"{prefix}{suffix}")
        assert values.shape == expected.shape
        np.testing.assert_allclose(got.world_from_grid, matrix, atol=1e-6)
        # The cube prints 5 significant digits.
        np.testing.assert_allclose(values, expected, rtol=1e-4, atol=1e-9)
    assert (got.grad < 100).any() and (got.dens == 100).any()
    assert got.points().shape == (got.dens.size, 3)
    np.testing.assert_allclose(got.points()[0], got.origin)


def test_nci_grid_like_and_refusals(cli, tmp_path):
    prefix = tmp_path / "nci"
    cli("nci", DIMER, "--step", "0.3", "-o", prefix)
    like = orbcloud.nci(DIMER, grid_like=f"{prefix}-grad.cube")
    expected, matrix = read_cube(f"{prefix}-grad.cube")
    np.testing.assert_allclose(like.grad, expected, rtol=1e-4, atol=1e-9)
    xyz = FIXTURES / "structures" / "ethane_trajectory.xyz"
    with pytest.raises(ValueError, match="no wavefunction"):
        orbcloud.nci(xyz)
    with pytest.raises(ValueError, match="intermolecular"):
        orbcloud.nci(DIMER, intermolecular=True)
    with pytest.raises(ValueError, match="step"):
        orbcloud.nci(DIMER, step=0)


def blue_green(img):
    """Blue-green pixels left of the colour bar: the NCI surface near sign(λ₂)ρ ≈ −0.01."""
    rgb = np.asarray(img)[..., :3].astype(int)
    width = rgb.shape[1]
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    mask = (g > r + 30) & (b > r + 30)
    mask[:, width * 7 // 10 :] = False
    return mask


def test_render_nci_draws_the_hydrogen_bond(cli, tmp_path):
    options = dict(size=(320, 240), lavapipe=True, grid_points=56)
    doc = orbcloud.load(DIMER)
    img = orbcloud.render(doc, nci=True, **options)
    mask = blue_green(img)
    assert mask.sum() >= 10, mask.sum()
    columns = np.nonzero(mask)[1]
    assert 0.35 < columns.mean() / img.shape[1] < 0.65
    # The command's picture with the same options.
    out = tmp_path / "cli.png"
    cli("render", DIMER, "-o", out, *orbcloud._words(dict(options, nci=True)))
    from PIL import Image

    expected = np.asarray(Image.open(out).convert("RGBA"), dtype=float)
    assert np.abs(np.asarray(img, dtype=float) - expected).mean() <= 1.0
    assert not blue_green(orbcloud.render(doc, density=True, **options)).any()
    # A structure without a wavefunction: its spherical atoms' NCI, here between a selection
    # (the acceptor, LIG 2) and the rest.
    pdb = FIXTURES / "nci" / "water_dimer.pdb"
    assert blue_green(orbcloud.render(pdb, nci=True, nci_between="resn LIG", size=(320, 240), lavapipe=True)).sum() >= 10
    with pytest.raises(ValueError, match="picks 0 of 6 atoms"):
        orbcloud.render(pdb, nci=True, nci_between="resn XYZ", lavapipe=True)


def test_eval_of_two_files_sums_their_densities_as_pyscf_does(cli, tmp_path):
    from pyscf import dft, gto, scf
    from pyscf.tools import molden

    # Two waters 3 Å apart, each on its own (RHF/STO-3G).
    geometries = [
        "O 0 0 0; H 0.757 0.586 0; H -0.757 0.586 0",
        "O 0 0 3.0; H 0.757 -0.586 3.0; H -0.757 -0.586 3.0",
    ]
    mols, dms, files = [], [], []
    for n, atom in enumerate(geometries):
        mol = gto.M(atom=atom, basis="sto-3g", verbose=0)
        mf = scf.RHF(mol).run()
        path = tmp_path / f"water{n}.molden"
        molden.from_scf(mf, str(path))
        mols.append(mol)
        dms.append(mf.make_rdm1())
        files.append(path)
    rng = np.random.default_rng(3)
    points = np.column_stack([rng.uniform(-1.5, 1.5, 60), rng.uniform(-1.5, 1.5, 60), rng.uniform(1.0, 4.7, 60)])
    pts = tmp_path / "points.xyz"
    np.savetxt(pts, points)
    rho = np.zeros((4, len(points)))
    for mol, dm in zip(mols, dms):
        ao = dft.numint.eval_ao(mol, points, deriv=1)
        rho += dft.numint.eval_rho(mol, ao, dm, xctype="GGA")
    s = np.linalg.norm(rho[1:4], axis=0) / (2 * (3 * np.pi**2) ** (1 / 3) * rho[0] ** (4 / 3))

    def values(*flags):
        out = cli("eval", *files, *flags, "--points", pts).stdout
        return np.array([float(line.split()[3]) for line in out.splitlines()])

    np.testing.assert_allclose(values("--density"), rho[0], rtol=1e-7, atol=1e-12)
    np.testing.assert_allclose(values("--rdg"), s, rtol=1e-6)
    np.testing.assert_allclose(np.abs(values("--sign-lambda2-rho")), rho[0], rtol=1e-7, atol=1e-12)

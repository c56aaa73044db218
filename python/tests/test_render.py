"""``render`` draws what ``orbcloud render`` draws with the same options, on lavapipe."""

import numpy as np
import pytest
from PIL import Image as PilImage

import orbcloud
from conftest import FIXTURES

WATER = FIXTURES / "wavefunctions" / "h2o_ccpvtz.molden"

CASES = {
    "isosurfaces": dict(orbital="homo", iso=0.05),
    "cloud_turned": dict(orbital="lumo", view="z", yaw=30, pitch=-10),
    "density_clipped": dict(density=True, iso=[0.05, 0.2], clip=(0, 0, 1), atoms="space-filling"),
    "orbital_number": dict(orbital=2, iso=0.1, no_volume=True, colors="red-white", zoom=1.3),
    "beside": dict(orbital="homo", iso=0.05, args=["--beside", "--orbital", "lumo", "--iso", "0.05"]),
}


def flags(options):
    return orbcloud._words(dict(options))


@pytest.mark.parametrize("name", CASES)
def test_render_equals_the_command(name, cli, tmp_path):
    options = dict(CASES[name], size=(160, 120), lavapipe=True)
    out = tmp_path / "cli.png"
    result = cli("render", WATER, "-o", out, *flags(options))
    assert "Vulkan" in result.stderr and "llvmpipe" in result.stderr.lower(), result.stderr
    expected = np.asarray(PilImage.open(out).convert("RGBA"), dtype=float)
    for source in (WATER, orbcloud.load(WATER)):
        got = orbcloud.render(source, **options)
        assert isinstance(got, orbcloud.Image) and got.dtype == np.uint8
        assert got.shape == expected.shape, (got.shape, expected.shape)
        mean = np.abs(got.astype(float) - expected).mean()
        assert mean <= 1.0, f"{name}: mean difference {mean:.3f} / 255"
        assert got[..., :3].std() > 1.0, "a blank picture"


def test_render_shows_inline():
    img = orbcloud.render(WATER, size=(64, 48), orbital="homo", iso=0.05, lavapipe=True)
    png = img._repr_png_()
    assert png.startswith(b"\x89PNG")
    import io

    back = np.asarray(PilImage.open(io.BytesIO(png)).convert("RGBA"))
    assert (back == np.asarray(img)).all()


def test_render_of_pyscf_document():
    pyscf = pytest.importorskip("pyscf")
    mol = pyscf.gto.M(atom="O 0 0 0.1; H 0 0.75 -0.5; H 0 -0.8 -0.45", basis="sto-3g", verbose=0)
    doc = orbcloud.from_pyscf(pyscf.scf.RHF(mol).run())
    img = doc.render(size=(96, 72), orbital="homo", iso=0.05, lavapipe=True)
    assert img.shape == (72, 96, 4) and img[..., :3].std() > 1.0


def test_render_rejects_unknown_options():
    with pytest.raises(ValueError, match="--no-such-option"):
        orbcloud.render(WATER, size=(32, 32), no_such_option=1, lavapipe=True)

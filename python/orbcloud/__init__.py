"""orbcloud from Python: molecular orbitals and densities read, evaluated and rendered by
orbcloud's Rust library (the same readers, evaluator and renderer as the ``orbcloud`` command).

>>> import orbcloud
>>> doc = orbcloud.load("water.molden")          # or orbcloud.from_pyscf(mf)
>>> doc.evaluate(points, orbital="homo")          # numpy, all cores, the GIL released
>>> orbcloud.render(doc, orbital="lumo", iso=0.05)  # an RGBA image, shown inline by IPython

Positions are in bohr, energies in hartree. An ``orbital`` is ``"homo"``, ``"lumo"``,
``"homo-N"``, ``"lumo+N"``, an ``int``: a 0-based index among the orbitals of that spin, as
PySCF numbers the columns of ``mo_coeff``, or an orbital's label where it is unique
(``"hole 1"``, ``"particle 1"`` of natural transition orbitals).
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from typing import NamedTuple, Sequence, Union

import numpy as np

from . import _native
from ._image import Image

__all__ = [
    "Document",
    "ExcitedState",
    "Image",
    "LoadError",
    "Orbital",
    "Scan",
    "Transition",
    "compute",
    "from_pyscf",
    "load",
    "load_scan",
    "nci",
    "render",
    "scan_compute",
    "view",
    "widget",
]

PathLike = Union[str, "os.PathLike[str]"]


class LoadError(ValueError):
    """A file orbcloud could not read: the reader's message, with the file and (when the reader
    names one) the 1-based line."""

    def __init__(self, message: str, file: str | None = None, line: int | None = None):
        super().__init__(message)
        self.file = file
        self.line = line


class Atoms(NamedTuple):
    numbers: np.ndarray
    """Atomic numbers (0 for a dummy centre)."""
    charges: np.ndarray
    """Nuclear charges as the file gives them."""
    positions: np.ndarray
    """Positions, bohr, n × 3."""
    ghost: np.ndarray
    """Whether each atom is a ghost (basis functions, no nucleus)."""


class Orbital(NamedTuple):
    index: int
    """0-based among the orbitals of its spin."""
    spin: str
    """``"alpha"`` or ``"beta"`` (every orbital of a restricted wavefunction is alpha)."""
    energy: float
    """Hartree (NaN when the file gives none)."""
    occupation: float
    label: str
    """Symmetry label as written ("" when none)."""


class Transition(NamedTuple):
    """One orbital-to-orbital contribution to an excited state."""

    from_orbital: int
    """1-based number of the orbital the electron leaves, among the orbitals of its spin (as
    the program prints it)."""
    to_orbital: int
    coefficient: float
    """The amplitude as the program prints it (PySCF, Gaussian: X or Y, ½ = Σ X² for a
    restricted state)."""
    spin: str
    """``"alpha"`` or ``"beta"`` in unrestricted calculations, ``""`` otherwise."""
    deexcitation: bool
    """A de-excitation (Y of TDHF/TDDFT)."""


class ExcitedState(NamedTuple):
    """An excited state as the program lists it (or PySCF computed it)."""

    number: int
    """1-based, as the program numbers it (``td.e[number - 1]``, ``get_nto(state=number)``)."""
    energy_ev: float
    """Excitation energy, eV."""
    wavelength_nm: float
    total_energy: float | None
    """The state's total energy, hartree, where known."""
    oscillator_strength: float | None
    """Length gauge, where known."""
    spin: str
    """``"Singlet"``, ``"Triplet"``, … (``""`` when not known)."""
    symmetry: str
    s_squared: float | None
    transitions: list[Transition]
    """The main transitions, largest |coefficient| first."""


_EXCITED_QUANTITIES = {
    "difference density": "difference_density",
    "attachment": "attachment",
    "detachment": "detachment",
    "excited density": "excited_density",
}


def _quantity_name(quantity: str) -> str:
    """``"difference density"``, ``"difference_density"``, ``"Difference-Density"`` alike."""
    return " ".join(str(quantity).lower().replace("_", " ").replace("-", " ").split())


def _grid_points(shape, world_from_grid: np.ndarray) -> np.ndarray:
    """Every point of a grid of `shape` (x slowest) mapped by `world_from_grid`, bohr."""
    idx = np.indices(shape).reshape(3, -1).T.astype(float)
    return idx @ world_from_grid[:3, :3].T + world_from_grid[:3, 3]


class Grid(NamedTuple):
    values: np.ndarray
    """nx × ny × nz values, x slowest (cube order)."""
    world_from_grid: np.ndarray
    """4 × 4 affine map from grid indices (i, j, k, 1) to bohr."""

    @property
    def origin(self) -> np.ndarray:
        return self.world_from_grid[:3, 3]

    @property
    def axes(self) -> np.ndarray:
        """The three step vectors (rows), bohr."""
        return self.world_from_grid[:3, :3].T

    def points(self) -> np.ndarray:
        """Every grid point's position (nx·ny·nz × 3, bohr) in the values' order."""
        return _grid_points(self.values.shape, self.world_from_grid)


class NciGrids(NamedTuple):
    """NCIPLOT's two grids, as ``orbcloud nci`` writes them to ``PREFIX-dens.cube`` and
    ``PREFIX-grad.cube``: nx × ny × nz values, x slowest (cube order)."""

    dens: np.ndarray
    """100·sign(λ₂)ρ (a.u.), 100 at the points cut (ρ above the cut)."""
    grad: np.ndarray
    """The reduced density gradient s, 100 at the points cut and where s is above ``rdg_cut``."""
    world_from_grid: np.ndarray
    """4 × 4 affine map from grid indices (i, j, k, 1) to bohr."""

    @property
    def origin(self) -> np.ndarray:
        return Grid.origin.fget(self)

    @property
    def axes(self) -> np.ndarray:
        """The three step vectors (rows), bohr."""
        return Grid.axes.fget(self)

    def points(self) -> np.ndarray:
        """Every grid point's position (nx·ny·nz × 3, bohr) in the values' order."""
        return _grid_points(self.dens.shape, self.world_from_grid)


class Document:
    """What orbcloud read from a file (or was given by :func:`from_pyscf`): atoms, data sets and
    the wavefunction, with its orbitals evaluated and rendered by the Rust library."""

    def __init__(self, native: _native.Document, path: str | None = None, pyscf=None, excited=None, weights=None, state=None):
        self._native = native
        self.path = path
        """The file it was read from (``None`` for :func:`from_pyscf`)."""
        self._pyscf = pyscf
        self._excited = excited
        self._states: dict[int, Document] = {}
        self.weights = weights
        """Natural transition orbitals' weights, descending, summing to 1 (an array, or the
        alpha and beta arrays of an unrestricted state), for :meth:`nto`'s documents; ``None``
        for other documents."""
        self.state_number = state
        """The excited state this document's orbitals (:meth:`nto`) or densities
        (:meth:`state`) belong to; ``None`` for others."""

    def __repr__(self) -> str:
        n = len(self.atoms.numbers)
        what = f"{len(self.orbitals)} orbitals over {self._native.n_basis} basis functions" if self.has_wavefunction else "no wavefunction"
        return f"<orbcloud.Document {self.source!r}: {n} atoms, {what}>"

    @property
    def source(self) -> str:
        return self._native.source

    @property
    def title(self) -> str:
        return self._native.title

    @property
    def atoms(self) -> Atoms:
        z, charges, positions, ghost = self._native.atoms()
        return Atoms(z, charges, positions, np.array(ghost, dtype=bool))

    @property
    def bonds(self) -> list[tuple[int, int]]:
        return self._native.bonds()

    @property
    def has_wavefunction(self) -> bool:
        return self._native.has_wavefunction

    @property
    def restricted(self) -> bool | None:
        return self._native.restricted

    @property
    def orbitals(self) -> list[Orbital]:
        """Every orbital, alpha first, in file order."""
        out, count = [], {"alpha": 0, "beta": 0}
        for energy, occupation, spin, label in self._native.orbitals():
            out.append(Orbital(count[spin], spin, energy, occupation, label))
            count[spin] += 1
        return out

    def energies(self, spin: str = "alpha") -> np.ndarray:
        return np.array([o.energy for o in self.orbitals if o.spin == spin])

    def occupations(self, spin: str = "alpha") -> np.ndarray:
        return np.array([o.occupation for o in self.orbitals if o.spin == spin])

    @property
    def states(self) -> list[ExcitedState]:
        """The excited states the document lists (a TD calculation from :func:`from_pyscf`, a
        Gaussian, ORCA or Q-Chem log, a Gaussian TD fchk); empty when it lists none."""
        listed = self._native.states()
        if listed is None:
            return []
        return [
            ExcitedState(number, ev, nm, total, f, spin, symmetry, s2, [Transition(*t) for t in transitions])
            for number, ev, nm, total, f, spin, symmetry, s2, transitions in listed[3]
        ]

    @property
    def excitation_method(self) -> str | None:
        """The excited states' program and method ("PySCF", "TDA (HF)"), ``None`` without states."""
        listed = self._native.states()
        return None if listed is None else f"{listed[0]} {listed[1]}".strip()

    @property
    def density_state(self) -> int | None:
        """The excited state whose density this document holds (:meth:`state`, a Gaussian TD
        fchk's), if any."""
        return self._native.density_state

    @property
    def electrons_moved(self) -> tuple[float, float] | None:
        """The integrals of the held excited state's attachment and detachment densities (the
        electrons the excitation moves), if it holds one."""
        return self._native.electrons_moved()

    def state(self, number: int) -> Document:
        """This document holding excited state ``number``'s density (1-based, as PySCF's
        ``td.e`` and ``get_nto`` number them): its difference, attachment, detachment and
        excited densities are then ``evaluate``'s, ``grid``'s and ``render``'s quantities. For a
        TD calculation from :func:`from_pyscf`, the unrelaxed density from the amplitudes (see
        ``orbcloud._excited``); a file's own excited state's density otherwise."""
        if self._excited is None:
            if self.density_state is not None and number == self.density_state:
                return self
            held = f"only state {self.density_state}'s" if self.density_state is not None else "no excited state's density"
            raise ValueError(f"{self.source}: state {number}'s density is not known (the document holds {held})")
        if number not in self._states:
            from ._pyscf import to_orbcloud_matrix

            amplitudes = self._excited
            index = amplitudes._index(number)
            mol = amplitudes.mol
            ground = to_orbcloud_matrix(mol, amplitudes.ground)
            excited = to_orbcloud_matrix(mol, amplitudes.ground + amplitudes.difference(number))
            source = f"{amplitudes.method} state {index + 1}: unrelaxed, from PySCF's amplitudes"
            native = self._native.with_state_density(index + 1, source, ground, excited)
            self._states[number] = Document(native, pyscf=self._pyscf, excited=amplitudes, state=index + 1)
        return self._states[number]

    def nto(self, state: int = 1) -> Document:
        """Excited state ``state``'s natural transition orbitals (1-based, as PySCF's
        ``td.get_nto(state=...)``) as a document of their own: orbitals ``"hole 1"``,
        ``"particle 1"``, ``"hole 2"``, … (their labels, which ``evaluate``, ``render`` and the
        widget take), ``weights`` descending and summing to 1, equal to ``get_nto``'s (X alone,
        renormalised). Each orbital's sign is ``get_nto``'s: its largest coefficient over the
        molecular orbitals positive. NTOs have no orbital energies (NaN); their occupations are
        the weights, as ORCA's and Q-Chem's NTO Molden files write them."""
        if self._excited is None:
            raise ValueError(f"{self.source}: natural transition orbitals need a TD calculation's amplitudes (from_pyscf(td))")
        from ._pyscf import document_parts

        amplitudes = self._excited
        number = amplitudes._index(state) + 1
        sets = amplitudes.nto(number)
        mol = amplitudes.mol
        labels = [label for _, _, _, names in sets for label in names]
        if amplitudes.restricted:
            weights, c, occupations, _ = sets[0]
            parts, keep = document_parts(mol, c, occupations, np.full(len(occupations), np.nan), labels=labels)
        else:
            c = tuple(c for _, c, _, _ in sets)
            occupations = tuple(o for _, _, o, _ in sets)
            energies = tuple(np.full(len(o), np.nan) for o in occupations)
            parts, keep = document_parts(mol, c, occupations, energies, labels=labels)
            weights = (sets[0][0], sets[1][0])
        parts["source"] = f"PySCF {amplitudes.method} state {number}: natural transition orbitals"
        return Document(_native.from_parts(**parts), pyscf=keep, weights=weights, state=number)

    def info(self, json: bool = False) -> str:
        """What ``orbcloud info`` prints of the document (``json=True``: its ``--json`` form):
        atoms, orbitals, excited states and, for a document holding an excited state's
        density, what its attachment and detachment densities say."""
        return self._native.info(bool(json))

    @property
    def writer(self) -> str | None:
        """The program that wrote the file, as the reader recognised it ("ORCA", "PySCF", …)."""
        n = self._native.normalization()
        return n and n[0]

    @property
    def repair(self) -> str | None:
        """The writer repair applied to make the orbitals orthonormal ("none" when none was needed)."""
        n = self._native.normalization()
        return n and n[1]

    @property
    def residual(self) -> float | None:
        """max |CᵀSC − I| of the orbitals, after any repair."""
        n = self._native.normalization()
        return n and n[2]

    @property
    def basis_functions(self) -> list[str]:
        """Names of the basis functions ("O1 2px"), in orbcloud's order."""
        return self._native.basis_function_names()

    @property
    def volumes(self) -> list[str]:
        """Names of the file's data sets (cube volumes)."""
        return self._native.volume_names()

    @property
    def problems(self) -> list[str]:
        """Parts of the file that could not be read while the rest opened."""
        return self._native.problems()

    def orbital_index(self, orbital: str | int = "homo", spin: str = "alpha") -> int:
        """The 0-based index, among the orbitals of ``spin``, of ``orbital``."""
        flat = self._flat_index(orbital, spin)
        return sum(1 for o in self._native.orbitals()[:flat] if o[2] == spin)

    def _flat_index(self, orbital: str | int, spin: str) -> int:
        if isinstance(orbital, (int, np.integer)) and not isinstance(orbital, bool):
            if orbital < 0:
                raise ValueError(f"orbital {orbital}: indices count from 0")
            return self._native.resolve(str(int(orbital) + 1), spin)
        try:
            return self._native.resolve(str(orbital), spin)
        except ValueError:
            # An orbital's label, where it names one orbital of that spin ("hole 1").
            wanted = " ".join(str(orbital).lower().split())
            named = [i for i, o in enumerate(self._native.orbitals()) if o[2] == spin and " ".join(o[3].lower().split()) == wanted]
            if len(named) == 1:
                return named[0]
            raise

    def _excited_target(self, quantity, state) -> tuple[Document, str | None]:
        """The document that evaluates ``quantity`` of ``state``, and the native name of an
        excited state's quantity (``None`` for the others)."""
        name = None if quantity is None else _quantity_name(quantity)
        kind = _EXCITED_QUANTITIES.get(name) if name is not None else None
        if name is not None and kind is None and name not in ("orbital", "density", "spin density"):
            raise ValueError(f"quantity {quantity!r}: one of orbital, density, spin density, {', '.join(_EXCITED_QUANTITIES)}")
        if state is not None:
            if kind is None:
                raise ValueError(f"state={state} picks the excited state of a quantity among {', '.join(_EXCITED_QUANTITIES)}")
            return self.state(int(state)), kind
        if kind is not None and self.density_state is None:
            raise ValueError(f"quantity {quantity!r} needs state=k (the excited state whose density it is)")
        return self, kind

    @staticmethod
    def _points(points) -> np.ndarray:
        p = np.ascontiguousarray(points, dtype=np.float64)
        if p.ndim == 1 and p.shape[0] == 3:
            p = p[None, :]
        if p.ndim != 2 or p.shape[1] != 3:
            raise ValueError(f"points must have shape (n, 3), got {p.shape}")
        return p

    def evaluate(self, points, orbital: str | int = "homo", spin: str = "alpha", quantity: str | None = None, state: int | None = None) -> np.ndarray:
        """ψ at ``points`` (n × 3, bohr): one value per point. ``quantity`` instead of an orbital:
        ``"density"``, ``"spin density"``, or an excited state's ``"difference density"``
        (ρ_exc − ρ_gs), ``"attachment"``, ``"detachment"``, ``"excited density"`` of ``state``
        (1-based; see :meth:`state`)."""
        target, kind = self._excited_target(quantity, state)
        p = self._points(points)
        if kind is not None:
            return target._native.values(p, kind, 0)
        name = None if quantity is None else _quantity_name(quantity)
        if name in ("density", "spin density"):
            return self.density(p, spin_density=name == "spin density")
        return self._native.values(p, "orbital", self._flat_index(orbital, spin))

    def density(self, points, spin_density: bool = False) -> np.ndarray:
        """The total electron density (or the spin density ρα − ρβ) at ``points`` (n × 3, bohr)."""
        return self._native.values(self._points(points), "spin_density" if spin_density else "density", 0)

    def basis_function(self, points, function: int | str) -> np.ndarray:
        """One basis function (an index, or a name as :attr:`basis_functions` gives it) at ``points``."""
        if isinstance(function, str):
            function = self.basis_functions.index(function)
        return self._native.values(self._points(points), "basis_function", int(function))

    def esp(self, points) -> np.ndarray:
        """The electrostatic potential of the nuclei and electrons at ``points`` (n × 3, bohr), in
        atomic units (hartree per elementary charge), as ``orbcloud eval --esp`` gives it."""
        return self._native.values(self._points(points), "esp", 0)

    def _quantity(self, orbital, spin, density, quantity=None, state=None) -> tuple[_native.Document, str, int]:
        if quantity is not None or state is not None:
            target, kind = self._excited_target(quantity, state)
            if kind is not None:
                return target._native, kind, 0
            density = {"density": True, "spin density": "spin"}.get(_quantity_name(quantity), density)
        if density in (True, "total"):
            return self._native, "density", 0
        if density == "spin":
            return self._native, "spin_density", 0
        return self._native, "orbital", self._flat_index(orbital, spin)

    def grid(self, orbital: str | int = "homo", spin: str = "alpha", points: int = 80, density: bool | str = False, quantity: str | None = None, state: int | None = None) -> Grid:
        """An orbital (or ``density=True`` / ``"spin"``, or :meth:`evaluate`'s ``quantity`` of
        ``state``) on a grid of ``points`` per side over the box where it decays, as ``orbcloud
        cube`` makes it."""
        native, kind, index = self._quantity(orbital, spin, density, quantity, state)
        values, matrix = native.grid(kind, index, int(points))
        return Grid(values, matrix)

    def write_cube(self, path: PathLike, orbital: str | int = "homo", spin: str = "alpha", points: int = 80, density: bool | str = False, quantity: str | None = None, state: int | None = None) -> None:
        """Writes :meth:`grid`'s values as a Gaussian cube file."""
        native, kind, index = self._quantity(orbital, spin, density, quantity, state)
        native.write_cube(os.fspath(path), kind, index, int(points))

    def nci(self, **options) -> NciGrids:
        """:func:`orbcloud.nci` of this document alone."""
        return nci([self], **options)

    def render(self, **options) -> Image:
        """:func:`orbcloud.render` of this document."""
        return render(self, **options)

    def view(self) -> subprocess.Popen:
        """:func:`orbcloud.view` of this document."""
        return view(self)

    def widget(self, **options):
        """:func:`orbcloud.widget` of this document."""
        return widget(self, **options)


def load(path: PathLike) -> Document:
    """Reads a file as the viewer opens it: Gaussian cube, Molden, fchk, AIM wfn/wfx, ORCA MKL,
    PDB, mmCIF or XYZ (each also gzipped). Raises :class:`LoadError` with the reader's message."""
    path = os.fspath(path)
    try:
        native = _native.load(path)
    except _native.NativeLoadError as e:
        raise LoadError(*e.args) from None
    return Document(native, path=path)


class Scan(NamedTuple):
    """A scan manifest's key frames (``*.scan.toml``), each a :class:`Document`."""

    title: str
    coordinate: str
    """What the frames vary, as chemists write it: "dihedral 1-2-3-4", "angle 2-1-3", "path"."""
    values: list[float]
    """The coordinate's value at each frame (degrees, Å, or the path position)."""
    labels: list[str]
    """Each value with its unit: "104.5°"."""
    frames: list[Document]


def load_scan(path: PathLike) -> Scan:
    """Reads a scan manifest and every frame it names, as the viewer does (geometries aligned,
    frames checked against each other). :func:`widget` of a scan has a slider along it."""
    try:
        title, coordinate, frames = _native.load_scan(os.fspath(path))
    except _native.NativeLoadError as e:
        raise LoadError(*e.args) from None
    return Scan(title, coordinate, [f[0] for f in frames], [f[1] for f in frames], [Document(f[2]) for f in frames])


def from_pyscf(mf_or_mol, mo_coeff=None, mo_occ=None, mo_energy=None) -> Document:
    """A document straight from PySCF: a mean-field object (``from_pyscf(mf)``) or a molecule with
    its orbitals (``from_pyscf(mol, mo_coeff, mo_occ, mo_energy)``). Restricted, restricted
    open-shell and unrestricted orbitals; cartesian or pure basis sets up to h functions.

    A TD calculation that has run (``tddft.TDA(mf).run()``, ``TDHF``, ``TDDFT``, restricted or
    unrestricted) gives its ground state's document with the excited states: :attr:`Document.states`,
    :meth:`Document.state` (their densities), :meth:`Document.nto` (natural transition orbitals).
    Make it before calling PySCF's ``get_nto``, which rescales ``td.xy`` in place."""
    from ._pyscf import document_parts

    if mo_coeff is None:
        from ._excited import is_td

        if is_td(mf_or_mol):
            from ._excited import Amplitudes

            amplitudes = Amplitudes(mf_or_mol)
            parts, keep = document_parts(mf_or_mol._scf)
            native = _native.from_parts(**parts).with_states("PySCF", amplitudes.method, amplitudes.states())
            return Document(native, pyscf=keep, excited=amplitudes)
    parts, keep = document_parts(mf_or_mol, mo_coeff, mo_occ, mo_energy)
    return Document(_native.from_parts(**parts), pyscf=keep)


def _words(options: dict) -> list[str]:
    """``render``'s keyword arguments as the command's options: ``iso=0.05`` → ``--iso 0.05``,
    ``size=(800, 600)`` → ``--size 800x600``, ``no_volume=True`` → ``--no-volume``, a list
    repeats an option that may be given several times (``iso=[0.02, 0.05]``), other sequences
    join with commas (``clip=(0, 0, 1)``); ``args=[...]`` adds words as they are."""
    repeated = {"iso", "iso_sigma", "optics_scale"}
    words: list[str] = []
    extra = list(options.pop("args", []) or [])
    for key, value in options.items():
        flag = "--" + key.replace("_", "-")
        if value is None or value is False:
            continue
        if value is True:
            words.append(flag)
            continue
        if key == "size":
            width, height = value
            value = f"{int(width)}x{int(height)}"
        elif key == "orbital" and isinstance(value, (int, np.integer)):
            value = int(value) + 1  # the command counts from 1
        elif isinstance(value, (list, tuple, np.ndarray)):
            if key in repeated:
                for v in value:
                    words += [flag, str(v)]
                continue
            value = ",".join(str(v) for v in value)
        words += [flag, str(value)]
    return words + [str(w) for w in extra]


def render(doc_or_path: Document | PathLike | None = None, size: tuple[int, int] = (800, 600), **options) -> Image:
    """The picture ``orbcloud render`` draws of a document or file with the same options, as an
    RGBA image (height × width × 4, uint8) that IPython shows inline. Options are the command's,
    with underscores: ``orbital="lumo"``, ``iso=0.05``, ``view="z"``, ``yaw=30``,
    ``no_volume=True``, ``colors="red-white"``, ``lavapipe=True``, ``nci=True`` (the NCI
    surface coloured by sign(λ₂)ρ, with ``nci_level`` and ``nci_range``); see :func:`_words`."""
    native = None
    if isinstance(doc_or_path, Document):
        doc_or_path, options = _resolved(doc_or_path, options)
        native = doc_or_path._native
    words = _words({"size": size, **options})
    if native is None and doc_or_path is not None:
        words.insert(0, os.fspath(doc_or_path))
    return Image.of(_native.render(native, words))


def nci(
    docs: Document | PathLike | Sequence[Document | PathLike],
    promolecular: bool = False,
    step: float | None = None,
    margin: float | None = None,
    cut: float | None = None,
    rdg_cut: float | None = None,
    intermolecular: bool = False,
    grid_like: PathLike | None = None,
) -> NciGrids:
    """NCIPLOT's grids of documents (or files) whose densities add, as ``orbcloud nci`` writes
    them (the same code): 100·sign(λ₂)ρ and s on a grid ``step`` Å apart (0.1 by default) over
    the atoms' box plus ``margin`` Å (0.75), or on the grid of the cube file ``grid_like``.
    Points whose density is above ``cut`` (0.05 a.u., promolecular 0.07) hold 100 in both, and
    ``grad`` holds 100 where s is above ``rdg_cut`` (1; 100 keeps every s). ``promolecular``:
    sums of spherical atoms instead of wavefunctions; ``intermolecular``: only the points no
    fragment holds more than 95 % of."""
    items = docs if isinstance(docs, (list, tuple)) else [docs]
    natives = [(d if isinstance(d, Document) else load(d))._native for d in items]
    dens, grad, matrix = _native.nci(
        natives,
        promolecular=bool(promolecular),
        step=None if step is None else float(step),
        margin=None if margin is None else float(margin),
        cut=None if cut is None else float(cut),
        rdg_cut=None if rdg_cut is None else float(rdg_cut),
        intermolecular=bool(intermolecular),
        grid_like=None if grid_like is None else os.fspath(grid_like),
    )
    return NciGrids(dens, grad, matrix)


def _resolved(doc: Document, options: dict) -> tuple[Document, dict]:
    """The document and options the command draws: an orbital named by its label (``"hole
    1"``) as its number, and for a TD calculation's ``state=k`` the document holding that
    state's density (``attachment=True, state=2``)."""
    options = dict(options)
    orbital = options.get("orbital")
    if isinstance(orbital, str):
        spin = options.get("spin") or "alpha"
        try:
            doc._native.resolve(orbital, spin)
        except ValueError:
            options["orbital"] = doc.orbital_index(orbital, spin)
    state = options.get("state")
    if state is not None and doc._excited is not None:
        doc = doc.state(int(state))
    return doc, options


def _viewable_path(doc: Document) -> str:
    """A file the desktop viewer can open holding ``doc``: its own, or a Molden file PySCF writes."""
    if doc.path is not None:
        return os.path.abspath(doc.path)
    if doc._pyscf is None:
        raise ValueError("this document has no file to show")
    from ._pyscf import write_molden

    fd, path = tempfile.mkstemp(prefix="orbcloud-", suffix=".molden")
    os.close(fd)
    write_molden(doc._pyscf, path)
    return path


def view(doc_or_path: Document | PathLike | Sequence[Document | PathLike]) -> subprocess.Popen:
    """Opens the desktop viewer on a document or file (or several) in a process of its own and
    returns at once; a document made by :func:`from_pyscf` goes through a temporary Molden file."""
    items = doc_or_path if isinstance(doc_or_path, (list, tuple)) else [doc_or_path]
    files = [_viewable_path(d) if isinstance(d, Document) else os.path.abspath(os.fspath(d)) for d in items]
    return subprocess.Popen([sys.executable, "-m", "orbcloud", "view", *files], start_new_session=True)


def widget(doc_or_docs, **options):
    """An interactive view for Jupyter: frames drawn by orbcloud's renderer, turned with the mouse,
    zoomed with the wheel, with controls for the orbital, the isovalue and cloud or isosurfaces; a
    :class:`Scan` (or a list of documents) adds a slider along its frames. Needs ``jupyter_rfb``
    and ``ipywidgets``."""
    from .notebook import Viewer

    return Viewer(doc_or_docs, **options)


def _geometry_file(path_or_mol, folder: str) -> tuple[str, dict]:
    """A file the command reads for ``path_or_mol`` (a path, or a PySCF ``Mole`` written as
    XYZ), and the charge and spin a ``Mole`` carries."""
    if isinstance(path_or_mol, (str, os.PathLike)):
        return os.fspath(path_or_mol), {}
    mol = path_or_mol
    coords = mol.atom_coords(unit="Angstrom")
    path = os.path.join(folder, "molecule.xyz")
    with open(path, "w") as f:
        f.write(f"{mol.natm}\nfrom PySCF\n")
        for i in range(mol.natm):
            x, y, z = coords[i]
            f.write(f"{mol.atom_pure_symbol(i)} {x:.10f} {y:.10f} {z:.10f}\n")
    return path, {"charge": mol.charge, "spin": mol.spin}


def _compute_words(method, basis, charge, spin, client, max_cycles=None) -> list[str]:
    words = ["--method", str(method), "--basis", str(basis), "--charge", str(int(charge)), "--spin", str(int(spin))]
    if max_cycles is not None:
        words += ["--max-cycles", str(int(max_cycles))]
    if client is not None:
        words += ["--dask", client.scheduler.address]
    return words


def _run_cli(words: list[str]) -> None:
    """Runs the ``orbcloud`` command line in this process; its computations run in this
    interpreter (``ORBCLOUD_PYTHON`` unless set already)."""
    os.environ.setdefault("ORBCLOUD_PYTHON", sys.executable)
    _native.run_cli([str(w) for w in words])


def compute(
    path_or_mol,
    method: str = "b3lyp",
    basis: str = "6-31g*",
    charge: int | None = None,
    spin: int | None = None,
    freq: bool = False,
    output: PathLike | None = None,
    client=None,
    max_cycles: int | None = None,
) -> Document:
    """The wavefunction of a geometry (a file orbcloud reads, or a PySCF ``Mole``) computed with
    PySCF, as ``orbcloud compute`` does: HF or any functional, a basis by name, open shells
    unrestricted; ``freq=True`` adds the normal modes. Written as a Molden file (``output``, by
    default a temporary file) and returned as a :class:`Document`. With a
    ``dask.distributed.Client`` it runs as a task of that cluster."""
    with tempfile.TemporaryDirectory(prefix="orbcloud-") as folder:
        path, carried = _geometry_file(path_or_mol, folder)
        charge = carried.get("charge", 0) if charge is None else charge
        spin = carried.get("spin", 0) if spin is None else spin
        if output is None:
            fd, output = tempfile.mkstemp(prefix="orbcloud-", suffix=".molden")
            os.close(fd)
        output = os.fspath(output)
        words = ["compute", path, *_compute_words(method, basis, charge, spin, client, max_cycles), "-o", output]
        if freq:
            words.append("--freq")
        _run_cli(words)
    return load(output)


def scan_compute(
    path_or_mol,
    output: PathLike,
    distance: Sequence[int] | None = None,
    angle: Sequence[int] | None = None,
    dihedral: Sequence[int] | None = None,
    frames: bool = False,
    start: float | None = None,
    stop: float | None = None,
    step: float | None = None,
    relaxed: bool = False,
    method: str = "b3lyp",
    basis: str = "6-31g*",
    charge: int | None = None,
    spin: int | None = None,
    workers: int | None = None,
    client=None,
    max_cycles: int | None = None,
) -> Scan:
    """A scan computed with PySCF, as ``orbcloud scan compute`` does: a ``distance``, ``angle``
    or ``dihedral`` (1-based atoms) from ``start`` to ``stop`` by ``step`` (Å or degrees), rigid
    or ``relaxed``, or every geometry of a trajectory (``frames=True``). One Molden file per
    value and the manifest go to ``output``; a second call into the same folder keeps the frames
    already computed. ``workers`` local processes, or the tasks of a ``dask.distributed.Client``.
    Returns the :class:`Scan` (:func:`widget` shows it with a slider)."""
    with tempfile.TemporaryDirectory(prefix="orbcloud-") as folder:
        path, carried = _geometry_file(path_or_mol, folder)
        charge = carried.get("charge", 0) if charge is None else charge
        spin = carried.get("spin", 0) if spin is None else spin
        words = ["scan", "compute", path]
        for name, atoms in (("distance", distance), ("angle", angle), ("dihedral", dihedral)):
            if atoms is not None:
                words += [f"--{name}", ",".join(str(int(a)) for a in atoms)]
        if frames:
            words.append("--frames")
        for name, value in (("from", start), ("to", stop), ("step", step)):
            if value is not None:
                words += [f"--{name}", repr(float(value))]
        if relaxed:
            words.append("--relaxed")
        if workers is not None:
            words += ["--workers", str(int(workers))]
        words += [*_compute_words(method, basis, charge, spin, client, max_cycles), "-o", os.fspath(output)]
        _run_cli(words)
    # The command names the manifest after the input file's stem.
    stem = os.path.basename(path)
    stem = (stem[:-3] if stem.endswith(".gz") else stem).split(".")[0] or "frame"
    return load_scan(os.path.join(os.fspath(output), f"{stem}.scan.toml"))

"""Wavefunctions computed with PySCF for orbcloud: single points (with normal modes on request)
and the frames of a scan, one after another, in local processes or as tasks of a Dask cluster.

This file is both a module of the Python package (``orbcloud.compute``, ``orbcloud.scan_compute``)
and the script the ``orbcloud`` command runs (``python3 _compute.py JOB.json``): it imports
nothing of orbcloud's, only the standard library, numpy and PySCF (geomeTRIC for relaxed scans,
Dask for ``--dask``). As a script it prints one JSON object a line on stdout:

    {"event": "start", "frames": N, "kept": K, "versions": {...}}
    {"event": "frame", "index": i, "at": v, "file": "...", "ok": true, "cycles": c, "energy": E, "seconds": t}
    {"event": "frame", "index": i, "at": v, "file": "...", "ok": false, "error": "..."}
    {"event": "done", "computed": n, "kept": k, "failed": f}

A job (JSON) names the settings and the frames, each an input geometry in Å:

    {"method": "b3lyp", "basis": "6-31g*", "charge": 0, "spin": 0, "max_cycles": 100,
     "relaxed": false, "freq": false, "gpu": false, "workers": 1, "dask": null,
     "coordinate": {"kind": "dihedral", "atoms": [1, 2, 3, 4]},   # 1-based; null for single points
     "start": 2,                                                    # the frame nearest the input
     "dir": "out/", "output": "out/compute-output.txt",                # what PySCF prints
     "frames": [{"file": "x_120.molden", "at": 120.0,
                                "symbols": ["C", ...], "angstrom": [[x, y, z], ...]}]}

Frames are computed in chains outward from ``start``: each SCF starts from its neighbour's
density (fewer cycles, orbitals that change continuously), and in a relaxed scan each
constrained optimisation starts from its neighbour's optimised geometry. Every finished frame is
recorded in ``DIR/compute-log.jsonl``; a run into the same directory keeps the frames already
computed with the same settings and geometry.
"""

from __future__ import annotations

import hashlib
import json
import os
import sys
import tempfile
import time

INSTALL = "pip install pyscf geometric 'dask[distributed]'"
LOG = "compute-log.jsonl"


class ComputeError(RuntimeError):
    """A job orbcloud cannot run: a missing package, a bad setting."""


def versions(relaxed: bool = False, dask: bool = False) -> dict:
    """The versions of the programs a job uses (recorded in the scan's manifest)."""
    import numpy
    import pyscf

    out = {"pyscf": pyscf.__version__, "numpy": numpy.__version__, "python": sys.version.split()[0]}
    if relaxed:
        import geometric

        out["geometric"] = geometric.__version__
    if dask:
        import distributed

        out["dask"] = distributed.__version__
    return out


def require(relaxed: bool = False, dask: bool = False, gpu: bool = False) -> None:
    """Raises :class:`ComputeError` naming what to install when a package the job needs is missing."""
    needed = [("pyscf", "pyscf")]
    if relaxed:
        needed.append(("geometric", "geometric"))
    if dask:
        needed.append(("distributed", "'dask[distributed]'"))
    if gpu:
        needed.append(("gpu4pyscf", "gpu4pyscf-cuda12x"))
    for module, package in needed:
        try:
            __import__(module)
        except ImportError:
            raise ComputeError(
                f"computing needs {module} in the Python that runs it ({sys.executable}): "
                f"{sys.executable} -m pip install {package} (or everything: {INSTALL}); "
                "ORBCLOUD_PYTHON names another interpreter"
            ) from None


def frame_key(settings: dict, frame: dict) -> str:
    """What a frame was computed from: a run that finds the same key keeps the frame's file."""
    what = {k: settings.get(k) for k in ("method", "basis", "charge", "spin", "relaxed", "coordinate", "freq")}
    what["at"] = round(float(frame["at"]), 6)
    what["symbols"] = list(frame["symbols"])
    what["angstrom"] = [[round(float(x), 6) for x in p] for p in frame["angstrom"]]
    return hashlib.sha256(json.dumps(what, sort_keys=True).encode()).hexdigest()[:16]


def _mean_field(mol, method: str, gpu: bool):
    """A PySCF mean-field object: HF (restricted, or unrestricted for open shells; "rohf" too)
    or Kohn–Sham with any functional libxc knows."""
    from pyscf import dft, scf

    m = method.strip().lower()
    open_shell = mol.spin != 0
    if m in ("hf", "rhf", "uhf", "rohf"):
        mf = {"rhf": scf.RHF, "uhf": scf.UHF, "rohf": scf.ROHF}.get(m, scf.UHF if open_shell else scf.RHF)(mol)
    else:
        mf = dft.UKS(mol) if open_shell else dft.RKS(mol)
        mf.xc = m
    if gpu:
        mf = mf.to_gpu()
    return mf


def _constraint(coordinate: dict, at: float) -> str:
    """geomeTRIC's constraints file holding the scan's coordinate at ``at`` (Å or degrees)."""
    kind, atoms = coordinate["kind"], " ".join(str(a) for a in coordinate["atoms"])
    return f"$set\n{kind} {atoms} {at:.8f}\n"


def _molden_text(mf, modes=None) -> str:
    """The Molden file PySCF writes of ``mf``, with ``[FREQ]``/``[FR-COORD]``/``[FR-NORM-COORD]``
    sections when normal modes are given."""
    from pyscf.tools import molden

    fd, path = tempfile.mkstemp(suffix=".molden")
    os.close(fd)
    try:
        molden.from_scf(mf, path)
        with open(path) as f:
            text = f.read()
    finally:
        os.unlink(path)
    if modes is not None:
        text += modes
    return text


# km/mol per (e²/amu): an IR intensity from a dipole derivative along a mass-weighted normal
# coordinate in atomic units (e/√amu).
KM_PER_MOL = 974.8801


def dipole_derivatives(mf, step: float = 1e-3):
    """∂μ/∂x (3N × 3, atomic units) by central differences of the SCF dipole, each displaced
    geometry's SCF starting from the last one's density (PySCF's scanner)."""
    import numpy as np

    mol = mf.mol
    scanner = mf.as_scanner()
    coords = mol.atom_coords()
    out = np.zeros((mol.natm * 3, 3))
    for a in range(mol.natm):
        for x in range(3):
            mu = []
            for sign in (1.0, -1.0):
                c = coords.copy()
                c[a, x] += sign * step
                moved = mol.set_geom_(c, unit="Bohr", inplace=False)
                scanner(moved)
                if not scanner.converged:
                    raise ComputeError(f"the SCF at a displaced geometry (atom {a + 1}) did not converge")
                mu.append(scanner.dip_moment(unit="AU", verbose=0))
            out[3 * a + x] = (mu[0] - mu[1]) / (2 * step)
    return out


def _normal_modes(mf) -> str:
    """The Hessian's normal modes as Molden sections: wavenumbers (cm⁻¹, imaginary ones
    negative), the geometry (bohr), each mode's Cartesian displacements, and IR intensities
    (km/mol) from the dipole's derivatives along each mode."""
    import numpy as np
    from pyscf.hessian import thermo

    mol = mf.mol
    hessian = mf.Hessian().kernel()
    result = thermo.harmonic_analysis(mol, hessian)
    freq = np.asarray(result["freq_wavenumber"])
    # Imaginary wavenumbers come back complex (or NaN-free imaginary parts): Molden writes them negative.
    wavenumbers = np.where(np.abs(np.imag(freq)) > np.abs(np.real(freq)), -np.abs(np.imag(freq)), np.real(freq))
    modes = np.asarray(result["norm_mode"]).reshape(len(wavenumbers), mol.natm, 3)
    # PySCF's modes are mass-weighted eigenvectors over √mass (amu): x = mode · Q.
    along = modes.reshape(len(wavenumbers), -1) @ dipole_derivatives(mf)
    intensities = KM_PER_MOL * (along**2).sum(axis=1)
    lines = ["[FREQ]"] + [f"{w:.4f}" for w in wavenumbers]
    lines.append("[FR-COORD]")
    for i in range(mol.natm):
        x, y, z = mol.atom_coord(i)
        lines.append(f"{mol.atom_pure_symbol(i)} {x:.8f} {y:.8f} {z:.8f}")
    lines.append("[FR-NORM-COORD]")
    for k, mode in enumerate(modes):
        lines.append(f"vibration {k + 1}")
        lines += [f"{dx:.8f} {dy:.8f} {dz:.8f}" for dx, dy, dz in mode]
    lines.append("[INT]")
    lines += [f"{i:.6f}" for i in intensities]
    return "\n".join(lines) + "\n"


def compute_frame(task: dict) -> dict:
    """One frame: the SCF (a constrained optimisation first when relaxed), from the neighbour's
    density when one is given. Never raises: a failure is returned, with its reason, so a chain
    and a Dask graph go on. Returns the Molden text, the energy, the SCF cycles, the optimised
    geometry (Å) and the density for the next frame."""
    import numpy as np
    from pyscf import gto, lib

    settings, frame = task["settings"], task["frame"]
    start = time.perf_counter()
    out = {"index": task["index"], "at": frame["at"], "file": frame["file"], "key": task["key"]}
    try:
        if task.get("threads"):
            lib.num_threads(int(task["threads"]))
        symbols, angstrom = frame["symbols"], task.get("angstrom") or frame["angstrom"]
        mol = gto.M(
            atom=[(s, tuple(p)) for s, p in zip(symbols, angstrom)],
            basis=settings["basis"],
            charge=int(settings["charge"]),
            spin=int(settings["spin"]),
            unit="Angstrom",
            symmetry=False,
            verbose=0,
        )
        cycles = [0]

        def counted(mol):
            mf = _mean_field(mol, settings["method"], settings.get("gpu", False))
            mf.max_cycle = int(settings.get("max_cycles", 100))
            # Tighter than PySCF's default (1e-9): orbital energies to 1e-7 Eh, which the
            # frames of a scan are compared by.
            mf.conv_tol = float(settings.get("conv_tol", 1e-10))
            mf.callback = lambda envs: cycles.__setitem__(0, cycles[0] + 1)
            return mf

        dm0 = task.get("dm0")
        if settings.get("relaxed"):
            from pyscf.geomopt.geometric_solver import kernel as optimize

            fd, path = tempfile.mkstemp(suffix=".txt")
            with os.fdopen(fd, "w") as f:
                f.write(_constraint(settings["coordinate"], frame["at"]))
            try:
                mf = counted(mol)
                if dm0 is not None:
                    mf.kernel(dm0=dm0)
                converged, mol = optimize(mf, assert_convergence=False, constraints=path, maxsteps=int(settings.get("max_steps", 100)))
            finally:
                os.unlink(path)
            if not converged:
                raise ComputeError(f"the constrained optimisation did not converge in {settings.get('max_steps', 100)} steps")
            # The optimiser ran on a copy: the final SCF below starts from the neighbour's density.
            cycles[0] = 0
        mf = counted(mol)
        mf.kernel(dm0=dm0)
        if not mf.converged:
            raise ComputeError(f"the SCF did not converge in {mf.max_cycle} cycles")
        modes = _normal_modes(mf) if settings.get("freq") else None
        dm = mf.make_rdm1()
        out.update(
            ok=True,
            molden=_molden_text(mf, modes),
            energy=float(mf.e_tot),
            cycles=cycles[0],
            angstrom=(mol.atom_coords(unit="Angstrom")).tolist(),
            dm=np.asarray(getattr(dm, "get", lambda: dm)()),
        )
    except Exception as e:  # a frame's failure is reported, the others go on
        out.update(ok=False, error=str(e) or type(e).__name__)
    out["seconds"] = time.perf_counter() - start
    return out


def chains(n: int, start: int, parallel: int, relaxed: bool) -> list[list[int]]:
    """The order frames are computed in, as chains run one after another, each frame next to
    one computed before it where it can be. A relaxed scan runs two chains outward from
    ``start`` (each geometry starts from its neighbour's optimised one). A rigid scan splits
    the frames into ``parallel`` contiguous blocks of nearly equal size, each run outward from
    the end nearest ``start`` (the block holding ``start``: up from it, then down)."""
    if relaxed:
        return [c for c in (list(range(start, n)), list(range(start - 1, -1, -1))) if c]
    k = max(1, min(parallel, n))
    bounds = [round(b * n / k) for b in range(k + 1)]
    out = []
    for lo, hi in zip(bounds, bounds[1:]):
        if lo <= start < hi:
            out.append(list(range(start, hi)) + list(range(start - 1, lo - 1, -1)))
        elif hi <= start:
            out.append(list(range(hi - 1, lo - 1, -1)))
        else:
            out.append(list(range(lo, hi)))
    return [c for c in out if c]


def _read_log(directory: str) -> dict:
    """The last record of each file in the directory's compute log."""
    records = {}
    try:
        with open(os.path.join(directory, LOG)) as f:
            for line in f:
                try:
                    r = json.loads(line)
                except ValueError:
                    continue  # a line cut short by a killed run
                records[r.get("file")] = r
    except FileNotFoundError:
        pass
    return records


class _Local:
    """Frames run here (one process) or in a pool of local processes."""

    def __init__(self, processes: int, threads: int):
        self.pool = None
        if processes > 1:
            import multiprocessing
            from concurrent.futures import ProcessPoolExecutor

            # Each process's BLAS and OpenMP threads, set before it imports numpy: OpenBLAS
            # otherwise starts a thread per core in every process, and two processes on two
            # cores ran each frame 1.4× slower than one alone instead of 1.07×.
            for name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
                os.environ[name] = str(threads)
            # Not "fork": a process forked after OpenMP has started its threads hangs in them.
            context = multiprocessing.get_context("spawn")
            self.pool = ProcessPoolExecutor(max_workers=processes, mp_context=context)
        self.pending = set()
        self.ready = []

    def submit(self, task):
        if self.pool is None:
            self.ready.append(compute_frame(task))
        else:
            self.pending.add(self.pool.submit(compute_frame, task))

    def next(self):
        if self.ready:
            return self.ready.pop(0)
        from concurrent.futures import FIRST_COMPLETED, wait

        done, self.pending = wait(self.pending, return_when=FIRST_COMPLETED)
        first, *rest = done
        self.ready += [f.result() for f in rest]
        return first.result()

    def busy(self):
        return bool(self.ready or self.pending)

    def close(self):
        if self.pool is not None:
            self.pool.shutdown(cancel_futures=True)


class _Dask:
    """Frames as tasks of a Dask cluster: the scheduler at an address, or a ``Client`` given."""

    def __init__(self, client):
        from distributed import as_completed

        self.client = client
        self.done = as_completed()

    def submit(self, task):
        self.done.add(self.client.submit(compute_frame, task, pure=False))

    def next(self):
        return next(self.done).result()

    def busy(self):
        return not self.done.is_empty()

    def close(self):
        pass


def _write(path: str, text: str) -> None:
    """Writes a file whole or not at all (a killed run leaves no half file to keep)."""
    tmp = path + ".part"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def run(job: dict, emit=lambda event: None, client=None) -> list[dict]:
    """Computes a job's frames into its directory, calling ``emit`` with each event (see the
    module's text); returns every frame's record, in frame order (``ok`` false for a failure)."""
    relaxed, dask = bool(job.get("relaxed")), job.get("dask") is not None or client is not None
    require(relaxed=relaxed, dask=dask and client is None, gpu=bool(job.get("gpu")))
    settings = {k: v for k, v in job.items() if k not in ("frames", "dir", "workers", "dask", "start", "output")}
    frames, directory = job["frames"], job["dir"]
    os.makedirs(directory, exist_ok=True)
    log = _read_log(directory)
    keys = [frame_key(settings, f) for f in frames]
    records: list[dict | None] = [None] * len(frames)
    for i, f in enumerate(frames):
        r = log.get(f["file"])
        if r and r.get("ok") and r.get("key") == keys[i] and os.path.exists(os.path.join(directory, f["file"])):
            records[i] = dict(r, index=i, kept=True)
    workers = max(1, int(job.get("workers") or 1))
    # The scheduler at the address the job names (the user's), disconnected at the end.
    own_client = dask and client is None
    if own_client:
        from distributed import Client

        client = Client(job["dask"], timeout=30)
    parallel = max(1, len(client.scheduler_info().get("workers", {}))) if dask else workers
    emit({"event": "start", "frames": len(frames), "kept": sum(r is not None for r in records), "versions": versions(relaxed, dask)})
    for r in records:
        if r is not None:
            emit({"event": "frame", **{k: r[k] for k in ("index", "at", "file", "ok", "energy", "cycles", "seconds")}, "kept": True})
    todo = [[i for i in c if records[i] is None] for c in chains(len(frames), int(job.get("start", 0)), parallel, relaxed)]
    todo = [c for c in todo if c]
    # A worker is a core: as many processes as there are chains to run at once (a relaxed
    # scan has two), each with its share of the workers as OpenMP threads. On a cluster each
    # Dask worker has its own threads.
    processes = max(1, min(workers, len(todo)))
    threads = None if dask else max(1, workers // processes)
    pool = _Dask(client) if dask else _Local(processes, threads)
    # The frame each chain computes next, with its neighbour's density and geometry.
    def task(i):
        """Frame ``i``, from a computed neighbour's density (and, relaxed, its geometry)."""
        t = {"index": i, "key": keys[i], "settings": settings, "frame": frames[i], "threads": threads}
        done = [records[j] for j in (i - 1, i + 1) if 0 <= j < len(frames) and records[j] and records[j].get("ok")]
        # One computed in this run (it has a density) before one kept from an earlier run.
        done.sort(key=lambda r: r.get("dm") is None)
        if done:
            t["dm0"] = done[0].get("dm")
            if relaxed:
                t["angstrom"] = done[0].get("angstrom")
        return t

    next_of = {}
    try:
        for c in todo:
            pool.submit(task(c[0]))
            next_of[c[0]] = c[1:]
        with open(os.path.join(directory, LOG), "a") as logfile:
            while pool.busy():
                r = pool.next()
                i = r["index"]
                if r["ok"]:
                    _write(os.path.join(directory, r["file"]), r.pop("molden"))
                record = {k: v for k, v in r.items() if k not in ("dm", "molden")}
                logfile.write(json.dumps(record) + "\n")
                logfile.flush()
                records[i] = r
                emit({"event": "frame", **{k: v for k, v in record.items() if k not in ("key", "angstrom")}})
                rest = next_of.pop(i, [])
                if rest:
                    pool.submit(task(rest[0]))
                    next_of[rest[0]] = rest[1:]
    finally:
        pool.close()
        if own_client:
            client.close()
    done = [dict(r, dm=None) if r else r for r in records]
    emit({
        "event": "done",
        "computed": sum(1 for r in done if r and r.get("ok") and not r.get("kept")),
        "kept": sum(1 for r in done if r and r.get("kept")),
        "failed": sum(1 for r in done if r and not r.get("ok")),
    })
    return done


def _end_with_parent() -> None:
    """The ``orbcloud`` command starts this script in a process group of its own with a pipe
    for standard input that it never writes: the pipe closes when the command ends, however it
    ends (Ctrl-C, killed, a cancelled scan), and then this process and its workers end too."""
    import signal
    import threading

    if os.getpgrp() != os.getpid() or sys.stdin is None or sys.stdin.isatty():
        return

    def watch():
        try:
            sys.stdin.buffer.read()
        finally:
            os.killpg(os.getpgrp(), signal.SIGKILL)

    threading.Thread(target=watch, daemon=True).start()


def main(argv: list[str]) -> int:
    if len(argv) != 1:
        print("usage: _compute.py JOB.json", file=sys.stderr)
        return 2
    with open(argv[0]) as f:
        job = json.load(f)
    # Events go to the standard output as it was; what PySCF and geomeTRIC print (geomeTRIC's
    # log, warnings) goes to the job's ``output`` file or nowhere, here and in the worker
    # processes that inherit it.
    events = os.fdopen(os.dup(1), "w")
    output = job.get("output") or os.devnull
    if output != os.devnull:
        os.makedirs(os.path.dirname(os.path.abspath(output)), exist_ok=True)
    quiet = os.open(output, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644)
    os.dup2(quiet, 1)
    os.dup2(quiet, 2)
    os.close(quiet)
    _end_with_parent()

    def emit(event):
        events.write(json.dumps(event) + "\n")
        events.flush()

    try:
        run(job, emit)
    except ComputeError as e:
        emit({"event": "error", "message": str(e)})
        return 3
    except Exception as e:  # anything else ends the run with its reason, never a traceback alone
        emit({"event": "error", "message": f"{type(e).__name__}: {e}"})
        return 1
    return 0


if __name__ == "__main__":
    code = main(sys.argv[1:])
    # No interpreter shutdown: the thread watching standard input holds its lock.
    sys.stdout.flush()
    os._exit(code)

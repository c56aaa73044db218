#!/usr/bin/env python3
"""Writes the structure-reader fixtures in tests/fixtures/structures/ and the values gemmi reads
from them (expected.json), the independent reference the reader tests compare with.

Sources: PDB entries 4E43 (HIV protease, alternate locations, CONECT, HELIX/SHEET) and the NMR
ensemble of neopetrosiamide (several models), as shipped in the MDAnalysisTests sdist on PyPI;
PDB data are public domain (CC0). Files are cut to a few hundred lines. Needs: pip install gemmi.
"""
import gzip
import json
import math
import os
import subprocess
import sys
import tarfile

import gemmi

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "..", "tests", "fixtures", "structures")
CACHE = os.path.expanduser("~/.cache/orbcloud")
SDIST = "mdanalysistests-2.11.0"


def source(name):
    """A data file of the MDAnalysisTests sdist, downloaded once into ~/.cache/orbcloud."""
    path = os.path.join(CACHE, name)
    if not os.path.exists(path):
        os.makedirs(CACHE, exist_ok=True)
        archive = os.path.join(CACHE, SDIST + ".tar.gz")
        if not os.path.exists(archive):
            subprocess.check_call([sys.executable, "-m", "pip", "download", "--no-deps", "--no-binary", ":all:",
                                   "-d", CACHE, SDIST.replace("-", "==")])
        with tarfile.open(archive) as t:
            member = t.getmember(f"{SDIST}/MDAnalysisTests/data/{name}")
            with open(path, "wb") as f:
                f.write(t.extractfile(member).read())
    return path


def excerpt_4e43():
    """Chain A residues 30-50 (altlocs at 34 and 46), the acetates and a few waters, with the
    HELIX, SHEET and CONECT records that name what is kept."""
    lines = open(source("4E43.pdb")).read().splitlines()
    kept, serials, waters = [], set(), 0
    for l in lines:
        rec = l[:6].strip()
        if rec in ("HEADER", "TITLE", "HELIX", "SHEET", "CRYST1"):
            kept.append(l)
        elif rec in ("ATOM", "HETATM"):
            chain, resname, number = l[21], l[17:20], int(l[22:26])
            take = chain == "A" and 30 <= number <= 50
            take |= rec == "HETATM" and resname == "ACT"
            if rec == "HETATM" and resname == "HOH" and waters < 12:
                waters += 1
                take = True
            if take:
                kept.append(l)
                serials.add(int(l[6:11]))
    for l in lines:
        if l.startswith("CONECT"):
            numbers = [int(l[i:i + 5]) for i in range(6, len(l.rstrip()), 5) if l[i:i + 5].strip()]
            if all(n in serials for n in numbers):
                kept.append(l)
    kept.append("END")
    return "\n".join(kept) + "\n"


def excerpt_nmr():
    """The first three models, residues 1-4 of each."""
    out, model = [], 0
    for l in open(source("nmr_neopetrosiamide.pdb")):
        rec = l[:6].strip()
        if rec == "MODEL":
            model += 1
        if model > 3:
            break
        if rec in ("MODEL", "ENDMDL") or (rec in ("ATOM", "HETATM") and int(l[22:26]) <= 4):
            out.append(l.rstrip("\n"))
    out.append("END")
    return "\n".join(out) + "\n"


def hy36(value, width):
    """Hybrid-36 encoding (the wwPDB convention for serials and residue numbers past the columns)."""
    if value < 10 ** width:
        return str(value).rjust(width)
    digits = "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZ"
    value -= 10 ** width
    value += 10 * 36 ** (width - 1)
    s = ""
    while value:
        value, r = divmod(value, 36)
        s = digits[r] + s
    return s.rjust(width)


def hybrid36_pdb():
    """Waters numbered past 99,999 atoms and 9,999 residues, as a big system writes them."""
    out = []
    for k in range(12):
        serial, resnum = 99_994 + 3 * k, 9_996 + k
        ox, oy, oz = 3.1 * k, 1.5 * (k % 3), -2.0 + 0.5 * k
        for j, (name, dx, dy, el) in enumerate([("OW", 0, 0, "O"), ("HW1", 0.757, 0.586, "H"), ("HW2", -0.757, 0.586, "H")]):
            out.append(f"HETATM{hy36(serial + j, 5)} {name:<4} HOH W{hy36(resnum, 4)}    "
                       f"{ox + dx:8.3f}{oy + dy:8.3f}{oz:8.3f}  1.00 {20 + k:5.2f}          {el:>2}")
    out.append(f"CONECT{hy36(100_000, 5)}{hy36(100_001, 5)}{hy36(100_002, 5)}")
    out.append("END")
    return "\n".join(out) + "\n"


def shuffled_cif(st):
    """The structure's _atom_site with columns in another order and some values quoted."""
    doc = st.make_mmcif_document()
    block = doc.sole_block()
    table = block.find_mmcif_category("_atom_site.")
    tags = list(table.tags)
    order = list(reversed(range(len(tags))))
    lines = [f"data_{block.name}", "_struct.title 'shuffled columns; quoted values'", "loop_"]
    lines += [tags[i] for i in order]
    for row in table:
        values = [row[i] for i in order]
        # Quote every comp id and atom name with a quote style CIF allows.
        values = [f'"{v}"' if tags[i].endswith(("comp_id", "atom_id")) and "'" in v else
                  (f"'{v}'" if tags[i].endswith(("comp_id", "atom_id")) else v) for v, i in zip(values, order)]
        lines.append(" ".join(values))
    lines.append("#")
    return "\n".join(lines) + "\n"


def trajectory_xyz():
    """Ethane turned about its C–C bond in three frames (a trajectory)."""
    frames = []
    for k, phi in enumerate([0.0, 30.0, 60.0]):
        atoms = [("C", 0.0, 0.0, 0.0), ("C", 0.0, 0.0, 1.54)]
        for j in range(3):
            a = math.radians(120 * j)
            atoms.append(("H", 1.02 * math.cos(a), 1.02 * math.sin(a), -0.36))
            b = math.radians(120 * j + 60 + phi)
            atoms.append(("H", 1.02 * math.cos(b), 1.02 * math.sin(b), 1.90))
        frames.append(f"{len(atoms)}\nethane, H-C-C-H turned {phi:.0f} degrees\n" +
                      "\n".join(f"{e:<2} {x:12.6f} {y:12.6f} {z:12.6f}" for e, x, y, z in atoms))
    return "\n".join(frames) + "\n"


def describe(path):
    """What gemmi reads: per model atom counts, altlocs, chains, residues, coordinates."""
    st = gemmi.read_structure(path)
    models = []
    for m in st:
        atoms = [a for ch in m for r in ch for a in r]
        first_model_residues = [r for ch in m for r in ch]
        models.append({
            "atoms": len(atoms),
            "altloc_atoms": sum(1 for a in atoms if a.altloc != "\0"),
            "residues": len(first_model_residues),
            "chains": sorted({ch.name for ch in m}),
            "first": [atoms[0].pos.x, atoms[0].pos.y, atoms[0].pos.z],
            "last": [atoms[-1].pos.x, atoms[-1].pos.y, atoms[-1].pos.z],
            "last_serial": atoms[-1].serial,
            "last_residue": first_model_residues[-1].seqid.num,
            "b_factors_sum": round(sum(a.b_iso for a in atoms), 4),
            "occupancy_sum": round(sum(a.occ for a in atoms), 4),
            "hydrogens": sum(1 for a in atoms if a.element.name in ("H", "D")),
        })
    return {"models": models}


def main():
    os.makedirs(OUT, exist_ok=True)
    files = {
        "4e43_excerpt.pdb": excerpt_4e43(),
        "nmr_excerpt.pdb": excerpt_nmr(),
        "hybrid36.pdb": hybrid36_pdb(),
        "ethane_trajectory.xyz": trajectory_xyz(),
    }
    for name, text in files.items():
        open(os.path.join(OUT, name), "w").write(text)
    st = gemmi.read_structure(os.path.join(OUT, "4e43_excerpt.pdb"))
    st.setup_entities()
    st.make_mmcif_document().write_file(os.path.join(OUT, "4e43_excerpt.cif"))
    shuffled = shuffled_cif(st)
    with gzip.open(os.path.join(OUT, "4e43_shuffled.cif.gz"), "wt") as f:
        f.write(shuffled)
    expected = {name: describe(os.path.join(OUT, name))
                for name in ["4e43_excerpt.pdb", "4e43_excerpt.cif", "4e43_shuffled.cif.gz", "nmr_excerpt.pdb",
                             "hybrid36.pdb"]}
    expected["generator"] = f"gemmi {gemmi.__version__}"
    with open(os.path.join(OUT, "expected.json"), "w") as f:
        json.dump(expected, f, indent=1)
        f.write("\n")
    for name in sorted(os.listdir(OUT)):
        print(f"{name:28s} {os.path.getsize(os.path.join(OUT, name)):8d} bytes")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Builds a ~10^6-atom test system: PDB entry 4E43 (HIV protease with waters and acetates, public
domain) replicated on an 8x9x8 lattice, 1,081,152 atoms in 1,728 chains; writes it as mmCIF and
PDB (hybrid-36 serials) and times gemmi reading each, the peer figure for `orbcloud bench load`.

    python3 scripts/make_million.py [OUT_DIR] [--lattice NxMxK] [--name NAME]
        (default target/million, 8x9x8, "million"; needs gemmi)

Smaller lattices make the 10^4- and 10^5-atom systems of the surface benchmarks
(`--lattice 5x1x1 --name p10k`, `--lattice 6x3x3 --name p100k`).
"""
import os
import sys
import time

import gemmi

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_structure_fixtures import source  # noqa: E402

NAMES = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789"


def chain_name(k):
    """Two characters, as a PDB file's columns 21-22 hold."""
    return NAMES[k // len(NAMES)] + NAMES[k % len(NAMES)]


def main():
    import argparse

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default=os.path.join(os.path.dirname(__file__), "..", "target", "million"))
    ap.add_argument("--lattice", default="8x9x8", help="copies along x, y and z")
    ap.add_argument("--name", default="million", help="file name stem")
    args = ap.parse_args()
    out = args.out
    lattice = tuple(int(n) for n in args.lattice.split("x"))
    os.makedirs(out, exist_ok=True)
    unit = gemmi.read_structure(source("4E43.pdb"))
    unit.remove_empty_chains()
    box = unit.calculate_box()
    size = [box.maximum.x - box.minimum.x + 4, box.maximum.y - box.minimum.y + 4, box.maximum.z - box.minimum.z + 4]
    big = gemmi.Structure()
    big.name = "4E43 x %d lattice" % (lattice[0] * lattice[1] * lattice[2])
    model = gemmi.Model(1)
    k = 0
    for i in range(lattice[0]):
        for j in range(lattice[1]):
            for l in range(lattice[2]):
                shift = gemmi.Position(i * size[0], j * size[1], l * size[2])
                for ch in unit[0]:
                    c = gemmi.Chain(chain_name(k))
                    k += 1
                    for r in ch:
                        c.add_residue(r)
                    for r in c:
                        for a in r:
                            a.pos = a.pos + shift
                    model.add_chain(c)
    big.add_model(model)
    big.setup_entities()
    atoms = big[0].count_atom_sites()
    cif = os.path.join(out, args.name + ".cif")
    pdb = os.path.join(out, args.name + ".pdb")
    big.make_mmcif_document().write_file(cif)
    big.write_pdb(pdb)
    print(f"{atoms} atoms in {k} chains: {cif} ({os.path.getsize(cif)} bytes), {pdb} ({os.path.getsize(pdb)} bytes)")
    for path in (cif, pdb):
        best = min(timed(path) for _ in range(3))
        print(f"gemmi {gemmi.__version__} read_structure {os.path.basename(path)}: {best * 1e3:.0f} ms "
              f"({atoms / best:.3e} atoms/s)")


def timed(path):
    t = time.perf_counter()
    gemmi.read_structure(path)
    return time.perf_counter() - t


if __name__ == "__main__":
    main()

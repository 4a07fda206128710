#!/usr/bin/env python3
"""Particles against elements at the same material points (docs/validation.md, "The weight at the
impact face").

Each element quadrilateral's centre node starts at the centre of a lattice cell, where a particle of
the same scene and spacing starts, so the final positions of the same material can be compared.
Both CSV files come from `gpa_face_probe SCENE REFINE VARIANT nodes.csv` (tools/face_probe.cpp),
one run with particles and one with `discretisation=elements`.

Prints the mean radial error (particle minus element, mm) of the particles in the bottom ROWS
lattice rows (default 4), split into the four columns nearest the axis, the middle, and the outer
column.

Usage: face_compare.py PARTICLES.csv ELEMENTS.csv SPACING_M [ROWS]
"""
import csv
import sys


def read(path):
    with open(path, newline="") as f:
        return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    particles, elements = read(sys.argv[1]), read(sys.argv[2])
    spacing = float(sys.argv[3])
    rows = int(sys.argv[4]) if len(sys.argv) > 4 else 4

    # Cell centres sit at odd multiples of half a spacing: key them by those integers.
    def key(x0, z0):
        return round(2 * x0 / spacing), round(2 * z0 / spacing)

    final_x = {key(e["x0"], e["z0"]): e["x"] for e in elements}
    outer = max(key(p["x0"], p["z0"])[0] for p in particles)
    groups = {"axis (4 columns)": [], "middle": [], "outer column": []}
    for p in particles:
        k = key(p["x0"], p["z0"])
        if k[1] > 2 * rows - 1 or k not in final_x:
            continue
        error = p["x"] - final_x[k]
        if k[0] == outer:
            groups["outer column"].append(error)
        elif k[0] <= 7:  # x0 below 4 spacings
            groups["axis (4 columns)"].append(error)
        else:
            groups["middle"].append(error)
    print(f"bottom {rows} rows, mean radial error (particles - elements):",
          ", ".join(f"{name} {1e3 * sum(v) / len(v):+.3f} mm ({len(v)} nodes)" for name, v in groups.items() if v))


if __name__ == "__main__":
    main()

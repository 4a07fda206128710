#!/usr/bin/env python3
"""The hoop pairing of a 3D Taylor bar's impact face, measured from a run's snapshots.

    python3 scripts/face_gaps.py RUN_FOLDER RADIUS SPACING [--band LO HI]

Takes the nodes of the first layer (initial height within half a spacing of the lowest node) whose
initial distance from the bar's axis (the z axis through x = y = 0) lies in the band LO-HI of the
radius (0.75-0.9 by default), sorts them by their angle about the axis, and prints the spread of
the angular gaps between neighbours (standard deviation over mean) in the first and in the last
snapshot. A lattice cut by a circle starts near 0.3-0.6; nodes that close up in pairs into radial
spokes raise it towards 1 and beyond (docs/validation.md, "The face pairs in the hoop direction").
RADIUS and SPACING in metres. Reads the binary .vtp snapshots gpa writes (appended raw data, UInt64
headers), with the standard library only.
"""

import argparse
import glob
import math
import os
import re
import struct
import sys

_TYPES = {"Float64": "d", "Float32": "f", "UInt8": "B", "Int32": "i", "UInt32": "I", "Int64": "q", "UInt64": "Q"}


def read_snapshot(path):
    """The points and the point-data arrays of one .vtp file, as lists of tuples or numbers."""
    data = open(path, "rb").read()
    marker = b'<AppendedData encoding="raw">'
    at = data.find(marker)
    if at < 0:
        raise ValueError(f"{path}: no appended raw data (not a snapshot gpa wrote?)")
    start = data.index(b"_", at + len(marker)) + 1
    header = data[:at].decode()
    count = int(re.search(r'NumberOfPoints="(\d+)"', header).group(1))

    def block(kind, components, offset):
        code = _TYPES[kind]
        p = start + offset
        size = struct.unpack("<Q", data[p : p + 8])[0]
        values = struct.unpack(f"<{size // struct.calcsize(code)}{code}", data[p + 8 : p + 8 + size])
        if components == 1:
            return list(values)
        return [values[k * components : (k + 1) * components] for k in range(count)]

    arrays = {}
    for m in re.finditer(
        r'<DataArray type="(\w+)" Name="(\w+)" NumberOfComponents="(\d+)" format="appended" offset="(\d+)"', header
    ):
        arrays[m.group(2)] = block(m.group(1), int(m.group(3)), int(m.group(4)))
    points = re.search(r'<Points>\s*<DataArray type="(\w+)"[^>]*NumberOfComponents="3" format="appended" offset="(\d+)"', header)
    arrays["points"] = block(points.group(1), 3, int(points.group(2)))
    return arrays


def gap_spread(snapshot, radius, spacing, band):
    """The spread of the angular gaps of the band's first-layer nodes, and their count."""
    if "displacement" not in snapshot:
        raise ValueError("the snapshot has no `displacement` field (output.fields)")
    initial = [tuple(x[k] - u[k] for k in range(3)) for x, u in zip(snapshot["points"], snapshot["displacement"])]
    bottom = min(x0[2] for x0 in initial)
    angles = []
    for x, x0 in zip(snapshot["points"], initial):
        r0 = math.hypot(x0[0], x0[1])
        if x0[2] - bottom < 0.5 * spacing and band[0] * radius <= r0 <= band[1] * radius:
            angles.append(math.atan2(x[1], x[0]))
    angles.sort()
    if len(angles) < 3:
        raise ValueError(f"only {len(angles)} nodes in the band: check RADIUS and SPACING")
    gaps = [b - a for a, b in zip(angles, angles[1:])]
    mean = sum(gaps) / len(gaps)
    deviation = math.sqrt(sum((g - mean) ** 2 for g in gaps) / len(gaps))
    return deviation / mean, len(angles)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", help="a run's output folder (with particles_*.vtp)")
    parser.add_argument("radius", type=float, help="the bar's radius, m")
    parser.add_argument("spacing", type=float, help="the node spacing, m")
    parser.add_argument("--band", type=float, nargs=2, default=(0.75, 0.9), metavar=("LO", "HI"))
    args = parser.parse_args()
    files = sorted(glob.glob(os.path.join(args.run, "particles_*.vtp")))
    if len(files) < 2:
        sys.exit(f"face_gaps.py: {args.run}: fewer than two snapshots (particles_*.vtp)")
    try:
        first, count = gap_spread(read_snapshot(files[0]), args.radius, args.spacing, args.band)
        last, _ = gap_spread(read_snapshot(files[-1]), args.radius, args.spacing, args.band)
    except (ValueError, KeyError, struct.error) as e:
        sys.exit(f"face_gaps.py: {e}")
    print(f"{args.run}: gap spread {first:.2f} -> {last:.2f} ({count} nodes, band {args.band[0]}-{args.band[1]} R)")


if __name__ == "__main__":
    main()

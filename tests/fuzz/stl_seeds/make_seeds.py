#!/usr/bin/env python3
"""Writes the seeds of the STL fuzz target (tests/fuzz/fuzz_stl.cpp) beside this script: a
tetrahedron and an octahedron in both forms, a binary cube, and two malformed files, all tiny so
that libFuzzer's mutations stay near the format. (libFuzzer reads this script as a seed too: an
input that is no STL file.) After changing a shape: python3 tests/fuzz/stl_seeds/make_seeds.py"""
import itertools
import pathlib
import struct

HERE = pathlib.Path(__file__).parent

# Each shape's triangles as corner triples, outward by the right-hand rule.
TETRA = [((0, 0, 0), (0, 1, 0), (1, 0, 0)), ((0, 0, 0), (1, 0, 0), (0, 0, 1)),
         ((0, 0, 0), (0, 0, 1), (0, 1, 0)), ((1, 0, 0), (0, 1, 0), (0, 0, 1))]


def cube(a):
    corner = lambda k: ((k & 1) * a, (k >> 1 & 1) * a, (k >> 2 & 1) * a)
    faces = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    out = []
    for f in faces:
        out += [(corner(f[0]), corner(f[1]), corner(f[2])), (corner(f[0]), corner(f[2]), corner(f[3]))]
    return out


def octahedron(r):
    out = []
    for sx, sy, sz in itertools.product((1, -1), repeat=3):
        tri = ((sx * r, 0, 0), (0, sy * r, 0), (0, 0, sz * r))
        out.append(tri if sx * sy * sz > 0 else (tri[0], tri[2], tri[1]))
    return out


def binary(tris, header=b"binary seed"):
    out = header.ljust(80, b" ") + struct.pack("<I", len(tris))
    for t in tris:
        out += struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *c) for c in t) + b"\0\0"
    return out


def ascii_(tris, name, number="{:g}".format, end="\n"):
    lines = [f"solid {name}"]
    for t in tris:
        lines += ["facet normal 0 0 0", " outer loop"]
        lines += ["  vertex " + " ".join(number(x) for x in c) for c in t]
        lines += [" endloop", "endfacet"]
    return (end.join(lines + [f"endsolid {name}", ""])).encode()


seeds = {
    "tetra_binary.stl": binary(TETRA),
    # A byte-order mark and CR LF line ends; numbers written with exponents.
    "tetra_ascii_crlf.stl": b"\xef\xbb\xbf" + ascii_(TETRA, "tetra", "{:.1e}".format, "\r\n"),
    # A binary header that begins like an ASCII file.
    "cube_binary.stl": binary(cube(2.5), b"solid cube"),
    "octahedron_binary.stl": binary(octahedron(1.5)),
    "octahedron_ascii.stl": ascii_(octahedron(1.5), "octahedron"),
    # Malformed: a tetrahedron with a hole (one facet left out), and a binary cube cut short.
    "open_tetra_ascii.stl": ascii_(TETRA[:3], "open"),
    "cut_cube_binary.stl": binary(cube(1.0))[:-20],
}
for name, data in seeds.items():
    (HERE / name).write_bytes(data)

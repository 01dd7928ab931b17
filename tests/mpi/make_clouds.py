#!/usr/bin/env python3
"""make_clouds.py DIR -- the clouds of tests/mpi/test_mpi.sh, as binary PLY.

Each is made so that the parts of a 2- or 3-rank run (Morton runs of equal
count) have their boundaries in dense regions:
  lattice.ply   a 14 x 11 x 3 lattice (spacing 1, 0.5): cuts fall on shared
                coordinate planes, many neighbours are equidistant (ties by
                input index), plus every 7th point repeated at the end of
                the file (duplicates on both sides of a cut), x y z double
  clusters.ply  two dense clusters and a sparse background in a thin sheet,
                NaN rows, unit normals (orient input), float, big endian
  tiny.ply      2 finite points and 2 NaN rows (a 3-rank run has an empty
                part; K above every part's count)
  ten.ply       10 points (knn:8 with 3 ranks: K above each part's count)
  few.ply       4 finite points and 5 NaN rows: most points cannot be
                fitted (a warning), and a 5-rank run has an empty part
Deterministic (own LCG, no random module state)."""
import math
import struct
import sys

state = 12345


def rnd():
    global state
    state = (state * 6364136223846793005 + 1442695040888963407) % (1 << 64)
    return (state >> 11) / float(1 << 53)


def write(path, pts, normals=None, fmt="<", typ="d"):
    names = ["x", "y", "z"] + (["nx", "ny", "nz"] if normals else [])
    tname = {"d": "double", "f": "float"}[typ]
    order = "binary_little_endian" if fmt == "<" else "binary_big_endian"
    head = "ply\nformat %s 1.0\ncomment tests/mpi\nelement vertex %d\n" % (order, len(pts))
    head += "".join("property %s %s\n" % (tname, n) for n in names) + "end_header\n"
    with open(path, "wb") as f:
        f.write(head.encode())
        for i, p in enumerate(pts):
            row = list(p) + (list(normals[i]) if normals else [])
            f.write(struct.pack(fmt + typ * len(row), *row))


def main(d):
    lat = [(x, y, 0.5 * z + 0.01 * math.sin(x * y)) for x in range(14) for y in range(11)
           for z in range(3)]
    lat += [lat[i] for i in range(0, len(lat), 7)]
    write(d + "/lattice.ply", lat)

    pts, nrm = [], []
    for i in range(1500):
        k = i % 5
        s = 0.01 if k < 2 else 1.0
        o = 0.3 if k == 0 else (0.7 if k == 1 else 0.0)
        x, y = o + s * rnd(), o + s * rnd()
        z = 0.05 * (x * x - y * y)
        if i % 97 == 13:
            x = float("nan")
        pts.append((x, y, z))
        n = (-0.1 * x if x == x else 0.0, 0.1 * y, 1.0)
        sgn = -1 if i % 3 == 0 else 1  # input normals of both signs
        nrm.append(tuple(sgn * c / math.sqrt(sum(v * v for v in n)) for c in n))
    write(d + "/clusters.ply", pts, nrm, ">", "f")

    nan = float("nan")
    write(d + "/tiny.ply", [(0.0, 0.0, 0.0), (nan, 0.0, 0.0), (1.0, 0.5, 0.0), (0.0, nan, nan)])
    write(d + "/ten.ply", [(rnd(), rnd(), 0.1 * rnd()) for _ in range(10)])
    write(d + "/few.ply", [(0.0, 0.0, 0.0), (nan, 0.0, 0.0), (1.0, 0.0, 0.1), (nan, nan, nan),
                           (0.0, 1.0, 0.05), (nan, 1.0, 1.0), (1.0, 1.0, 0.2), (2.0, nan, 0.0),
                           (5.0, 5.0, nan)])


if __name__ == "__main__":
    main(sys.argv[1])

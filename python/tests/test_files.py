"""jetfit.read / jetfit.write over the library's readers and writers:
the command's formats, its error lines, and its rule that a failed write
leaves the old file untouched."""
import os
import struct

import numpy as np
import pytest

import jetfit
from conftest import TOP, fib_sphere, save_xyz


def test_read_cloud_with_and_without_normals(tmp_path, cmd):
    p = fib_sphere(100)
    pts, nrm, faces, attrs = jetfit.read(str(save_xyz(tmp_path / "a.xyz", p)))
    assert np.array_equal(pts, p) and nrm is None and faces is None and attrs == {}
    assert pts.dtype == np.float64 and pts.flags.c_contiguous and pts.flags.owndata is False
    pts, nrm, _, _ = jetfit.read(save_xyz(tmp_path / "b.xyz", p, p))
    assert np.array_equal(nrm, p)
    cmd("generate", "sphere", "-o", tmp_path / "s.ply", "--n", "50")
    pts, _, _, _ = jetfit.read(tmp_path / "s.ply")  # os.PathLike
    assert pts.shape == (50, 3)


def test_read_columns(tmp_path):
    data = np.arange(30, dtype=float).reshape(6, 5)
    np.savetxt(tmp_path / "c.txt", data, fmt="%.17g")
    pts, _, _, _ = jetfit.read(str(tmp_path / "c.txt"), columns=[4, 2, 0])
    assert np.array_equal(pts, data[:, [4, 2, 0]])
    with pytest.raises(ValueError, match="^columns=1,2: expected 3 or 6 column numbers$"):
        jetfit.read(str(tmp_path / "c.txt"), columns=[1, 2])


def test_read_polygons(tmp_path):
    (tmp_path / "q.off").write_text("OFF\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 2 0\n"
                                    "4 0 1 2 3\n3 1 4 2\n")
    v, _, faces, _ = jetfit.read(str(tmp_path / "q.off"))
    assert isinstance(faces, list) and [f.tolist() for f in faces] == [[0, 1, 2, 3], [1, 4, 2]]


@pytest.mark.parametrize("content,ext", [("1 2 3\n4 5 x\n", "xyz"), ("", "xyz"),
                                         ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n", "off"),
                                         ("ply\nformat nonsense 1.0\n", "ply")])
def test_read_errors_are_the_commands(tmp_path, cmd, content, ext):
    f = tmp_path / f"bad.{ext}"
    f.write_text(content)
    rc, err = cmd("estimate", f, "-o", tmp_path / "o.ply", check=False)
    assert rc == 1
    with pytest.raises(jetfit.FileError) as e:
        jetfit.read(str(f))
    assert isinstance(e.value, OSError)
    assert "jetfit: " + str(e.value) == err.strip()


def test_missing_file(tmp_path, cmd):
    rc, err = cmd("estimate", tmp_path / "nope.xyz", "-o", tmp_path / "o.ply", check=False)
    with pytest.raises(OSError) as e:
        jetfit.read(str(tmp_path / "nope.xyz"))
    assert "jetfit: " + str(e.value) == err.strip()


@pytest.mark.parametrize("ext", ["ply", "csv", "xyz", "txt"])
def test_write_formats_equal_the_command(tmp_path, cmd, ext):
    f = save_xyz(tmp_path / "in.xyz", fib_sphere(400))
    cmd("estimate", f, "-o", tmp_path / f"c.{ext}", "--quiet", "--degree", "4", "--ascii")
    pts, _, _, _ = jetfit.read(str(f))
    r = jetfit.estimate(pts, degree=4)
    jetfit.write(str(tmp_path / f"p.{ext}"), r, ascii=True, threads=2)
    assert (tmp_path / f"p.{ext}").read_bytes() == (tmp_path / f"c.{ext}").read_bytes()


def test_mesh_ply_keeps_faces(tmp_path, cmd):
    cmd("generate", "sphere", "-o", tmp_path / "m.off", "--n", "300", "--mesh")
    cmd("estimate", tmp_path / "m.off", "-o", tmp_path / "c.ply", "--quiet", "--neighbors", "rings")
    v, _, faces, _ = jetfit.read(str(tmp_path / "m.off"))
    r = jetfit.estimate_mesh(v, faces)
    jetfit.write(str(tmp_path / "p.ply"), r)
    assert (tmp_path / "p.ply").read_bytes() == (tmp_path / "c.ply").read_bytes()
    _, _, f2, _ = jetfit.read(str(tmp_path / "p.ply"))
    assert np.array_equal(f2, faces)


def test_failed_write_leaves_old_file(tmp_path):
    r = jetfit.estimate(fib_sphere(100))
    old = tmp_path / "out.ply"
    old.write_bytes(b"old content")
    with pytest.raises(ValueError, match="points: 3 rows for a Result of 100"):
        jetfit.write(str(old), r, points=np.zeros((3, 3)))
    with pytest.raises(jetfit.FileError):
        jetfit.write(str(tmp_path / "no" / "such" / "dir.ply"), r)
    with pytest.raises(jetfit.FileError):
        jetfit.write(str(tmp_path / "out.unknown"), r)
    assert old.read_bytes() == b"old content"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.ply"]
    jetfit.write(str(old), r)
    assert old.read_bytes().startswith(b"ply\n")


def test_write_needs_points():
    with pytest.raises(TypeError):
        jetfit.write("x.ply", "not a result")


def test_read_bad_rows(tmp_path, cmd):
    f = tmp_path / "b.xyz"
    f.write_text("0 0 0\n1 0 0\n1 x 0\n0 1 0\n")
    rc, err = cmd("estimate", f, "-o", tmp_path / "o.ply", check=False)
    with pytest.raises(jetfit.FileError) as e:
        jetfit.read(str(f))
    assert "jetfit: " + str(e.value) == err.strip()
    rc, err = cmd("estimate", f, "-o", tmp_path / "o.ply", "--bad-rows", "skip", "--quiet")
    with pytest.warns(RuntimeWarning) as w:
        pts, _, _, _ = jetfit.read(str(f), bad_rows="skip")
    assert "jetfit: " + str(w[0].message) in err
    assert pts.shape == (4, 3) and np.isnan(pts[2]).all() and (pts[3] == [0, 1, 0]).all()
    with pytest.raises(ValueError, match="^bad_rows=keep: "):
        jetfit.read(str(f), bad_rows="keep")


def test_read_attributes_ply_csv(tmp_path):
    """Every other per-point value comes back in its input type: PLY
    properties (normals too), and the named columns of a CSV packed in
    the smallest exact type."""
    n = 7
    p = fib_sphere(n)
    rgb = np.arange(3 * n, dtype=np.uint8).reshape(n, 3) * 11
    inten = np.linspace(-1.5, 2.25, n).astype(np.float32)
    rec = np.zeros(n, dtype=[("x", "<f8"), ("y", "<f8"), ("z", "<f8"), ("red", "u1"),
                             ("green", "u1"), ("blue", "u1"), ("intensity", "<f4"),
                             ("nx", "<f4")])
    rec["x"], rec["y"], rec["z"] = p.T
    rec["red"], rec["green"], rec["blue"] = rgb.T
    rec["intensity"] = inten
    rec["nx"] = 1
    head = ("ply\nformat binary_little_endian 1.0\nelement vertex %d\n" % n
            + "".join("property %s %s\n" % (t, nm) for t, nm in
                      [("double", "x"), ("double", "y"), ("double", "z"), ("uchar", "red"),
                       ("uchar", "green"), ("uchar", "blue"), ("float", "intensity"),
                       ("float", "nx")]) + "end_header\n")
    (tmp_path / "c.ply").write_bytes(head.encode() + rec.tobytes())
    pts, nrm, _, attrs = jetfit.read(tmp_path / "c.ply")
    assert np.array_equal(pts, p) and nrm is None
    assert list(attrs) == ["red", "green", "blue", "intensity", "nx"]
    for k, c in enumerate(("red", "green", "blue")):
        assert attrs[c].dtype == np.uint8 and np.array_equal(attrs[c], rgb[:, k])
    assert attrs["intensity"].dtype == np.float32
    assert np.array_equal(attrs["intensity"], inten)
    with open(tmp_path / "c.csv", "w") as f:
        f.write("id,X,Y,Z,label,w,big\n")
        for i in range(n):
            f.write("%d,%.17g,%.17g,%.17g,%d,%.17g,%d\n" % (i, *p[i], 300 + i, 0.1 * i, -70000))
    pts, _, _, attrs = jetfit.read(tmp_path / "c.csv")
    assert np.array_equal(pts, p)
    assert list(attrs) == ["id", "label", "w", "big"]
    assert attrs["id"].dtype == np.uint8 and np.array_equal(attrs["id"], np.arange(n))
    assert attrs["label"].dtype == np.uint16 and np.array_equal(attrs["label"], 300 + np.arange(n))
    assert attrs["w"].dtype == np.float64 and np.array_equal(attrs["w"], 0.1 * np.arange(n))
    assert attrs["big"].dtype == np.int32 and (attrs["big"] == -70000).all()
    _, _, _, attrs = jetfit.read(save_xyz(tmp_path / "plain.xyz", p))
    assert attrs == {}


def test_read_attributes_las(tmp_path, cmd):
    """A LAS file's dimensions, decoded from the record bits, and the
    extra bytes of a LAS file jetfit wrote: its columns read back."""
    src = os.path.join(TOP, "tests", "data", "las", "simple.las")
    raw = open(src, "rb").read()
    off, = struct.unpack_from("<I", raw, 96)
    rl, = struct.unpack_from("<H", raw, 105)
    n, = struct.unpack_from("<I", raw, 107)
    recs = np.frombuffer(raw, np.uint8, n * rl, off).reshape(n, rl)
    pts, _, _, attrs = jetfit.read(src)
    assert pts.shape == (n, 3)
    assert attrs["intensity"].dtype == np.uint16
    assert np.array_equal(attrs["intensity"], recs[:, 12:14].copy().view("<u2").ravel())
    assert np.array_equal(attrs["return_number"], recs[:, 14] & 7)
    assert np.array_equal(attrs["number_of_returns"], (recs[:, 14] >> 3) & 7)
    assert np.array_equal(attrs["classification"], recs[:, 15] & 31)
    assert np.array_equal(attrs["gps_time"], recs[:, 20:28].copy().view("<f8").ravel())
    assert np.array_equal(attrs["blue"], recs[:, 32:34].copy().view("<u2").ravel())
    cmd("estimate", src, "-o", tmp_path / "o.las", "--quiet", "--neighbors", "knn:10")
    cmd("estimate", src, "-o", tmp_path / "o.csv", "--quiet", "--neighbors", "knn:10")
    pts2, _, _, attrs2 = jetfit.read(tmp_path / "o.las")
    ref = np.genfromtxt(tmp_path / "o.csv", delimiter=",", names=True)
    assert np.array_equal(pts2, pts)
    assert list(attrs2)[:len(attrs)] == list(attrs)
    for name in ref.dtype.names[3:]:
        assert np.array_equal(attrs2[name], ref[name], equal_nan=True), name
    assert attrs2["degree"].dtype == np.int32 and attrs2["nx"].dtype == np.float64


def test_read_las_scaled_extra_bytes(tmp_path, cmd):
    """An Extra Byte with the scale and offset options (LAS 1.4 R15 table
    24): read as raw * scale + offset, float64."""
    src = os.path.join(TOP, "tests", "data", "las", "simple.las")
    cmd("estimate", src, "-o", tmp_path / "o.las", "--quiet", "--neighbors", "knn:10")
    raw = bytearray(open(tmp_path / "o.las", "rb").read())
    _, _, _, plain = jetfit.read(tmp_path / "o.las")
    off, = struct.unpack_from("<I", raw, 96)
    d = raw.index(b"degree\0", 0, off) - 4  # its 192-byte description
    assert raw[d + 2] == 6 and plain["degree"].dtype == np.int32
    raw[d + 3] |= 8 | 16
    struct.pack_into("<d", raw, d + 112, 0.5)
    struct.pack_into("<d", raw, d + 136, 3.0)
    open(tmp_path / "s.las", "wb").write(raw)
    _, _, _, attrs = jetfit.read(tmp_path / "s.las")
    assert attrs["degree"].dtype == np.float64
    assert np.array_equal(attrs["degree"], plain["degree"] * 0.5 + 3.0)
    assert np.array_equal(attrs["nx"], plain["nx"])


def test_write_las_then_read_its_normals(tmp_path):
    """issue 31: write() sets the LAS frame itself (it failed naming an
    internal function), and the nx ny nz Extra Bytes read back as normals."""
    pts = np.random.default_rng(3).normal(size=(800, 3))
    pts /= np.linalg.norm(pts, axis=1)[:, None]
    r = jetfit.estimate(pts, neighbors="knn:12", orient="viewpoint:0,0,0")
    jetfit.write(str(tmp_path / "o.las"), r)
    p2, n2, _, attrs = jetfit.read(str(tmp_path / "o.las"))
    assert np.abs(p2 - pts).max() < 1e-6  # LAS stores integers at its scale
    assert n2 is not None and np.array_equal(n2, r.normal)  # doubles in Extra Bytes
    r2 = jetfit.estimate(p2, normals=n2, neighbors="knn:12", orient="input")
    assert ((r2.normal * p2).sum(axis=1) < 0).all()  # inwards, as the file's


def test_read_laz_equals_las_twin():
    """A LAZ file (issue 25) reads as its uncompressed LAS twin: the same
    points and attributes, bit for bit (laz-perf's test files)."""
    d = os.path.join(TOP, "tests", "data", "laz")
    for laz, las in (("point-color-time.las.laz", "point-color-time.las"),
                     ("1_4_w_evlr.laz", "1_4_w_evlr.las")):
        pz, _, _, az = jetfit.read(os.path.join(d, laz))
        ps, _, _, as_ = jetfit.read(os.path.join(d, las))
        assert np.array_equal(pz, ps)
        assert list(az) == list(as_)
        for name in as_:
            assert np.array_equal(az[name], as_[name]), name

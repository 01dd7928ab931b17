"""jetfit.estimate / estimate_mesh give the command's numbers bit for bit:
the command's output file and jetfit.write's file of the same cloud and
options are byte-identical, and as_structured() equals the file's table."""
import numpy as np
import pytest

import jetfit
from conftest import fib_sphere, save_xyz


def ply_table(path):
    """The vertex table of a binary little-endian PLY written by jetfit."""
    raw = open(path, "rb").read()
    end = raw.index(b"end_header\n") + len(b"end_header\n")
    fields, n = [], None
    for line in raw[:end].decode().splitlines():
        w = line.split()
        if w[:2] == ["element", "vertex"]:
            n = int(w[2])
        elif w[:2] == ["element", "face"]:
            break
        elif w and w[0] == "property" and n is not None:
            fields.append((w[2], {"double": "<f8", "int": "<i4"}[w[1]]))
    dt = np.dtype(fields)
    return np.frombuffer(raw, dt, count=n, offset=end)


def kwargs_to_flags(kw):
    flags = []
    for k, v in kw.items():
        if k == "robust_normals":
            flags.append("--robust-normals")
            continue
        if isinstance(v, (list, tuple)):
            v = ",".join(map(str, v))
        flags += ["--" + k.replace("_", "-"), str(v)]
    return flags


def same_as_command(cmd, tmp_path, infile, kw, mesh=False):
    out_cmd = tmp_path / "cmd.ply"
    out_py = tmp_path / "py.ply"
    cmd("estimate", infile, "-o", out_cmd, "--quiet", *kwargs_to_flags(kw))
    pts, nrm, faces, _ = jetfit.read(str(infile))
    if mesh:
        r = jetfit.estimate_mesh(pts, faces, normals=nrm, **kw)
    else:
        r = jetfit.estimate(pts, normals=nrm, **kw)
    jetfit.write(str(out_py), r)
    a, b = out_cmd.read_bytes(), out_py.read_bytes()
    assert a == b, f"files differ ({len(a)} vs {len(b)} bytes)"
    table = ply_table(out_cmd)
    s = r.as_structured()
    assert s.dtype.names == table.dtype.names
    assert s.tobytes() == table.tobytes()
    return r


@pytest.fixture(scope="module")
def cloud(tmp_path_factory):
    """2000 noisy samples of the paper's surface, with a NaN row."""
    d = tmp_path_factory.mktemp("cloud")
    f = d / "exp.xyz"
    import subprocess
    from conftest import JETFIT_BIN
    subprocess.run([JETFIT_BIN, "generate", "exp", "-o", str(f), "--n", "2000",
                    "--noise", "0.002", "--seed", "7"], check=True, capture_output=True)
    pts = np.loadtxt(f)
    pts[123] = np.nan
    return save_xyz(d / "exp_nan.xyz", pts)


CLOUD_CASES = [
    {},
    {"neighbors": "knn:16"},
    {"neighbors": "radius:0.08"},
    {"neighbors": "knn:24,radius:0.06"},
    {"neighbors": "natural"},
    {"neighbors": "natural:20", "normal": "mincirc"},
    {"neighbors": "natural", "normal": "pca"},
    {"degree": 4, "neighbors": "knn:40"},
    {"degree": 3, "monge_degree": 3, "fit": "interp"},
    {"frame": "axis", "max_cond": 50.5},
    {"robust": "huber", "neighbors": "knn:24"},
    {"robust": "tukey", "neighbors": "knn:24"},
    {"scales": [8, 16, 32]},
    {"degree_select": 1, "degree": 3},
    {"dist_weight": 0.4},
    {"robust_normals": True},
    {"orient": "mst:6"},
    {"orient": "viewpoint:0,0,5"},
]


@pytest.mark.parametrize("kw", CLOUD_CASES, ids=lambda kw: ",".join(f"{k}={v}" for k, v in kw.items()) or "defaults")
def test_cloud_equals_command(cmd, tmp_path, cloud, kw):
    r = same_as_command(cmd, tmp_path, cloud, kw)
    assert r.status[123] == jetfit.STATUS["nonfinite"]
    assert np.isnan(r.k1[123]) and np.isnan(r.normal[123]).all()


def test_input_normals_orient_and_natural(cmd, tmp_path):
    """Normals given: oriented like them by default (the command's rule),
    and natural neighbourhoods can take their tangent planes from them."""
    p = fib_sphere(1500, 2.0, (1, 2, 3))
    nrm = (p - (1, 2, 3)) / 2.0
    f = save_xyz(tmp_path / "s.xyz", p, nrm)
    r = same_as_command(cmd, tmp_path, f, {"neighbors": "knn:12"})
    assert (np.einsum("ij,ij->i", r.normal, nrm) > 0.99).all()
    assert np.allclose(r.k1, -0.5, atol=0.02)
    same_as_command(cmd, tmp_path, f, {"neighbors": "natural", "normal": "input"})


@pytest.mark.parametrize("kw", [{}, {"rings": 12}, {"degree": 4}, {"neighbors": "knn:10"}],
                         ids=["rings", "rings:12", "rings-degree4", "knn-on-mesh"])
def test_mesh_equals_command(cmd, tmp_path, kw):
    f = tmp_path / "m.off"
    cmd("generate", "exp", "-o", f, "--n", "900", "--mesh", "--seed", "3")
    kw = dict(kw)
    if "rings" in kw:
        kw = {"neighbors": f"rings:{kw.pop('rings')}"}
    elif "neighbors" not in kw:
        kw["neighbors"] = "rings"
    same_as_command(cmd, tmp_path, f, kw, mesh=True)


def test_mesh_rings_keyword(tmp_path, cmd):
    f = tmp_path / "m.off"
    cmd("generate", "sphere", "-o", f, "--n", "600", "--mesh")
    v, _, faces, _ = jetfit.read(str(f))
    assert faces.shape[1] == 3 and faces.dtype == np.int32
    a = jetfit.estimate_mesh(v, faces, 12)
    b = jetfit.estimate_mesh(v, faces, neighbors="rings:12")
    assert np.array_equal(a.as_structured(), b.as_structured())
    # polygons as lists give the same mesh
    c = jetfit.estimate_mesh(v, [list(t) for t in faces])
    d = jetfit.estimate_mesh(v, faces)
    assert c.as_structured().tobytes() == d.as_structured().tobytes()


def test_thread_count_identity():
    p = fib_sphere(20000) + np.random.default_rng(1).normal(0, 1e-3, (20000, 3))
    rs = [jetfit.estimate(p, neighbors="knn:20", degree=3, threads=t) for t in (1, 2, 3)]
    for r in rs[1:]:
        assert r.as_structured().tobytes() == rs[0].as_structured().tobytes()

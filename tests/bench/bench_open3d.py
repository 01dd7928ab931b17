#!/usr/bin/env python3
"""bench_open3d.py -- `jetfit estimate` end to end beside Open3D's normals
alone, on the same text file, in the same run (docs/benchmarks.md "Open3D,
side by side"; issue 15.4).

    /usr/bin/python3 tests/bench/bench_open3d.py [--n N] [--reps R]
        [--threads T] [--jetfit build/jetfit]

(Debian's python3-open3d installs for /usr/bin/python3.)  Input: N points
(default 10^6) of the paper's §6.1 surface in random order, `jetfit
generate exp --seed 2003`, as .xyz text (%.17g) in a temporary folder.
Contenders, R times (default 3) in turn, T threads (default 2):
  - `jetfit estimate IN.xyz -o OUT.ply --neighbors knn:16 --degree 2
    --threads T --quiet`: the whole command (start, read the text, k-d
    tree, jets, normals, curvatures and principal directions, binary PLY
    written), wall time of the process;
  - Open3D: a fresh process (OMP_NUM_THREADS = T before the import) reads
    the same file with open3d.io.read_point_cloud (not timed), then
    PointCloud.estimate_normals(KDTreeSearchParamKNN(16)) is timed: its
    k-d tree and PCA normals, nothing else (compute only).
Printed: each rep's wall and CPU times (CPU: every thread's, from
wait4 for the command and process_time around the call for Open3D) and
ratios (Open3D's time / jetfit's), the medians, the peak RSS of each
process, and the load average before and after (on a loaded machine,
read the CPU ratio).  A ratio above 1: jetfit's whole run took less time than
Open3D's normals alone.
"""
import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time


def child_open3d(path, threads):
    """In a fresh process: prints the seconds estimate_normals took."""
    os.environ["OMP_NUM_THREADS"] = str(threads)  # before Open3D starts OpenMP
    import open3d as o3d
    pcd = o3d.io.read_point_cloud(path, format="xyz")
    n = len(pcd.points)
    t, c = time.perf_counter(), time.process_time()
    pcd.estimate_normals(search_param=o3d.geometry.KDTreeSearchParamKNN(knn=16))
    dt, dc = time.perf_counter() - t, time.process_time() - c
    assert len(pcd.normals) == n
    print(dt, n, dc)


def wait_child(argv, **kw):
    """Runs argv; returns (its wall seconds, CPU seconds of all its
    threads, peak RSS in MB, stdout): wait4 gives the child's own rusage
    (a load on the machine stretches wall time, CPU time much less)."""
    t = time.perf_counter()
    p = subprocess.Popen(argv, **kw)
    out = p.stdout.read() if p.stdout else ""
    _, status, ru = os.wait4(p.pid, 0)
    dt = time.perf_counter() - t
    p.returncode = os.waitstatus_to_exitcode(status)
    if p.returncode != 0:
        raise RuntimeError("%s failed (%d)" % (argv[0], p.returncode))
    return dt, ru.ru_utime + ru.ru_stime, ru.ru_maxrss / 1024.0, out


def run_open3d(path, threads, n):
    """(wall, CPU) of estimate_normals alone, and the process's peak RSS
    (Python, Open3D and the cloud it read included)."""
    _, _, peak, out = wait_child([sys.executable, __file__, "--child", "--threads",
                                  str(threads), path], stdout=subprocess.PIPE, text=True)
    t, m, c = out.split()
    if int(m) != n:
        raise RuntimeError("open3d read %s points, not %d" % (m, n))
    return float(t), float(c), peak


def run_jetfit(jetfit, path, out, threads):
    """(wall, CPU, peak RSS) of the whole command."""
    if os.path.exists(out):
        os.remove(out)  # no deletion of an old output charged to this run
    t, c, peak, _ = wait_child([jetfit, "estimate", path, "-o", out, "--neighbors", "knn:16",
                                "--degree", "2", "--threads", str(threads), "--quiet"])
    return t, c, peak


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=1000000)
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    top = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
    ap.add_argument("--jetfit", default=os.path.join(top, "build", "jetfit"))
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("path", nargs="?", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child:
        return child_open3d(a.path, a.threads)
    try:
        import open3d  # noqa: F401
    except ImportError:
        print("bench_open3d: open3d is not installed for %s (Debian: python3-open3d, "
              "run with /usr/bin/python3)" % sys.executable)
        return 1

    tmp = tempfile.mkdtemp(prefix="bench_open3d.")
    path = os.path.join(tmp, "exp.xyz")
    out = os.path.join(tmp, "out.ply")
    subprocess.run([a.jetfit, "generate", "exp", "-o", path, "--n", str(a.n), "--seed", "2003"],
                   check=True, capture_output=True)
    with open("/proc/loadavg") as f:
        load = f.read().split()[:3]
    print("bench_open3d: %d points (§6.1 surface, random order, .xyz text %%.17g), "
          "%d threads, load average %s" % (a.n, a.threads, " ".join(load)))
    print("| rep | jetfit estimate, whole command: wall / CPU | Open3D estimate_normals "
          "alone: wall / CPU | Open3D / jetfit: wall / CPU |")
    print("|---|---|---|---|")
    tj, to, cj, co, pj, po = [], [], [], [], [], []
    for r in range(a.reps):
        t, c, p = run_jetfit(a.jetfit, path, out, a.threads)
        tj.append(t), cj.append(c), pj.append(p)
        t, c, p = run_open3d(path, a.threads, a.n)
        to.append(t), co.append(c), po.append(p)
        print("| %d | %.3f / %.3f s | %.3f / %.3f s | %.2fx / %.2fx |"
              % (r + 1, tj[-1], cj[-1], to[-1], co[-1], to[-1] / tj[-1], co[-1] / cj[-1]))
        sys.stdout.flush()
    mj, mo = statistics.median(tj), statistics.median(to)
    mcj, mco = statistics.median(cj), statistics.median(co)
    print("| median | %.3f / %.3f s (%.0f points/s) | %.3f / %.3f s (%.0f points/s) | "
          "%.2fx / %.2fx |" % (mj, mcj, a.n / mj, mo, mco, a.n / mo, mo / mj, mco / mcj))
    print("peak RSS: jetfit (whole process) %.0f MB, %.0f B/point; Open3D's process (Python, "
          "the cloud read, the normals) %.0f MB" % (max(pj), max(pj) * 1048576 / a.n, max(po)))
    with open("/proc/loadavg") as f:
        print("load average after: %s" % " ".join(f.read().split()[:3]))
    for p in (path, out):
        if os.path.exists(p):
            os.remove(p)
    os.rmdir(tmp)
    return 0


if __name__ == "__main__":
    sys.exit(main())

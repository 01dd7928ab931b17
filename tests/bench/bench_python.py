#!/usr/bin/env python3
"""bench_python.py -- the Python module's speed and memory beside its peers,
in the same run (docs/benchmarks.md "Python module").

    PYTHONPATH=build/python python3 tests/bench/bench_python.py [--n N]
        [--reps R] [--threads T] [--jetfit build/jetfit]

Input: N points (default 10^6) of the paper's §6.1 surface in random order
(`jetfit generate exp`, binary PLY in a temporary folder).  Contenders,
with knn:16 and T threads (default 2), R times (default 3) in turn, each
run in a fresh process (this script with --child; no fork after OpenMP
started) that reads the file with jetfit.read, so every Python contender
works on the same array, and whose peak memory is its own:
  - jetfit.estimate(pts, neighbors="knn:16", threads=T): normals,
    curvatures, principal directions (the whole call: options, the
    library's estimate, the Result's arrays);
  - the command's in-memory part: `jetfit estimate FILE -o OUT --neighbors
    knn:16 --threads T`, its jf_estimate time taken from the tree and fit
    times of its summary's `phases:` line; its whole wall time
    (read, estimate, write) and peak RSS are printed beside;
  - Open3D's PointCloud.estimate_normals(KDTreeSearchParamKNN(16)) (normals
    only; the Vector3dVector copy of the array is not timed), OpenMP
    threads set to T (OMP_NUM_THREADS); skipped if open3d is missing.
Printed: median wall time, points/s, Open3D's time / the contender's, and
the peak RSS the contender added to its process (VmHWM after the call -
VmRSS before it, the peak reset by /proc/self/clear_refs)
per point.
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time


def status_kib(field):
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(field + ":"):
                return int(line.split()[1])
    raise RuntimeError(field)


def start_peak():
    """Resets the peak RSS (Linux: clear_refs 5) and returns the current
    RSS in KiB, so peak_added() is what the timed call added."""
    with open("/proc/self/clear_refs", "w") as f:
        f.write("5")
    return status_kib("VmRSS")


def peak_added(before):
    return status_kib("VmHWM") - before


def child(kind, path, threads):
    """One contender in this (fresh) process; prints 'seconds added_kib'."""
    os.environ["OMP_NUM_THREADS"] = str(threads)  # Open3D's OpenMP, before import
    import jetfit
    pts, _, _, _ = jetfit.read(path)
    if kind == "open3d":
        import open3d as o3d
        pcd = o3d.geometry.PointCloud()
        pcd.points = o3d.utility.Vector3dVector(pts)
        before = start_peak()
        t = time.perf_counter()
        pcd.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(16))
        dt = time.perf_counter() - t
        assert len(pcd.normals) == len(pts)
    else:
        before = start_peak()
        t = time.perf_counter()
        r = jetfit.estimate(pts, neighbors="knn:16", threads=threads)
        dt = time.perf_counter() - t
        assert (r.status == 0).mean() > 0.99
    print(dt, peak_added(before))


def run_child(kind, path, threads):
    p = subprocess.run([sys.executable, __file__, "--child", kind, "--threads", str(threads),
                        path], capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError("%s: %s" % (kind, p.stderr[-500:]))
    t, kib = p.stdout.split()
    return float(t), float(kib)


def run_command(jetfit_bin, path, out, threads, n):
    """The command: (jf_estimate seconds, whole wall seconds, its peak RSS
    in KiB).  The jf_estimate part is the tree and fit phases of the
    summary's `phases:` line (read and write left out)."""
    t0 = time.perf_counter()
    p = subprocess.Popen([jetfit_bin, "estimate", path, "-o", out, "--neighbors", "knn:16",
                          "--threads", str(threads)], stdout=subprocess.DEVNULL,
                         stderr=subprocess.PIPE)
    text = p.stderr.read()
    _, status, ru = os.wait4(p.pid, 0)
    p.returncode = os.waitstatus_to_exitcode(status)
    wall = time.perf_counter() - t0
    m = re.search(rb"phases: .*tree ([0-9.]+) s, fit ([0-9.]+) s", text)
    if p.returncode != 0 or not m:
        raise RuntimeError("jetfit estimate failed: %r" % text[-300:])
    return float(m.group(1)) + float(m.group(2)), wall, ru.ru_maxrss


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=1000000)
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    top = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
    ap.add_argument("--jetfit", default=os.path.join(top, "build", "jetfit"))
    ap.add_argument("--child", choices=["jetfit", "open3d"], help=argparse.SUPPRESS)
    ap.add_argument("path", nargs="?", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child:
        return child(a.child, a.path, a.threads)
    try:
        import open3d  # noqa: F401
        have_o3d = True
    except ImportError:
        have_o3d = False

    tmp = tempfile.mkdtemp(prefix="bench_python.")
    path = os.path.join(tmp, "exp.ply")
    out = os.path.join(tmp, "out.ply")
    subprocess.run([a.jetfit, "generate", "exp", "-o", path, "--n", str(a.n), "--seed", "2003"],
                   check=True, capture_output=True)
    n = a.n
    PY, EST, CMD, O3D = ("jetfit.estimate (Python)", "jetfit estimate: jf_estimate part",
                         "jetfit estimate: whole command", "Open3D estimate_normals")
    runs = {PY: [], EST: [], CMD: []}
    peaks = {PY: [], CMD: []}
    if have_o3d:
        runs[O3D], peaks[O3D] = [], []
    for _ in range(a.reps):
        t, kib = run_child("jetfit", path, a.threads)
        runs[PY].append(t)
        peaks[PY].append(kib)
        t, wall, kib = run_command(a.jetfit, path, out, a.threads, n)
        runs[EST].append(t)
        runs[CMD].append(wall)
        peaks[CMD].append(kib)
        os.remove(out)
        if have_o3d:
            t, kib = run_child("open3d", path, a.threads)
            runs[O3D].append(t)
            peaks[O3D].append(kib)
    os.remove(path)
    os.rmdir(tmp)
    ref = statistics.median(runs[O3D]) if have_o3d else None
    print("bench_python: %d points (§6.1 surface, random order), knn:16, %d threads, "
          "median of %d" % (n, a.threads, a.reps))
    print("| contender | wall | points/s | Open3D's time / this | peak memory |")
    print("|---|---|---|---|---|")
    for k, v in runs.items():
        t = statistics.median(v)
        pk = ""
        if k in peaks:
            pk = "%.0f B/pt %s" % (statistics.median(peaks[k]) * 1024 / n,
                                   "(whole process)" if k == CMD else "(added)")
        print("| %s | %.3f s | %.0f | %s | %s |" % (k, t, n / t,
                                                   ("%.2fx" % (ref / t)) if ref else "-", pk))


if __name__ == "__main__":
    sys.exit(main())

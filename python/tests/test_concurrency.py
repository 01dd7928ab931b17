"""Concurrent calls from Python threads (issue 32): three threads per
round start estimates of the same array at once, each with its own OpenMP
team; the interpreter must survive and every result equal a single call's
bits.  On LLVM's libomp (the module's runtime until issue 32) 140,000
points (above 2 x 65,536, where the k-d tree builds with OpenMP tasks)
ended in SIGSEGV, SIGBUS or "OMP: Error #13: Assertion failure at
kmp_alloc" in 4 runs of 4; knn:6 at degree 1 keeps the fits cheap.  Each case runs in a child interpreter, so a crash fails
the test instead of killing pytest.  Also: an empty or huge
OMP_NUM_THREADS (issue 31, issue 33 item 5) runs with a sane count."""
import os
import subprocess
import sys

import pytest

import jetfit

CHILD = r"""
import sys, threading, numpy as np, jetfit
n, nthreads, rounds, k, deg = map(int, sys.argv[1:6])
A = np.random.default_rng(7).random((n, 3))
kw = dict(neighbors=f"knn:{k}", degree=deg)
want = jetfit.estimate(A, threads=1, **kw).as_structured().tobytes()
bad = []
def work():
    got = jetfit.estimate(A, threads=2, **kw).as_structured().tobytes()
    if got != want:
        bad.append(1)
for r in range(rounds):
    ts = [threading.Thread(target=work) for _ in range(nthreads)]
    for t in ts: t.start()
    for t in ts: t.join()
print("differ" if bad else "same", len(bad))
"""


def child(args, env=None, timeout=300):
    e = dict(os.environ)
    e.update(env or {})
    return subprocess.run([sys.executable, "-c", CHILD, *map(str, args)], capture_output=True,
                          text=True, env=e, timeout=timeout)


@pytest.mark.parametrize("n,nthreads,rounds,k,deg", [(140000, 3, 6, 6, 1), (20000, 4, 3, 16, 2)])
def test_threads_rounds_sizes(n, nthreads, rounds, k, deg):
    p = child([n, nthreads, rounds, k, deg])
    assert p.returncode == 0, f"exit {p.returncode}: {p.stderr[-500:]}"
    assert p.stdout.split()[0] == "same", p.stdout


def test_empty_omp_num_threads():
    p = child([3000, 2, 1, 12, 2], env={"OMP_NUM_THREADS": ""})
    assert p.returncode == 0, f"exit {p.returncode}: {p.stderr[-500:]}"
    assert p.stdout.split()[0] == "same"


def test_huge_omp_num_threads_is_clamped():
    """100,000 crashed libgomp (issue 33 item 5): the default is clamped
    to the processors; an explicit threads= is obeyed."""
    code = ("import numpy as np, jetfit; A = np.random.default_rng(1).random((300, 3));"
            "print(len(jetfit.estimate(A, neighbors='knn:12')))")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       env=dict(os.environ, OMP_NUM_THREADS="100000"), timeout=300)
    assert p.returncode == 0, f"exit {p.returncode}: {p.stderr[-500:]}"
    assert p.stdout.split() == ["300"]


def test_one_runtime():
    assert jetfit.OPENMP_RUNTIME == "libgomp"

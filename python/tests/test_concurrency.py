"""Concurrent calls from Python threads (issue 32): two to four threads
per round start estimates of the same array at once, each with its own
OpenMP team; the interpreter must survive and every result equal a single
call's bits.  On LLVM's libomp (the module's runtime until issue 32) the
first rounds ended in a bus error or "OMP: Error #13: Assertion failure at
kmp_alloc.cpp".  Each case runs in a child interpreter, so a crash fails
the test instead of killing pytest.  Also: an empty or huge
OMP_NUM_THREADS (issue 31, issue 33 item 5) runs with a sane count."""
import os
import subprocess
import sys

import pytest

import jetfit

CHILD = r"""
import sys, threading, numpy as np, jetfit
n, nthreads, rounds, k = map(int, sys.argv[1:5])
A = np.random.default_rng(7).random((n, 3))
want = jetfit.estimate(A, neighbors=f"knn:{k}", threads=1).as_structured().tobytes()
bad = []
def work():
    got = jetfit.estimate(A, neighbors=f"knn:{k}", threads=2).as_structured().tobytes()
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


@pytest.mark.parametrize("n,nthreads,rounds", [(20000, 2, 6), (60000, 2, 3), (5000, 4, 8)])
def test_threads_rounds_sizes(n, nthreads, rounds):
    p = child([n, nthreads, rounds, 16])
    assert p.returncode == 0, f"exit {p.returncode}: {p.stderr[-500:]}"
    assert p.stdout.split()[0] == "same", p.stdout


def test_empty_omp_num_threads():
    p = child([3000, 2, 1, 12], env={"OMP_NUM_THREADS": ""})
    assert p.returncode == 0, f"exit {p.returncode}: {p.stderr[-500:]}"
    assert p.stdout.split()[0] == "same"


def test_huge_omp_num_threads_is_clamped():
    """100,000 crashed libgomp (issue 33 item 5): the default is clamped
    to the processors; an explicit threads= is obeyed."""
    code = ("import numpy as np, jetfit; A = np.random.default_rng(1).random((3000, 3));"
            "print(len(jetfit.estimate(A, neighbors='knn:12')))")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       env=dict(os.environ, OMP_NUM_THREADS="100000"), timeout=300)
    assert p.returncode == 0, f"exit {p.returncode}: {p.stderr[-500:]}"
    assert p.stdout.split() == ["3000"]


def test_one_runtime():
    assert jetfit.OPENMP_RUNTIME == "libgomp"

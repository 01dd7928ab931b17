"""jetfit: normals, principal curvatures and directions, and Monge
coefficients of point clouds and meshes by osculating jets (Cazals & Pouget,
SGP 2003), on numpy arrays.

The numbers are the ``jetfit estimate`` command's, bit for bit: the module
calls the same library (libjetfit) with options parsed by the command's own
parser.  docs/python.md is the manual; in short::

    import numpy as np, jetfit
    pts = np.random.rand(1000, 3)
    r = jetfit.estimate(pts, neighbors="knn:16", degree=2)
    r.normal, r.k1, r.k2, r.d1, r.d2      # (N,3), (N,), (N,), (N,3), (N,3)
    table = r.as_structured()             # the output file's columns

Functions: estimate, estimate_mesh, fit_jet, read, write.  Types: Result,
Jet.  STATUS maps the per-point flag names to their bits; FileError (an
OSError) carries the command's "FILE:LINE: reason".  The GIL is released
while estimating; Ctrl-C raises KeyboardInterrupt within a fraction of a
second.
"""
from ._jetfit import (OPENMP_RUNTIME, STATUS, FileError, Jet, Result,
                      __version__, estimate, estimate_mesh, fit_jet, read,
                      write)

__all__ = ["estimate", "estimate_mesh", "fit_jet", "read", "write", "Result",
           "Jet", "STATUS", "FileError", "__version__", "OPENMP_RUNTIME",
           "status_names"]


def status_names(status):
    """The '|'-joined flag names of one status value ("ok" for 0), as the
    command's summary names them."""
    status = int(status)
    if status == 0:
        return "ok"
    return "|".join(name for name, bit in STATUS.items() if status & bit)

/* module.c -- the `jetfit._jetfit` extension: its function table, the
 * STATUS flag names, FileError and the version.  jetfit/__init__.py
 * re-exports everything (docs/python.md is the manual). */
#define JF_PY_MODULE_C
#include "jfpy.h"

PyObject *jf_py_FileError;

PyObject *jf_py_status_error(jf_status st, const char *msg)
{
    if (!msg || !msg[0]) msg = jf_strerror(st);
    switch (st) {
    case JF_ERR_NOMEM: PyErr_SetString(PyExc_MemoryError, msg); break;
    case JF_ERR_CANCELLED:
        /* the cancel hook saw a signal whose handler raised (Ctrl-C:
         * KeyboardInterrupt); keep that exception */
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_KeyboardInterrupt, msg);
        break;
    case JF_ERR_INVALID:
    case JF_ERR_FORMAT:
    case JF_ERR_TOO_LARGE: PyErr_SetString(PyExc_ValueError, msg); break;
    default: PyErr_SetString(PyExc_RuntimeError, msg);
    }
    return NULL;
}

/* STATUS: {name: bit} for every per-point flag, from the library's own
 * names (jf_point_status_str), so it cannot drift from the command's. */
static PyObject *status_dict(void)
{
    PyObject *d = PyDict_New();
    if (!d) return NULL;
    for (unsigned b = 0; b < 32; b++) {
        char name[64];
        jf_point_status_str(1u << b, name, sizeof name);
        if (!name[0]) break; /* past the last named flag */
        PyObject *v = PyLong_FromUnsignedLong(1ul << b);
        if (!v || PyDict_SetItemString(d, name, v) < 0) {
            Py_XDECREF(v);
            Py_DECREF(d);
            return NULL;
        }
        Py_DECREF(v);
    }
    return d;
}

/* The keywords of estimate and estimate_mesh (docs/python.md has the
 * long form; the defaults are the library's, jf_estimate_opts_init). */
#define JF_PY_EST_PARAMS \
"  neighbors : str, default 'knn:32': knn:K | radius:R | knn:K,radius:R |\n" \
"      rings[:N] (meshes) | natural[:N] (K and N count the point)\n" \
"  degree : int 1..9, default 2: the jet's degree\n" \
"  monge_degree : int 2..4, default min(degree, 4): 3 adds b0..b3, 4 c0..c4\n" \
"  fit : 'approx' (default) | 'interp'\n" \
"  frame : 'pca' (default) | 'axis'\n" \
"  max_cond : float >= 1, default 1000: lower the degree while cond > max_cond\n" \
"  orient : None (default: 'scanner' with scanners=, else 'input' with\n" \
"      normals=, else 'none') | 'none' | 'input' | 'viewpoint:X,Y,Z' |\n" \
"      'scanner' | 'mst' | 'mst:K'\n" \
"  normals : (N, 3) array or None: the points' own normals (orient='input',\n" \
"      normal='input')\n" \
"  normal : natural only: None (auto: jet on a noisy cloud, else pca) |\n" \
"      'auto' | 'poles' | 'mincirc' | 'pca' | 'jet' | 'input'\n" \
"  robust : None (none) | 'none' | 'huber' | 'tukey'\n" \
"  scales : sequence of up to 8 ascending ints >= 3: per-point scale choice\n" \
"  degree_select : int 1..degree or None: per-point degree choice\n" \
"  dist_weight : float > 0 or None: Gaussian weights, sigma = C x farthest\n" \
"  robust_normals : bool, default False: degree_select=1, dist_weight=0.55\n" \
"  threads : int 1..4096 or None (all cores)\n" \
"  scanners : (N, 3) array or None: each point's scanner position\n" \
"      (orient='scanner')\n"

/* Docstrings: the first lines are the signature (CPython's __text_signature__
 * convention, so help() and inspect.signature show it); docs/python.md is
 * the manual. */
PyDoc_STRVAR(estimate_doc,
"estimate(points, *, neighbors='knn:32', degree=2, monge_degree=None, fit='approx', "
"frame='pca', max_cond=1000, orient=None, normals=None, normal=None, robust=None, "
"scales=None, degree_select=None, dist_weight=None, robust_normals=False, threads=None, "
"scanners=None)\n"
"--\n\n"
"Normals, principal curvatures and directions and Monge coefficients of every\n"
"point of an (N, 3) array, as `jetfit estimate` computes them (same options,\n"
"same defaults, same bits).  neighbors='auto' chooses K and the degree per\n"
"point (Result.sigma: the noise it saw).  Returns a Result.  A C-contiguous float64 array\n"
"is not copied.  Bad option values raise ValueError naming the keyword\n"
"('degree=12: expected an integer 1..9').  The GIL is released; Ctrl-C\n"
"raises KeyboardInterrupt.\n"
"\n"
"Parameters (every one after points is keyword-only):\n"
"  points : (N, 3) array of x y z (any real dtype; NaN rows: status nonfinite)\n"
JF_PY_EST_PARAMS);

PyDoc_STRVAR(estimate_mesh_doc,
"estimate_mesh(vertices, faces, rings=None, *, neighbors=None, degree=2, "
"monge_degree=None, fit='approx', frame='pca', max_cond=1000, orient=None, "
"normals=None, normal=None, robust=None, scales=None, degree_select=None, "
"dist_weight=None, robust_normals=False, threads=None, scanners=None)\n"
"--\n\n"
"estimate() on a mesh: faces is an (M, k) integer array or a sequence of\n"
"polygons; rings=None is the command's `rings`, rings=N is `rings:N`.\n"
"\n"
"Parameters:\n"
"  vertices : (N, 3) array of x y z\n"
"  faces : (M, k) integer array or a sequence of polygons (vertex indices)\n"
"  rings : None (the fewest whole rings holding enough points) or N\n"
JF_PY_EST_PARAMS);

PyDoc_STRVAR(read_doc,
"read(path, *, columns=None, bad_rows=None)\n--\n\n"
"columns: 3 or 6 0-based column numbers of x y z [nx ny nz] (text files);\n"
"bad_rows: 'error' (default) or 'skip' (a NaN row, status nonfinite).\n"
"Reads a cloud or mesh with the command's readers: (points (N, 3) float64,\n"
"normals or None, faces or None, attributes: a dict name -> (N,) array in\n"
"the input's type of every other per-point value (PLY properties, named CSV\n"
"columns, LAS dimensions and extra bytes; PTX: scan and scanner)).  Errors\n"
"raise jetfit.FileError (an OSError) with the command's 'FILE:LINE: reason'.");

PyDoc_STRVAR(write_doc,
"write(path, result, *, points=None, faces=None, ascii=False, threads=None)\n--\n\n"
"Writes the command's output file of a Result (.ply, .csv, .xyz, .txt, .las, .laz),\n"
"byte for byte; through a temporary renamed at the end.\n"
"\n"
"Parameters:\n"
"  path : str or path-like; the format from its extension\n"
"  result : a Result of estimate() or estimate_mesh()\n"
"  points : (N, 3) array, default the Result's own points\n"
"  faces : faces to keep in a PLY output, default the Result's\n"
"  ascii : bool, default False: ascii PLY\n"
"  threads : int or None: threads formatting text rows");

PyDoc_STRVAR(fit_jet_doc,
"fit_jet(neighbors, degree=2, *, monge_degree=None, fit='approx', frame='pca', "
"max_cond=1000, point=None, weights=None)\n--\n\n"
"One osculating jet on an (n, 3) neighbourhood at point (default: its first\n"
"row), optionally weighted.  Returns a jetfit.Jet.\n"
"\n"
"Parameters:\n"
"  neighbors : (n, 3) array, n >= (degree+1)(degree+2)/2\n"
"  degree : int 1..9, default 2\n"
"  monge_degree, fit, frame, max_cond : as in estimate()\n"
"  point : (3,) array or None: where the jet is taken (default neighbors[0])\n"
"  weights : (n,) array or None: a weight per neighbour");

static PyMethodDef methods[] = {
    {"estimate", (PyCFunction)(void (*)(void))jf_py_estimate, METH_VARARGS | METH_KEYWORDS,
     estimate_doc},
    {"estimate_mesh", (PyCFunction)(void (*)(void))jf_py_estimate_mesh,
     METH_VARARGS | METH_KEYWORDS, estimate_mesh_doc},
    {"read", (PyCFunction)(void (*)(void))jf_py_read, METH_VARARGS | METH_KEYWORDS, read_doc},
    {"write", (PyCFunction)(void (*)(void))jf_py_write, METH_VARARGS | METH_KEYWORDS, write_doc},
    {"fit_jet", (PyCFunction)(void (*)(void))jf_py_fit_jet, METH_VARARGS | METH_KEYWORDS,
     fit_jet_doc},
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef moddef = {PyModuleDef_HEAD_INIT, "_jetfit",
                                    "jetfit's C extension (use the jetfit package).", -1,
                                    methods, NULL, NULL, NULL, NULL};

/* numpy's own import_array() says only "numpy.core.multiarray failed to
 * import": say which interpreter and numpy the module was built for, and
 * keep numpy's reason (no numpy on this interpreter, or another ABI). */
static int numpy_or_explain(void)
{
    if (_import_array() >= 0) return 0;
    PyObject *t, *v, *tb;
    PyErr_Fetch(&t, &v, &tb);
    PyErr_NormalizeException(&t, &v, &tb);
    PyObject *sys_exe = PySys_GetObject("executable"); /* borrowed */
    PyErr_Format(PyExc_ImportError,
                 "jetfit cannot use numpy in this interpreter (%S, Python %s): %S.  The module "
                 "was built for %s with numpy %s (its C API): run that interpreter, or build "
                 "jetfit for this one (pip install --no-build-isolation . with its numpy, "
                 "docs/python.md)",
                 sys_exe ? sys_exe : Py_None, Py_GetVersion(), v ? v : Py_None, JF_PY_BUILT_FOR,
                 JF_PY_NUMPY_VERSION);
    Py_XDECREF(t);
    Py_XDECREF(v);
    Py_XDECREF(tb);
    return -1;
}

PyMODINIT_FUNC PyInit__jetfit(void)
{
    if (numpy_or_explain() < 0) return NULL;
    PyObject *m = PyModule_Create(&moddef);
    if (!m) return NULL;
    if (PyType_Ready(&jf_py_ResultType) < 0) goto fail;
    Py_INCREF(&jf_py_ResultType);
    if (PyModule_AddObject(m, "Result", (PyObject *)&jf_py_ResultType) < 0) {
        Py_DECREF(&jf_py_ResultType);
        goto fail;
    }
    if (jf_py_fitjet_init(m) < 0) goto fail;
    jf_py_FileError = PyErr_NewExceptionWithDoc(
        "jetfit.FileError",
        "A file could not be read or written; str() is the command's one line "
        "'FILE:LINE: reason'.",
        PyExc_OSError, NULL);
    if (!jf_py_FileError) goto fail;
    Py_INCREF(jf_py_FileError);
    if (PyModule_AddObject(m, "FileError", jf_py_FileError) < 0) {
        Py_DECREF(jf_py_FileError);
        goto fail;
    }
    PyObject *st = status_dict();
    if (!st || PyModule_AddObject(m, "STATUS", st) < 0) {
        Py_XDECREF(st);
        goto fail;
    }
    if (PyModule_AddStringConstant(m, "__version__", jf_version()) < 0) goto fail;
    /* which OpenMP runtime the module runs on (python/CMakeLists.txt) */
    if (PyModule_AddStringConstant(m, "OPENMP_RUNTIME", JF_PY_OPENMP) < 0) goto fail;
    return m;
fail:
    Py_DECREF(m);
    return NULL;
}

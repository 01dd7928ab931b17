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
"is not copied.  Bad option values raise ValueError with the command's words.\n"
"The GIL is released; Ctrl-C raises KeyboardInterrupt.");

PyDoc_STRVAR(estimate_mesh_doc,
"estimate_mesh(vertices, faces, rings=None, *, neighbors=None, degree=2, "
"monge_degree=None, fit='approx', frame='pca', max_cond=1000, orient=None, "
"normals=None, normal=None, robust=None, scales=None, degree_select=None, "
"dist_weight=None, robust_normals=False, threads=None, scanners=None)\n"
"--\n\n"
"estimate() on a mesh: faces is an (M, k) integer array or a sequence of\n"
"polygons; rings=None is the command's `rings`, rings=N is `rings:N`.");

PyDoc_STRVAR(read_doc,
"read(path, *, columns=None, bad_rows=None)\n--\n\n"
"Reads a cloud or mesh with the command's readers: (points (N, 3) float64,\n"
"normals or None, faces or None, attributes: a dict name -> (N,) array in\n"
"the input's type of every other per-point value (PLY properties, named CSV\n"
"columns, LAS dimensions and extra bytes; PTX: scan and scanner)).  Errors\n"
"raise jetfit.FileError (an OSError) with the command's 'FILE:LINE: reason'.");

PyDoc_STRVAR(write_doc,
"write(path, result, *, points=None, faces=None, ascii=False, threads=None)\n--\n\n"
"Writes the command's output file of a Result (.ply, .csv, .xyz, .txt), byte\n"
"for byte; through a temporary renamed at the end.");

PyDoc_STRVAR(fit_jet_doc,
"fit_jet(neighbors, degree=2, *, monge_degree=None, fit='approx', frame='pca', "
"max_cond=1000, point=None, weights=None)\n--\n\n"
"One osculating jet on an (n, 3) neighbourhood at point (default: its first\n"
"row), optionally weighted.  Returns a jetfit.Jet.");

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

PyMODINIT_FUNC PyInit__jetfit(void)
{
    import_array();
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

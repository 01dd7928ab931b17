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

static PyMethodDef methods[] = {
    {"estimate", (PyCFunction)(void (*)(void))jf_py_estimate, METH_VARARGS | METH_KEYWORDS,
     "estimate(points, neighbors='knn:32', ...) -> Result (see jetfit.estimate)"},
    {"estimate_mesh", (PyCFunction)(void (*)(void))jf_py_estimate_mesh,
     METH_VARARGS | METH_KEYWORDS, "estimate_mesh(vertices, faces, rings=None, ...) -> Result"},
    {"read", (PyCFunction)(void (*)(void))jf_py_read, METH_VARARGS | METH_KEYWORDS,
     "read(path, columns=None) -> (points, normals, faces, attributes)"},
    {"write", (PyCFunction)(void (*)(void))jf_py_write, METH_VARARGS | METH_KEYWORDS,
     "write(path, result, points=None, faces=None, ascii=False, threads=None)"},
    {"fit_jet", (PyCFunction)(void (*)(void))jf_py_fit_jet, METH_VARARGS | METH_KEYWORDS,
     "fit_jet(neighbors, degree=2, ...) -> Jet"},
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

/* fitjet.c -- jetfit.fit_jet(neighbors, degree=2, ...): one osculating jet
 * (jf_fit_point, or jf_fit_point_weighted with weights=) on an (n, 3)
 * neighbourhood, at `point` (default: its first row).  Returns a
 * jetfit.Jet, a named tuple of the command's columns for that point. */
#include <math.h>

#include "jfpy.h"

PyTypeObject *jf_py_JetType;

static PyStructSequence_Field jet_fields[] = {
    {"normal", "(3,) unit normal"},
    {"k1", "principal curvature, k1 >= k2"},
    {"k2", "principal curvature"},
    {"d1", "(3,) principal direction of k1"},
    {"d2", "(3,) principal direction of k2"},
    {"b", "(4,) Monge b0..b3, or None when monge_degree < 3"},
    {"c", "(5,) Monge c0..c4, or None when monge_degree < 4"},
    {"degree", "degree used"},
    {"neighbors", "points in the fit"},
    {"cond", "condition number of the fit"},
    {"residual", "RMS fit residual"},
    {"status", "flags (jetfit.STATUS; 0 = ok)"},
    {NULL, NULL}};

static PyStructSequence_Desc jet_desc = {
    "jetfit.Jet", "One osculating jet: the output columns of one point.", jet_fields, 12};

int jf_py_fitjet_init(PyObject *m)
{
    jf_py_JetType = PyStructSequence_NewType(&jet_desc);
    if (!jf_py_JetType) return -1;
    Py_INCREF(jf_py_JetType);
    if (PyModule_AddObject(m, "Jet", (PyObject *)jf_py_JetType) < 0) {
        Py_DECREF(jf_py_JetType);
        return -1;
    }
    return 0;
}

static PyObject *vec(const double *v, npy_intp n)
{
    PyArrayObject *a = jf_py_empty(1, n, 0, NPY_DOUBLE);
    if (a) memcpy(PyArray_DATA(a), v, (size_t)n * sizeof *v);
    return (PyObject *)a;
}

static PyObject *jet_from(const jf_result *r, int monge)
{
    PyObject *t = PyStructSequence_New(jf_py_JetType);
    if (!t) return NULL;
    PyObject *v[12] = {vec(r->normal, 3),
                       PyFloat_FromDouble(r->k1),
                       PyFloat_FromDouble(r->k2),
                       vec(r->d1, 3),
                       vec(r->d2, 3),
                       monge >= 3 ? vec(r->b, 4) : Py_NewRef(Py_None),
                       monge >= 4 ? vec(r->c, 5) : Py_NewRef(Py_None),
                       PyLong_FromLong(r->degree),
                       PyLong_FromLong(r->n_used),
                       PyFloat_FromDouble(r->cond),
                       PyFloat_FromDouble(r->residual),
                       PyLong_FromUnsignedLong(r->status)};
    int ok = 1;
    for (int j = 0; j < 12; j++) {
        if (!v[j]) ok = 0;
        else PyStructSequence_SET_ITEM(t, j, v[j]); /* steals */
    }
    if (!ok) Py_CLEAR(t); /* frees the items set */
    return t;
}

PyObject *jf_py_fit_jet(PyObject *self, PyObject *args, PyObject *kw)
{
    (void)self;
    static char *kwl[] = {"neighbors", "degree", "monge_degree", "fit", "frame",
                          "max_cond",  "point",  "weights",      NULL};
    PyObject *nbobj, *degree = NULL, *monge = NULL, *fit = NULL, *frame = NULL, *max_cond = NULL,
                     *point = NULL, *weights = NULL;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O|O$OOOOOO:fit_jet", kwl, &nbobj, &degree, &monge,
                                     &fit, &frame, &max_cond, &point, &weights))
        return NULL;
    jf_py_opts po;
    jf_py_opts_init(&po);
    if (jf_py_opt(&po, "degree", "degree", degree, JF_PY_INT) ||
        jf_py_opt(&po, "monge_degree", "monge_degree", monge, JF_PY_INT) ||
        jf_py_opt(&po, "fit", "fit", fit, JF_PY_STR) ||
        jf_py_opt(&po, "frame", "frame", frame, JF_PY_STR) ||
        jf_py_opt(&po, "max_cond", "max_cond", max_cond, JF_PY_FLOAT) ||
        jf_py_opts_finish(&po))
        return NULL;
    PyArrayObject *nb = jf_py_points(nbobj, "neighbors"), *pa = NULL, *wa = NULL;
    PyObject *ret = NULL;
    jf_fitter *f = NULL;
    if (!nb) return NULL;
    size_t n = (size_t)PyArray_DIM(nb, 0);
    const double *p = PyArray_DATA(nb);
    if (point && point != Py_None) {
        pa = (PyArrayObject *)PyArray_FromAny(point, PyArray_DescrFromType(NPY_DOUBLE), 1, 1,
                                              NPY_ARRAY_C_CONTIGUOUS | NPY_ARRAY_ALIGNED, NULL);
        if (!pa) goto out;
        if (PyArray_DIM(pa, 0) != 3) {
            PyErr_SetString(PyExc_ValueError, "point: expected 3 coordinates");
            goto out;
        }
        p = PyArray_DATA(pa);
    } else if (n == 0) {
        PyErr_SetString(PyExc_ValueError, "neighbors: empty, and no point= given");
        goto out;
    }
    if (weights && weights != Py_None) {
        wa = (PyArrayObject *)PyArray_FromAny(weights, PyArray_DescrFromType(NPY_DOUBLE), 1, 1,
                                              NPY_ARRAY_C_CONTIGUOUS | NPY_ARRAY_ALIGNED, NULL);
        if (!wa) goto out;
        if ((size_t)PyArray_DIM(wa, 0) != n) {
            PyErr_Format(PyExc_ValueError, "weights: %zd values for %zd neighbours",
                         (Py_ssize_t)PyArray_DIM(wa, 0), (Py_ssize_t)n);
            goto out;
        }
    }
    jf_params prm = po.o.params;
    if (n > prm.max_neighbors) prm.max_neighbors = n;
    jf_status st = jf_fitter_create(&prm, &f);
    jf_result r;
    if (st == JF_OK) {
        Py_BEGIN_ALLOW_THREADS
        st = wa ? jf_fit_point_weighted(f, p, PyArray_DATA(nb), PyArray_DATA(wa), n, &r)
                : jf_fit_point(f, p, PyArray_DATA(nb), n, &r);
        Py_END_ALLOW_THREADS
    }
    if (st != JF_OK) {
        jf_py_status_error(st, st == JF_ERR_INVALID && wa
                                   ? "weights: expected finite values >= 0"
                                   : NULL);
        goto out;
    }
    ret = jet_from(&r, prm.monge_degree);
out:
    jf_fitter_free(f);
    Py_XDECREF(nb);
    Py_XDECREF(pa);
    Py_XDECREF(wa);
    return ret;
}

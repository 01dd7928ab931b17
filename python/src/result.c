/* result.c -- jetfit.Result: one numpy array per output column group,
 * named as the command's columns (normal = nx ny nz, d1 = d1x d1y d1z,
 * b = b0..b3, c = c0..c4, neighbors = the fit's n_used), element i for
 * input point i; as_structured() gives the output file's table. */
#include <math.h>
#include <stddef.h>

#include "jfpy.h"
#include <structmember.h>

typedef struct {
    PyObject_HEAD
    PyObject *normal, *k1, *k2, *d1, *d2, *b, *c;
    PyObject *degree, *neighbors, *status, *cond, *residual;
    PyObject *sigma; /* neighbors="auto": the noise it saw; NaN otherwise */
    PyObject *points, *faces; /* as given (points converted on demand) */
    PyObject *auto_step0; /* neighbors="auto": step 0's decision (str); None otherwise */
    Py_ssize_t n;
    int monge;
    int with_sigma; /* neighbors="auto": sigma is an output column */
} Result;

#define ARR(o) ((PyArrayObject *)(o))

static void result_dealloc(Result *r)
{
    Py_XDECREF(r->normal);
    Py_XDECREF(r->k1);
    Py_XDECREF(r->k2);
    Py_XDECREF(r->d1);
    Py_XDECREF(r->d2);
    Py_XDECREF(r->b);
    Py_XDECREF(r->c);
    Py_XDECREF(r->degree);
    Py_XDECREF(r->neighbors);
    Py_XDECREF(r->status);
    Py_XDECREF(r->cond);
    Py_XDECREF(r->residual);
    Py_XDECREF(r->sigma);
    Py_XDECREF(r->points);
    Py_XDECREF(r->faces);
    Py_XDECREF(r->auto_step0);
    Py_TYPE(r)->tp_free((PyObject *)r);
}

PyObject *jf_py_result_new(size_t n, int monge, int sigma, PyObject *points, PyObject *faces)
{
    Result *r = PyObject_New(Result, &jf_py_ResultType);
    if (!r) return NULL;
    npy_intp N = (npy_intp)n;
    r->n = (Py_ssize_t)n;
    r->monge = monge;
    r->with_sigma = sigma != 0;
    r->normal = (PyObject *)jf_py_empty(2, N, 3, NPY_DOUBLE);
    r->k1 = (PyObject *)jf_py_empty(1, N, 0, NPY_DOUBLE);
    r->k2 = (PyObject *)jf_py_empty(1, N, 0, NPY_DOUBLE);
    r->d1 = (PyObject *)jf_py_empty(2, N, 3, NPY_DOUBLE);
    r->d2 = (PyObject *)jf_py_empty(2, N, 3, NPY_DOUBLE);
    r->b = monge >= 3 ? (PyObject *)jf_py_empty(2, N, 4, NPY_DOUBLE) : Py_NewRef(Py_None);
    r->c = monge >= 4 ? (PyObject *)jf_py_empty(2, N, 5, NPY_DOUBLE) : Py_NewRef(Py_None);
    r->degree = (PyObject *)jf_py_empty(1, N, 0, NPY_INT32);
    r->neighbors = (PyObject *)jf_py_empty(1, N, 0, NPY_INT32);
    r->status = (PyObject *)jf_py_empty(1, N, 0, NPY_INT32);
    r->cond = (PyObject *)jf_py_empty(1, N, 0, NPY_DOUBLE);
    r->residual = (PyObject *)jf_py_empty(1, N, 0, NPY_DOUBLE);
    r->sigma = (PyObject *)jf_py_empty(1, N, 0, NPY_DOUBLE);
    r->points = Py_XNewRef(points ? points : Py_None);
    r->faces = Py_XNewRef(faces ? faces : Py_None);
    r->auto_step0 = Py_NewRef(Py_None);
    if (!r->normal || !r->k1 || !r->k2 || !r->d1 || !r->d2 || !r->b || !r->c || !r->degree ||
        !r->neighbors || !r->status || !r->cond || !r->residual || !r->sigma) {
        Py_DECREF(r);
        return NULL;
    }
    return (PyObject *)r;
}

/* Where each column of a Result is written. */
typedef struct {
    double *nrm, *k1, *k2, *d1, *d2, *cond, *resid, *b, *c;
    int32_t *deg, *nb, *st;
    double *sigma;
} outp;

static outp out_ptrs(Result *r)
{
    return (outp){PyArray_DATA(ARR(r->normal)), PyArray_DATA(ARR(r->k1)),
                  PyArray_DATA(ARR(r->k2)),     PyArray_DATA(ARR(r->d1)),
                  PyArray_DATA(ARR(r->d2)),     PyArray_DATA(ARR(r->cond)),
                  PyArray_DATA(ARR(r->residual)),
                  r->monge >= 3 ? PyArray_DATA(ARR(r->b)) : NULL,
                  r->monge >= 4 ? PyArray_DATA(ARR(r->c)) : NULL,
                  PyArray_DATA(ARR(r->degree)), PyArray_DATA(ARR(r->neighbors)),
                  PyArray_DATA(ARR(r->status)), PyArray_DATA(ARR(r->sigma))};
}

static void put(const outp *o, size_t i, const jf_result *p)
{
    memcpy(o->nrm + 3 * i, p->normal, sizeof p->normal);
    memcpy(o->d1 + 3 * i, p->d1, sizeof p->d1);
    memcpy(o->d2 + 3 * i, p->d2, sizeof p->d2);
    o->k1[i] = p->k1;
    o->k2[i] = p->k2;
    if (o->b) memcpy(o->b + 4 * i, p->b, sizeof p->b);
    if (o->c) memcpy(o->c + 5 * i, p->c, sizeof p->c);
    o->deg[i] = p->degree;
    o->nb[i] = p->n_used;
    o->st[i] = (int32_t)p->status;
    o->cond[i] = p->cond;
    o->resid[i] = p->residual;
    o->sigma[i] = p->sigma;
}

void jf_py_result_fill(PyObject *result, const jf_result *res, size_t n, int threads)
{
    const outp o = out_ptrs((Result *)result);
    /* on the estimate's threads: the first touch of fresh output pages
     * costs as much as the copy (10^6 points: 0.2 s on one thread) */
#pragma omp parallel for schedule(static) num_threads(threads)
    for (size_t i = 0; i < n; i++) put(&o, i, &res[i]);
}

jf_status jf_py_result_block(void *result, const uint32_t *idx, jf_result *res, size_t m)
{
    /* reads the arrays' data pointers only: no GIL needed */
    const outp o = out_ptrs(result);
    for (size_t j = 0; j < m; j++) put(&o, idx[j], &res[j]);
    return JF_OK;
}

int jf_py_result_monge(PyObject *result) { return ((Result *)result)->monge; }

int jf_py_result_sigma(PyObject *result) { return ((Result *)result)->with_sigma; }

int jf_py_result_step0(PyObject *result, int chosen)
{
    char line[256];
    PyObject *s = PyUnicode_FromString(jf_auto_step0_str(chosen, line, sizeof line));
    if (!s) return -1;
    Result *r = (Result *)result;
    Py_SETREF(r->auto_step0, s);
    return 0;
}

size_t jf_py_result_count(PyObject *result, unsigned mask)
{
    Result *r = (Result *)result;
    const int32_t *st = PyArray_DATA(ARR(r->status));
    size_t n = 0;
    for (Py_ssize_t i = 0; i < r->n; i++) n += ((uint32_t)st[i] & mask) != 0;
    return n;
}

/* ---- the output file's columns: the library's one list ------------------ */

size_t jf_py_result_columns(PyObject *result, jf_column *cols)
{
    return jf_result_columns(((Result *)result)->monge, ((Result *)result)->with_sigma, cols);
}

/* The source array of column j and its component, in file order. */
static void column_source(Result *r, PyArrayObject *pts, size_t j, PyArrayObject **a, int *comp)
{
    PyArrayObject *v3[] = {pts, ARR(r->normal)};
    *comp = 0;
    if (j < 6) {
        *a = v3[j / 3], *comp = (int)(j % 3);
        return;
    }
    if (j == 6 || j == 7) {
        *a = ARR(j == 6 ? r->k1 : r->k2);
        return;
    }
    if (j < 14) {
        *a = ARR(j < 11 ? r->d1 : r->d2), *comp = (int)((j - 8) % 3);
        return;
    }
    j -= 14;
    if (r->monge >= 3) {
        if (j < 4) {
            *a = ARR(r->b), *comp = (int)j;
            return;
        }
        j -= 4;
    }
    if (r->monge >= 4) {
        if (j < 5) {
            *a = ARR(r->c), *comp = (int)j;
            return;
        }
        j -= 5;
    }
    /* jf_result_columns' order: sigma (when there) before status */
    PyObject *tail[] = {r->degree, r->neighbors, r->cond, r->residual, r->sigma, r->status};
    *a = ARR(tail[j == 4 && !r->with_sigma ? 5 : j]);
}

/* Result.as_structured(points=None): one structured array, fields named and
 * typed as the output file's columns (F64 -> '<f8', I32 -> '<i4'). */
static PyObject *as_structured(Result *r, PyObject *args, PyObject *kw)
{
    static char *kwl[] = {"points", NULL};
    PyObject *pobj = NULL;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "|O:as_structured", kwl, &pobj)) return NULL;
    if (!pobj || pobj == Py_None) pobj = r->points;
    if (pobj == Py_None) {
        PyErr_SetString(PyExc_ValueError, "as_structured: this Result has no points; pass points=");
        return NULL;
    }
    PyArrayObject *pts = jf_py_points(pobj, "points");
    if (!pts) return NULL;
    if (PyArray_DIM(pts, 0) != r->n) {
        Py_DECREF(pts);
        return PyErr_Format(PyExc_ValueError, "points: %zd rows for a Result of %zd",
                            (Py_ssize_t)PyArray_DIM(pts, 0), r->n);
    }
    jf_column cols[JF_RESULT_MAX_COLS];
    size_t nc = jf_py_result_columns((PyObject *)r, cols);
    PyObject *spec = PyList_New((Py_ssize_t)nc);
    for (size_t j = 0; spec && j < nc; j++) {
        PyObject *t = Py_BuildValue("(ss)", cols[j].name, cols[j].type == JF_COL_I32 ? "<i4" : "<f8");
        if (!t) Py_CLEAR(spec);
        else PyList_SET_ITEM(spec, (Py_ssize_t)j, t);
    }
    PyArray_Descr *dt = NULL;
    if (!spec || !PyArray_DescrConverter(spec, &dt)) {
        Py_XDECREF(spec);
        Py_DECREF(pts);
        return NULL;
    }
    Py_DECREF(spec);
    npy_intp dims[1] = {r->n};
    PyArrayObject *out = (PyArrayObject *)PyArray_Empty(1, dims, dt, 0); /* steals dt */
    if (!out) {
        Py_DECREF(pts);
        return NULL;
    }
    char *base = PyArray_DATA(out);
    size_t rec = (size_t)PyArray_ITEMSIZE(out), off = 0;
    for (size_t j = 0; j < nc; j++) {
        PyArrayObject *a;
        int comp;
        column_source(r, pts, j, &a, &comp);
        npy_intp w = PyArray_NDIM(a) == 2 ? PyArray_DIM(a, 1) : 1;
        if (cols[j].type == JF_COL_I32) {
            const int32_t *s = PyArray_DATA(a);
            for (Py_ssize_t i = 0; i < r->n; i++) memcpy(base + (size_t)i * rec + off, &s[i], 4);
            off += 4;
        } else {
            const double *s = PyArray_DATA(a);
            for (Py_ssize_t i = 0; i < r->n; i++)
                memcpy(base + (size_t)i * rec + off, &s[(size_t)(i * w + comp)], 8);
            off += 8;
        }
    }
    Py_DECREF(pts);
    return (PyObject *)out;
}

static Py_ssize_t result_len(Result *r) { return r->n; }

static PyObject *result_repr(Result *r)
{
    return PyUnicode_FromFormat("<jetfit.Result: %zd points, monge_degree %d>", r->n, r->monge);
}

static PyMemberDef members[] = {
    {"normal", T_OBJECT_EX, offsetof(Result, normal), READONLY, "(N, 3) unit normals (nx ny nz)"},
    {"k1", T_OBJECT_EX, offsetof(Result, k1), READONLY, "(N,) principal curvature, k1 >= k2"},
    {"k2", T_OBJECT_EX, offsetof(Result, k2), READONLY, "(N,) principal curvature"},
    {"d1", T_OBJECT_EX, offsetof(Result, d1), READONLY, "(N, 3) principal direction of k1"},
    {"d2", T_OBJECT_EX, offsetof(Result, d2), READONLY, "(N, 3) principal direction of k2"},
    {"b", T_OBJECT_EX, offsetof(Result, b), READONLY,
     "(N, 4) Monge b0..b3, or None when monge_degree < 3"},
    {"c", T_OBJECT_EX, offsetof(Result, c), READONLY,
     "(N, 5) Monge c0..c4, or None when monge_degree < 4"},
    {"degree", T_OBJECT_EX, offsetof(Result, degree), READONLY, "(N,) int32 degree used"},
    {"neighbors", T_OBJECT_EX, offsetof(Result, neighbors), READONLY,
     "(N,) int32 points in the fit"},
    {"status", T_OBJECT_EX, offsetof(Result, status), READONLY,
     "(N,) int32 flags (jetfit.STATUS; 0 = ok)"},
    {"cond", T_OBJECT_EX, offsetof(Result, cond), READONLY, "(N,) condition number"},
    {"residual", T_OBJECT_EX, offsetof(Result, residual), READONLY, "(N,) RMS fit residual"},
    {"sigma", T_OBJECT_EX, offsetof(Result, sigma), READONLY,
     "(N,) neighbors='auto': the noise it estimated (length units); NaN otherwise"},
    {"auto_step0", T_OBJECT_EX, offsetof(Result, auto_step0), READONLY,
     "neighbors='auto': step 0's decision for the cloud, as the command's summary "
     "says it ('K capped at 32; ...' or 'no cap on K; ...'); None otherwise"},
    {"points", T_OBJECT_EX, offsetof(Result, points), READONLY, "the points, as given"},
    {"faces", T_OBJECT_EX, offsetof(Result, faces), READONLY, "the faces (meshes) or None"},
    {"monge_degree", T_INT, offsetof(Result, monge), READONLY, "Monge degree (2..4)"},
    {NULL, 0, 0, 0, NULL}};

static PyMethodDef rmethods[] = {
    {"as_structured", (PyCFunction)(void (*)(void))as_structured, METH_VARARGS | METH_KEYWORDS,
     "as_structured(points=None) -> one structured array with the output file's columns"},
    {NULL, NULL, 0, NULL}};

static PySequenceMethods rseq = {.sq_length = (lenfunc)result_len};

PyTypeObject jf_py_ResultType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "jetfit.Result",
    .tp_doc = "Per-point results of jetfit.estimate: one array per quantity, row i for point i.",
    .tp_basicsize = sizeof(Result),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_dealloc = (destructor)result_dealloc,
    .tp_repr = (reprfunc)result_repr,
    .tp_as_sequence = &rseq,
    .tp_members = members,
    .tp_methods = rmethods,
};

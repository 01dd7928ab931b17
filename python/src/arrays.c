/* arrays.c -- numpy in and out: (N, 3) points and normals, faces.
 *
 * Points reach the library as `const double *xyz`, 3 per point.  An array
 * that already is C-contiguous, aligned float64 (N, 3) is passed as is (no
 * copy: the library only reads it); anything else -- float32, Fortran
 * order, a strided view, integers, a list -- is converted once by numpy
 * into a new array (same values: float32 and integers convert exactly). */
#include "jfpy.h"

PyArrayObject *jf_py_points(PyObject *obj, const char *what)
{
    PyArray_Descr *want = PyArray_DescrFromType(NPY_DOUBLE);
    if (!want) return NULL;
    if (PyArray_Check(obj)) {
        /* complex, bool, object, strings, datetimes: not coordinates */
        int t = PyArray_TYPE((PyArrayObject *)obj);
        if (!PyTypeNum_ISFLOAT(t) && !PyTypeNum_ISINTEGER(t)) {
            Py_DECREF(want);
            return (PyArrayObject *)PyErr_Format(
                PyExc_TypeError, "%s: expected a float or integer array, got dtype %S", what,
                (PyObject *)PyArray_DESCR((PyArrayObject *)obj));
        }
    }
    /* steals `want`; returns obj itself (new reference) when it fits */
    PyArrayObject *a = (PyArrayObject *)PyArray_FromAny(
        obj, want, 0, 0, NPY_ARRAY_C_CONTIGUOUS | NPY_ARRAY_ALIGNED, NULL);
    if (!a) {
        if (PyErr_ExceptionMatches(PyExc_TypeError) || PyErr_ExceptionMatches(PyExc_ValueError)) {
            PyObject *t, *v, *tb;
            PyErr_Fetch(&t, &v, &tb);
            PyErr_Format(PyExc_TypeError, "%s: expected an (N, 3) array of numbers (%S)", what,
                         v ? v : Py_None);
            Py_XDECREF(t);
            Py_XDECREF(v);
            Py_XDECREF(tb);
        }
        return NULL;
    }
    if (PyArray_NDIM(a) != 2 || PyArray_DIM(a, 1) != 3) {
        PyObject *shape = PyObject_GetAttrString((PyObject *)a, "shape");
        PyErr_Format(PyExc_ValueError, "%s: expected an (N, 3) array, got shape %S", what,
                     shape ? shape : Py_None);
        Py_XDECREF(shape);
        Py_DECREF(a);
        return NULL;
    }
    return a;
}

PyArrayObject *jf_py_empty(int nd, npy_intp d0, npy_intp d1, int type)
{
    npy_intp dims[2] = {d0, d1};
    return (PyArrayObject *)PyArray_EMPTY(nd, dims, type, 0);
}

void jf_py_faces_free(jf_cloud *c)
{
    PyMem_Free(c->face_off);
    PyMem_Free(c->face_idx);
    c->face_off = NULL;
    c->face_idx = NULL;
    c->nfaces = 0;
}

/* Index check shared by both layouts: negative indices would wrap. */
static int put_index(jf_cloud *c, size_t at, long long v, size_t f)
{
    if (v < 0 || (unsigned long long)v >= UINT32_MAX) {
        PyErr_Format(PyExc_ValueError, "faces: face %zu: vertex index %lld out of range", f, v);
        return -1;
    }
    c->face_idx[at] = (uint32_t)v;
    return 0;
}

/* (M, k) integer array */
static int faces_array(PyObject *obj, jf_cloud *c)
{
    PyArrayObject *a = (PyArrayObject *)PyArray_FromAny(
        obj, PyArray_DescrFromType(NPY_LONGLONG), 2, 2,
        NPY_ARRAY_C_CONTIGUOUS | NPY_ARRAY_ALIGNED | NPY_ARRAY_FORCECAST, NULL);
    if (!a) return -1;
    size_t m = (size_t)PyArray_DIM(a, 0), k = (size_t)PyArray_DIM(a, 1);
    if (k < 3) {
        Py_DECREF(a);
        PyErr_Format(PyExc_ValueError, "faces: expected (M, k) with k >= 3, got k = %zu", k);
        return -1;
    }
    c->face_off = PyMem_Malloc((m + 1) * sizeof *c->face_off);
    c->face_idx = PyMem_Malloc((m * k > 0 ? m * k : 1) * sizeof *c->face_idx);
    if (!c->face_off || !c->face_idx) {
        Py_DECREF(a);
        jf_py_faces_free(c);
        PyErr_NoMemory();
        return -1;
    }
    const long long *v = PyArray_DATA(a);
    for (size_t f = 0; f <= m; f++) c->face_off[f] = f * k;
    for (size_t j = 0; j < m * k; j++)
        if (put_index(c, j, v[j], j / k) < 0) {
            Py_DECREF(a);
            jf_py_faces_free(c);
            return -1;
        }
    c->nfaces = m;
    Py_DECREF(a);
    return 0;
}

/* a sequence of polygons of any sizes >= 3 */
static int faces_lists(PyObject *obj, jf_cloud *c)
{
    PyObject *seq = PySequence_Fast(obj, "faces: expected an (M, k) integer array or a "
                                         "sequence of index sequences");
    if (!seq) return -1;
    size_t m = (size_t)PySequence_Fast_GET_SIZE(seq), total = 0, cap = 0;
    c->face_off = PyMem_Malloc((m + 1) * sizeof *c->face_off);
    if (!c->face_off) goto nomem;
    c->face_off[0] = 0;
    for (size_t f = 0; f < m; f++) {
        PyArrayObject *p = (PyArrayObject *)PyArray_FromAny(
            PySequence_Fast_GET_ITEM(seq, f), PyArray_DescrFromType(NPY_LONGLONG), 1, 1,
            NPY_ARRAY_C_CONTIGUOUS | NPY_ARRAY_ALIGNED, NULL);
        if (!p) goto fail;
        size_t k = (size_t)PyArray_DIM(p, 0);
        if (k < 3) {
            Py_DECREF(p);
            PyErr_Format(PyExc_ValueError, "faces: face %zu has %zu vertices (3 or more)", f, k);
            goto fail;
        }
        if (total + k > cap) {
            size_t ncap = 2 * (total + k) + 16;
            uint32_t *g = PyMem_Realloc(c->face_idx, ncap * sizeof *g);
            if (!g) {
                Py_DECREF(p);
                goto nomem;
            }
            c->face_idx = g, cap = ncap;
        }
        const long long *v = PyArray_DATA(p);
        for (size_t j = 0; j < k; j++)
            if (put_index(c, total + j, v[j], f) < 0) {
                Py_DECREF(p);
                goto fail;
            }
        Py_DECREF(p);
        total += k;
        c->face_off[f + 1] = total;
    }
    if (!c->face_idx && !(c->face_idx = PyMem_Malloc(sizeof *c->face_idx))) goto nomem;
    c->nfaces = m;
    Py_DECREF(seq);
    return 0;
nomem:
    PyErr_NoMemory();
fail:
    Py_DECREF(seq);
    jf_py_faces_free(c);
    return -1;
}

int jf_py_faces(PyObject *obj, size_t nverts, jf_cloud *c)
{
    (void)nverts; /* indices are checked against it by jf_mesh_build */
    c->nfaces = 0;
    c->face_off = NULL;
    c->face_idx = NULL;
    if (PyArray_Check(obj)) {
        if (!PyTypeNum_ISINTEGER(PyArray_TYPE((PyArrayObject *)obj))) {
            PyErr_Format(PyExc_TypeError, "faces: expected an integer array, got dtype %S",
                         (PyObject *)PyArray_DESCR((PyArrayObject *)obj));
            return -1;
        }
        return faces_array(obj, c);
    }
    return faces_lists(obj, c);
}

PyObject *jf_py_faces_out(const jf_cloud *c)
{
    size_t m = c->nfaces, k = m ? c->face_off[1] - c->face_off[0] : 3;
    int uniform = 1;
    for (size_t f = 0; f < m && uniform; f++) uniform = c->face_off[f + 1] - c->face_off[f] == k;
    if (uniform) {
        PyArrayObject *a = jf_py_empty(2, (npy_intp)m, (npy_intp)k, NPY_INT32);
        if (!a) return NULL;
        int32_t *d = PyArray_DATA(a);
        for (size_t j = 0; j < m * k; j++) d[j] = (int32_t)c->face_idx[j];
        return (PyObject *)a;
    }
    PyObject *list = PyList_New((Py_ssize_t)m);
    for (size_t f = 0; list && f < m; f++) {
        size_t b = c->face_off[f], e = c->face_off[f + 1];
        PyArrayObject *a = jf_py_empty(1, (npy_intp)(e - b), 0, NPY_INT32);
        if (!a) {
            Py_CLEAR(list);
            break;
        }
        int32_t *d = PyArray_DATA(a);
        for (size_t j = b; j < e; j++) d[j - b] = (int32_t)c->face_idx[j];
        PyList_SET_ITEM(list, (Py_ssize_t)f, (PyObject *)a);
    }
    return list;
}

/* files.c -- jetfit.read(path) and jetfit.write(path, result, ...): the
 * library's readers (jf_cloud_read) and table writer (jf_writer_*), so a
 * file means the same as to the command, errors read the same ("FILE:LINE:
 * reason", raised as jetfit.FileError, an OSError) and write() produces the
 * command's output file byte for byte (same columns, rows, temporary then
 * rename: a failed write leaves an existing file untouched). */
#include "jfpy.h"
#include "io/io_internal.h" /* jf__las_columns: .laz columns as the command writes them */

/* ---- read ---------------------------------------------------------------- */

static void free_capsule(PyObject *cap) { free(PyCapsule_GetPointer(cap, NULL)); }

/* An (n, 3) float64 array over malloc'd data, which it then owns (no copy;
 * the library allocated it with malloc). */
static PyObject *own_xyz(double *data, size_t n)
{
    npy_intp dims[2] = {(npy_intp)n, 3};
    PyObject *a = PyArray_SimpleNewFromData(2, dims, NPY_DOUBLE, data);
    if (!a) return NULL;
    PyObject *cap = PyCapsule_New(data, NULL, free_capsule);
    if (!cap) {
        Py_DECREF(a);
        return NULL;
    }
    if (PyArray_SetBaseObject((PyArrayObject *)a, cap) < 0) { /* steals cap */
        Py_DECREF(a);
        return NULL;
    }
    return a;
}

static PyObject *file_error(jf_status st, const jf_error *err, const char *path)
{
    if (st == JF_ERR_NOMEM) return PyErr_NoMemory();
    PyErr_SetString(jf_py_FileError, err->msg[0] ? err->msg : path);
    return NULL;
}

/* {name: (n,) array} of the attribute table, each in its input type
 * (LAS bit fields as uint8, scaled LAS Extra Bytes as float64), in the
 * file's order. */
static PyObject *attrs_dict(const jf_attrs *a, size_t n)
{
    static const int npy[10] = {NPY_INT8,  NPY_UINT8,  NPY_INT16, NPY_UINT16, NPY_INT32,
                                NPY_UINT32, NPY_INT64, NPY_UINT64, NPY_FLOAT32, NPY_FLOAT64};
    static const size_t size[10] = {1, 1, 2, 2, 4, 4, 8, 8, 4, 8};
    const uint16_t one = 1;
    const int little = *(const unsigned char *)&one == 1;
    PyObject *d = PyDict_New();
    for (size_t j = 0; d && j < a->nattrs; j++) {
        const jf_attr *at = &a->attr[j];
        int t = at->bits ? JF_ATTR_U8 : at->scale_factor != 0 ? JF_ATTR_F64 : (int)at->type;
        npy_intp dims[1] = {(npy_intp)n};
        PyObject *arr = PyArray_SimpleNew(1, dims, little ? npy[t] : NPY_FLOAT64);
        if (!arr) {
            Py_CLEAR(d);
            break;
        }
        unsigned char *o = PyArray_DATA((PyArrayObject *)arr);
        for (size_t i = 0; i < n; i++) {
            const unsigned char *r = a->rec + i * a->stride + at->offset;
            if (!little || at->scale_factor != 0) { /* big-endian host, or a scaled LAS
                                                 Extra Byte: values as doubles */
                double v = jf_attr_get(a, j, i);
                memcpy(o + 8 * i, &v, 8);
            } else if (at->bits) {
                o[i] = (unsigned char)((r[0] >> at->shift) & ((1u << at->bits) - 1u));
            } else {
                memcpy(o + size[t] * i, r, size[t]);
            }
        }
        int bad = PyDict_SetItemString(d, at->name, arr) < 0;
        Py_DECREF(arr);
        if (bad) Py_CLEAR(d);
    }
    return d;
}

/* attrs["scan"] (N,) int32 and attrs["scanner"] (N, 3) float64: the scan
 * of each row and the position of its scanner (c->scanner[c->scan[i]]). */
static int scanner_attrs(const jf_cloud *c, PyObject *attrs)
{
    PyArrayObject *scan = jf_py_empty(1, (npy_intp)c->n, 0, NPY_INT32);
    PyArrayObject *pos = scan ? jf_py_empty(2, (npy_intp)c->n, 3, NPY_DOUBLE) : NULL;
    int rc = -1;
    if (pos) {
        int32_t *s = PyArray_DATA(scan);
        double *p = PyArray_DATA(pos);
        for (size_t i = 0; i < c->n; i++) {
            s[i] = (int32_t)c->scan[i];
            memcpy(p + 3 * i, c->scanner + 3 * (size_t)c->scan[i], 3 * sizeof(double));
        }
        if (PyDict_SetItemString(attrs, "scan", (PyObject *)scan) == 0 &&
            PyDict_SetItemString(attrs, "scanner", (PyObject *)pos) == 0)
            rc = 0;
    }
    Py_XDECREF(scan);
    Py_XDECREF(pos);
    return rc;
}

PyObject *jf_py_read(PyObject *self, PyObject *args, PyObject *kw)
{
    (void)self;
    static char *kwl[] = {"path", "columns", "bad_rows", NULL};
    PyObject *pathobj, *columns = NULL, *bad_rows = NULL;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O&|$OO:read", kwl, PyUnicode_FSConverter, &pathobj,
                                     &columns, &bad_rows))
        return NULL;
    const char *path = PyBytes_AS_STRING(pathobj);
    jf_py_opts po;
    jf_py_opts_init(&po);
    if (jf_py_opt(&po, "columns", "columns", columns, JF_PY_LIST) ||
        jf_py_opt(&po, "bad_rows", "bad_rows", bad_rows, JF_PY_STR)) {
        Py_DECREF(pathobj);
        return NULL;
    }
    jf_cloud c = {0};
    jf_error err = {{0}};
    jf_status st;
    Py_BEGIN_ALLOW_THREADS
    st = jf_cloud_read(path, &po.ro, &c, &err);
    Py_END_ALLOW_THREADS
    if (st != JF_OK) {
        file_error(st, &err, path);
        Py_DECREF(pathobj);
        return NULL;
    }
    if (c.nbad) {
        /* bad_rows="skip": the command's line, as a warning */
        char lines[160] = "";
        size_t shown = c.nbad < 10 ? c.nbad : 10, len = 0;
        for (size_t k = 0; k < shown && len < sizeof lines; k++)
            len += (size_t)snprintf(lines + len, sizeof lines - len, "%s%zu", k ? ", " : "",
                                    c.bad_line[k]);
        if (PyErr_WarnFormat(PyExc_RuntimeWarning, 1,
                             "%s: %zu unparsable rows kept as NaN rows (status nonfinite), "
                             "lines %s%s", path, c.nbad, lines, c.nbad > shown ? ", ..." : "") < 0) {
            jf_cloud_free(&c);
            Py_DECREF(pathobj);
            return NULL;
        }
    }
    Py_DECREF(pathobj);
    PyObject *pts = NULL, *nrm = NULL, *faces = NULL, *attrs = NULL, *out = NULL;
    if (!(pts = own_xyz(c.xyz, c.n))) goto done;
    c.xyz = NULL; /* the array owns it now */
    if (c.nrm) {
        if (!(nrm = own_xyz(c.nrm, c.n))) goto done;
        c.nrm = NULL;
    } else {
        nrm = Py_NewRef(Py_None);
    }
    faces = c.nfaces ? jf_py_faces_out(&c) : Py_NewRef(Py_None);
    if (!faces) goto done;
    /* the input's other per-point values (jf_cloud.attrs): name -> an (N,)
     * array of the input's type; a PTX file's scans (scan index and scanner
     * position of every row, what estimate(..., scanners=) takes) */
    if (!(attrs = attrs_dict(&c.attrs, c.n))) goto done;
    if (c.scanner && scanner_attrs(&c, attrs) < 0) goto done;
    out = PyTuple_Pack(4, pts, nrm, faces, attrs);
done:
    Py_XDECREF(pts);
    Py_XDECREF(nrm);
    Py_XDECREF(faces);
    Py_XDECREF(attrs);
    jf_cloud_free(&c);
    return out;
}

/* ---- write --------------------------------------------------------------- */

/* The arrays of a Result, looked up once (borrowed through `r`). */
typedef struct {
    const double *xyz, *nrm, *k1, *k2, *d1, *d2, *b, *c, *cond, *res;
    const int32_t *deg, *nb, *st;
    const double *sigma; /* NULL: no sigma column */
} cols_src;

static const void *data_of(PyObject *r, const char *name)
{
    PyObject *a = PyObject_GetAttrString(r, name);
    if (!a) return NULL;
    const void *d = a == Py_None ? NULL : PyArray_DATA((PyArrayObject *)a);
    Py_DECREF(a); /* the Result keeps it alive */
    return d;
}

/* One row as cmd_estimate.c's make_row builds it. */
static size_t make_row(const cols_src *s, size_t i, int monge, double *v)
{
    size_t n = 0;
    for (int j = 0; j < 3; j++) v[n++] = s->xyz[3 * i + (size_t)j];
    for (int j = 0; j < 3; j++) v[n++] = s->nrm[3 * i + (size_t)j];
    v[n++] = s->k1[i];
    v[n++] = s->k2[i];
    for (int j = 0; j < 3; j++) v[n++] = s->d1[3 * i + (size_t)j];
    for (int j = 0; j < 3; j++) v[n++] = s->d2[3 * i + (size_t)j];
    if (monge >= 3)
        for (int j = 0; j < 4; j++) v[n++] = s->b[4 * i + (size_t)j];
    if (monge >= 4)
        for (int j = 0; j < 5; j++) v[n++] = s->c[5 * i + (size_t)j];
    v[n++] = s->deg[i];
    v[n++] = s->nb[i];
    v[n++] = s->cond[i];
    v[n++] = s->res[i];
    if (s->sigma) v[n++] = s->sigma[i]; /* jf_result_columns' order */
    v[n++] = (double)(uint32_t)s->st[i];
    return n;
}

PyObject *jf_py_write(PyObject *self, PyObject *args, PyObject *kw)
{
    (void)self;
    static char *kwl[] = {"path", "result", "points", "faces", "ascii", "threads", NULL};
    PyObject *pathobj, *result, *points = NULL, *faces = NULL, *threads = NULL;
    int ascii = 0;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O&O!|$OOpO:write", kwl, PyUnicode_FSConverter,
                                     &pathobj, &jf_py_ResultType, &result, &points, &faces, &ascii,
                                     &threads))
        return NULL;
    PyObject *ret = NULL;
    PyArrayObject *pa = NULL;
    jf_cloud fc = {0};
    jf_py_opts po;
    jf_py_opts_init(&po);
    if (jf_py_opt(&po, "threads", "threads", threads, JF_PY_INT)) goto out;
    int nthreads = po.o.threads;
    if (!points || points == Py_None) points = PyObject_GetAttrString(result, "points");
    else Py_INCREF(points);
    if (!points) goto out;
    if (points == Py_None) {
        Py_DECREF(points);
        PyErr_SetString(PyExc_ValueError, "write: this Result has no points; pass points=");
        goto out;
    }
    pa = jf_py_points(points, "points");
    Py_DECREF(points);
    if (!pa) goto out;
    size_t n = (size_t)PyObject_Length(result);
    if ((size_t)PyArray_DIM(pa, 0) != n) {
        PyErr_Format(PyExc_ValueError, "points: %zd rows for a Result of %zd",
                     (Py_ssize_t)PyArray_DIM(pa, 0), (Py_ssize_t)n);
        goto out;
    }
    PyObject *fobj = faces && faces != Py_None ? Py_NewRef(faces)
                                               : PyObject_GetAttrString(result, "faces");
    if (!fobj) goto out;
    int fbad = fobj != Py_None && jf_py_faces(fobj, n, &fc) < 0;
    Py_DECREF(fobj);
    if (fbad) goto out;
    /* a face naming a point the file does not have is an error, never
     * dropped (issue 33.3) */
    for (size_t f = 0; f < fc.nfaces; f++)
        for (size_t k = fc.face_off[f]; k < fc.face_off[f + 1]; k++)
            if (fc.face_idx[k] >= n) {
                PyErr_Format(PyExc_ValueError, "faces: face %zu has vertex index %lu, the "
                             "points have %zu rows", f, (unsigned long)fc.face_idx[k], n);
                goto out;
            }

    int monge = jf_py_result_monge(result);
    cols_src s = {PyArray_DATA(pa), data_of(result, "normal"), data_of(result, "k1"),
                  data_of(result, "k2"), data_of(result, "d1"), data_of(result, "d2"),
                  data_of(result, "b"), data_of(result, "c"), data_of(result, "cond"),
                  data_of(result, "residual"), data_of(result, "degree"),
                  data_of(result, "neighbors"), data_of(result, "status"),
                  jf_py_result_sigma(result) ? data_of(result, "sigma") : NULL};
    if (PyErr_Occurred()) goto out;
    jf_column cols[JF_RESULT_MAX_COLS];
    size_t ncols = jf_py_result_columns(result, cols);
    const char *path = PyBytes_AS_STRING(pathobj);
    jf__las_columns(path, 0, cols, ncols); /* .laz: compact, as the command */
    jf_error err = {{0}};
    jf_writer *w = NULL;
    jf_status st;
    enum { BLOCK = 65536 };
    double *rows = PyMem_RawMalloc((n < BLOCK ? (n ? n : 1) : BLOCK) * ncols * sizeof *rows);
    if (!rows) {
        PyErr_NoMemory();
        goto out;
    }
    Py_BEGIN_ALLOW_THREADS
    st = jf_writer_open(path, cols, ncols, n, ascii, &w, &err);
    if (st == JF_OK) {
        /* a mesh keeps its faces in a PLY output, as the command does */
        if (fc.nfaces && (st = jf_writer_faces(w, fc.nfaces, fc.face_off, fc.face_idx)) != JF_OK)
            jf_writer_abort(w);
        /* .las: the scale and offset from the points, as the command sets them */
        if (st == JF_OK) (void)jf_writer_las_frame(w, s.xyz, n);
        for (size_t b0 = 0; st == JF_OK && b0 < n; b0 += BLOCK) {
            size_t nb = n - b0 < BLOCK ? n - b0 : BLOCK;
            for (size_t k = 0; k < nb; k++) make_row(&s, b0 + k, monge, rows + k * ncols);
            if (jf_writer_rows(w, rows, nb, nthreads) != JF_OK) break;
        }
        if (st == JF_OK)
            st = jf_writer_commit(w, &err); /* reports a failed row too */
        else
            snprintf(err.msg, sizeof err.msg, "%s: cannot write its %zu faces: %s", path,
                     fc.nfaces, jf_strerror(st));
    }
    Py_END_ALLOW_THREADS
    PyMem_RawFree(rows);
    if (st != JF_OK) {
        file_error(st, &err, path);
        goto out;
    }
    ret = Py_NewRef(Py_None);
out:
    jf_py_faces_free(&fc);
    Py_XDECREF(pa);
    Py_DECREF(pathobj);
    return ret;
}

/* estimate.c -- jetfit.estimate(points, ...) and jetfit.estimate_mesh(
 * vertices, faces, ...): jf_estimate on numpy arrays.
 *
 * design:
 *  1. Options through the command's parser (options.c); points (and
 *     normals) as (N, 3) float64 C arrays, passed without a copy when they
 *     already are (arrays.c).
 *  2. The Result's arrays are made first (so nothing fails after the
 *     work), then jf_estimate runs on a thread of its own, the GIL
 *     released (offthread.c); the calling thread runs Python's signal
 *     handlers every 0.1 s: Ctrl-C raises KeyboardInterrupt there, the
 *     cancel hook (jetfit.h) says stop, every OpenMP thread leaves after
 *     its current block (JF_BLOCK_MAX points).
 *  3. The results go into the Result's arrays block by block as they are
 *     fitted (jf_estimate_blocks' sink, on the estimate's threads), except
 *     with orient='mst', which needs every normal first: then n results
 *     are kept and copied (jf_estimate_blocks would fit twice).
 * Memory: the library's own (k-d tree ~40 B/point; with mst 216 B/point
 * of jf_result) plus the Result's arrays (116-188 B/point); no copy of
 * the points when they are float64 C-contiguous. */
#include <math.h>

#include "jfpy.h"

/* jf_cancel_fn: read on the estimate's threads; set by jf_py_off_thread
 * when a signal handler raised (KeyboardInterrupt). */
static int check_stop(void *user)
{
    return __atomic_load_n((volatile int *)user, __ATOMIC_ACQUIRE);
}

typedef struct {
    jf_cloud *c;
    jf_estimate_opts *o;
    jf_result *res; /* n results (orient mst), else NULL */
    PyObject *result;
    jf_error err;
    jf_status st;
} est_job;

/* On jf_py_off_thread's thread, without the GIL. */
static void est_work(void *p)
{
    est_job *j = p;
    if (j->res) {
        j->st = jf_estimate(j->c, j->o, j->res, &j->err);
        if (j->st == JF_OK)
            jf_py_result_fill(j->result, j->res, j->c->n,
                              j->o->threads > 0 ? j->o->threads : jf_default_threads(NULL));
    } else {
        j->st = jf_estimate_blocks(j->c, j->o, jf_py_result_block, j->result, &j->err);
    }
}

/* No point fitted: ValueError; most points unfitted: RuntimeWarning --
 * the command's rule and words (cmd_estimate.c, issues 31, 33.12).
 * -1 with the exception set (result released). */
static int nothing_fitted(const jf_cloud *c, PyObject *result)
{
    size_t unfit = jf_py_result_count(result, JF_PT_FAILED | JF_PT_NONFINITE);
    size_t nonfin = jf_py_result_count(result, JF_PT_NONFINITE);
    if (c->n && unfit == c->n) {
        double big = 0;
        for (size_t i = 0; i < 3 * c->n; i++)
            if (isfinite(c->xyz[i]) && fabs(c->xyz[i]) > big) big = fabs(c->xyz[i]);
        PyErr_Format(PyExc_ValueError, "no point could be fitted (%zu non-finite, %zu failed)%s",
                     nonfin, c->n - nonfin,
                     big > 1e150 ? ": coordinates near 1e150 or beyond overflow the fit "
                                   "(rescale the cloud)"
                     : nonfin < c->n ? ": too few or collinear neighbours (K must be at least 3)"
                                     : ": every point is NaN or infinite");
        Py_DECREF(result);
        return -1;
    }
    if (unfit > c->n / 2 &&
        PyErr_WarnFormat(PyExc_RuntimeWarning, 1, "%zu of %zu points could not be fitted "
                         "(status failed or nonfinite)", unfit, c->n) < 0) {
        Py_DECREF(result); /* warnings made errors */
        return -1;
    }
    return 0;
}

/* Runs the estimate on cloud c with options o into a new Result. */
static PyObject *run(jf_cloud *c, jf_py_opts *po, PyObject *points, PyObject *faces)
{
    jf_estimate_opts *o = &po->o;
    if (o->orient == JF_ORIENT_SCANNER && !c->scanner) {
        PyErr_SetString(PyExc_ValueError,
                        "orient='scanner' needs scanners=: the (N, 3) position of the scanner "
                        "that measured each point (jetfit.read gives them for a PTX file as "
                        "attributes['scanner'])");
        return NULL;
    }
    if ((o->orient == JF_ORIENT_INPUT || o->normal == JF_NORMAL_INPUT) && !c->nrm && c->n) {
        PyErr_Format(PyExc_ValueError,
                     "%s='input' needs normals=: an (N, 3) array of the points' normals "
                     "(jetfit.read gives a file's as its second value)",
                     o->orient == JF_ORIENT_INPUT ? "orient" : "normal");
        return NULL;
    }
    PyObject *result = jf_py_result_new(c->n, po->o.params.monge_degree, o->nb.kind == JF_NB_AUTO,
                                        points, faces);
    if (!result) return NULL;
    /* mst orients after every normal is known: jf_estimate_blocks would
     * fit twice, so that one keeps the n results and copies them */
    const int whole = o->orient == JF_ORIENT_MST;
    jf_result *res = whole ? PyMem_RawMalloc((c->n ? c->n : 1) * sizeof *res) : NULL;
    if (whole && !res) {
        Py_DECREF(result);
        return PyErr_NoMemory();
    }
    volatile int stop = 0;
    o->cancel = check_stop;
    o->cancel_user = (void *)&stop;
    int chosen = 0; /* neighbors="auto": step 0's decision */
    o->auto_chosen = &chosen;
    est_job j = {c, o, whole ? res : NULL, result, {{0}}, JF_OK};
    jf_py_off_thread(est_work, &j, &stop);
    jf_status st = j.st;
    PyMem_RawFree(res);
    if (st != JF_OK) {
        Py_DECREF(result);
        return jf_py_status_error(st, j.err.msg);
    }
    if (chosen && jf_py_result_step0(result, chosen) < 0) {
        Py_DECREF(result);
        return NULL;
    }
    return nothing_fitted(c, result) ? NULL : result;
}

#define EST_KW "neighbors", "degree", "monge_degree", "fit", "frame", "max_cond", "orient", \
               "normals", "normal", "robust", "scales", "degree_select", "dist_weight",      \
               "robust_normals", "threads", "scanners"

/* The shared keywords, parsed into po; normals into *nrm (or NULL). */
typedef struct {
    PyObject *neighbors, *degree, *monge, *fit, *frame, *max_cond, *orient, *normals, *normal,
        *robust, *scales, *dsel, *dw, *rn, *threads, *scanners;
} est_kw;

static int parse_kw(jf_py_opts *po, est_kw *k)
{
    return jf_py_opts_parse(po, k->neighbors, k->degree, k->monge, k->fit, k->frame, k->max_cond,
                            k->orient, k->normal, k->robust, k->scales, k->dsel, k->dw, k->rn,
                            k->threads);
}

/* points and normals into c; *pa, *na own the arrays (XDECREF them). */
static int cloud_from(PyObject *points, PyObject *normals, const char *what, jf_cloud *c,
                      PyArrayObject **pa, PyArrayObject **na)
{
    *pa = jf_py_points(points, what);
    if (!*pa) return -1;
    c->n = (size_t)PyArray_DIM(*pa, 0);
    c->xyz = PyArray_DATA(*pa);
    if (normals && normals != Py_None) {
        *na = jf_py_points(normals, "normals");
        if (!*na) return -1;
        if (PyArray_DIM(*na, 0) != PyArray_DIM(*pa, 0)) {
            PyErr_Format(PyExc_ValueError, "normals: %zd rows for %zd points",
                         (Py_ssize_t)PyArray_DIM(*na, 0), (Py_ssize_t)c->n);
            return -1;
        }
        c->nrm = PyArray_DATA(*na);
    }
    return 0;
}

/* scanners= (N, 3): the scanner of each point, as scan i of N scans (the
 * library's PTX form: scan index per point, one position per scan).
 * *sa owns the positions, *scan (PyMem) the indices. */
static int scanners_from(PyObject *scanners, jf_cloud *c, PyArrayObject **sa, uint32_t **scan)
{
    if (!scanners || scanners == Py_None) return 0;
    *sa = jf_py_points(scanners, "scanners");
    if (!*sa) return -1;
    if ((size_t)PyArray_DIM(*sa, 0) != c->n) {
        PyErr_Format(PyExc_ValueError, "scanners: %zd rows for %zd points",
                     (Py_ssize_t)PyArray_DIM(*sa, 0), (Py_ssize_t)c->n);
        return -1;
    }
    if (c->n >= UINT32_MAX) { /* jf_estimate refuses it anyway */
        PyErr_SetString(PyExc_ValueError, "scanners: too many points");
        return -1;
    }
    *scan = PyMem_Malloc((c->n ? c->n : 1) * sizeof **scan);
    if (!*scan) {
        PyErr_NoMemory();
        return -1;
    }
    for (size_t i = 0; i < c->n; i++) (*scan)[i] = (uint32_t)i;
    c->scan = *scan;
    c->scanner = PyArray_DATA(*sa);
    c->nscans = c->n;
    return 0;
}

PyObject *jf_py_estimate(PyObject *self, PyObject *args, PyObject *kw)
{
    (void)self;
    static char *kwl[] = {"points", EST_KW, NULL};
    PyObject *points;
    est_kw k = {0};
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O|$OOOOOOOOOOOOOOOO:estimate", kwl, &points,
                                     &k.neighbors, &k.degree, &k.monge, &k.fit, &k.frame,
                                     &k.max_cond, &k.orient, &k.normals, &k.normal, &k.robust,
                                     &k.scales, &k.dsel, &k.dw, &k.rn, &k.threads, &k.scanners))
        return NULL;
    jf_py_opts po;
    if (parse_kw(&po, &k) || jf_py_opts_finish(&po)) return NULL;
    jf_cloud c = {0};
    PyArrayObject *pa = NULL, *na = NULL, *sa = NULL;
    uint32_t *scan = NULL;
    PyObject *r = NULL;
    if (cloud_from(points, k.normals, "points", &c, &pa, &na) == 0 &&
        scanners_from(k.scanners, &c, &sa, &scan) == 0)
        r = run(&c, &po, points, NULL);
    PyMem_Free(scan);
    Py_XDECREF(pa);
    Py_XDECREF(na);
    Py_XDECREF(sa);
    return r;
}

PyObject *jf_py_estimate_mesh(PyObject *self, PyObject *args, PyObject *kw)
{
    (void)self;
    static char *kwl[] = {"vertices", "faces", "rings", EST_KW, NULL};
    PyObject *verts, *faces, *rings = NULL;
    est_kw k = {0};
    if (!PyArg_ParseTupleAndKeywords(args, kw, "OO|O$OOOOOOOOOOOOOOOO:estimate_mesh", kwl, &verts,
                                     &faces, &rings, &k.neighbors, &k.degree, &k.monge, &k.fit,
                                     &k.frame, &k.max_cond, &k.orient, &k.normals, &k.normal,
                                     &k.robust, &k.scales, &k.dsel, &k.dw, &k.rn, &k.threads,
                                     &k.scanners))
        return NULL;
    jf_py_opts po;
    if (parse_kw(&po, &k)) return NULL;
    /* rings=None: the command's `rings` (whole rings, 2 N_n points);
     * rings=N: `rings:N`, N points.  neighbors= may still pick another
     * kind (knn on the vertices, natural). */
    if (!k.neighbors) {
        PyObject *spec;
        if (!rings || rings == Py_None) spec = PyUnicode_FromString("rings");
        else if (PyLong_Check(rings) && !PyBool_Check(rings)) spec = PyUnicode_FromFormat("rings:%S", rings);
        else
            return PyErr_Format(PyExc_TypeError, "rings: expected an int, got %s",
                                Py_TYPE(rings)->tp_name);
        if (!spec) return NULL;
        int bad = jf_py_opt(&po, "neighbors", "rings", spec, JF_PY_STR);
        Py_DECREF(spec);
        if (bad) return NULL;
    } else if (rings && rings != Py_None) {
        PyErr_SetString(PyExc_TypeError, "estimate_mesh: give rings= or neighbors=, not both");
        return NULL;
    }
    if (jf_py_opts_finish(&po)) return NULL;
    jf_cloud c = {0};
    PyArrayObject *pa = NULL, *na = NULL, *sa = NULL;
    uint32_t *scan = NULL;
    PyObject *r = NULL;
    if (cloud_from(verts, k.normals, "vertices", &c, &pa, &na) == 0 &&
        scanners_from(k.scanners, &c, &sa, &scan) == 0 && jf_py_faces(faces, c.n, &c) == 0) {
        r = run(&c, &po, verts, faces);
        jf_py_faces_free(&c);
    }
    PyMem_Free(scan);
    Py_XDECREF(pa);
    Py_XDECREF(na);
    Py_XDECREF(sa);
    return r;
}

/* jfpy.h -- shared declarations of the Python module's C files (python/src):
 *   module.c   the module: functions table, STATUS, FileError, __version__
 *   arrays.c   numpy in (points, normals, faces) and out
 *   options.c  keyword arguments -> jf_estimate_opts through the library's
 *              parser (jf_estimate_opts_set), the command's too, so values
 *              are accepted and rejected with the same words
 *   estimate.c estimate(), estimate_mesh(): GIL released, Ctrl-C polled
 *   offthread.c the OpenMP work of a call on a thread of its own
 *   result.c   the Result type and as_structured()
 *   files.c    read(), write() over the library's readers and writers
 *   fitjet.c   fit_jet(): one neighbourhood
 * Only module.c defines PY_ARRAY_UNIQUE_SYMBOL's table; the others import
 * it (NO_IMPORT_ARRAY). */
#ifndef JF_PY_H
#define JF_PY_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>

#define PY_ARRAY_UNIQUE_SYMBOL jf_py_ARRAY_API
#ifndef JF_PY_MODULE_C
#define NO_IMPORT_ARRAY
#endif
#include <numpy/arrayobject.h>

#include "jetfit.h"

/* module.c */
extern PyObject *jf_py_FileError;
/* Raises the exception matching a library status (NOMEM: MemoryError,
 * CANCELLED: keeps the pending KeyboardInterrupt, INVALID/FORMAT/TOO_LARGE:
 * ValueError, others RuntimeError) with msg (or jf_strerror). NULL. */
PyObject *jf_py_status_error(jf_status st, const char *msg);

/* arrays.c */
/* An (N, 3) float64 C-contiguous view of obj: a new reference to obj
 * itself when it already is one (no copy), else a converted copy; float
 * and integer dtypes are accepted, others raise TypeError, other shapes
 * ValueError naming `what`. */
PyArrayObject *jf_py_points(PyObject *obj, const char *what);
/* Faces: an (M, k) integer array (k >= 3) or a sequence of index
 * sequences, into jf_cloud's face_off/face_idx (PyMem_Malloc'd; free with
 * jf_py_faces_free).  0 or -1 with an exception. */
int jf_py_faces(PyObject *obj, size_t nverts, jf_cloud *c);
void jf_py_faces_free(jf_cloud *c);
/* Faces back to Python: (M, k) int32 if every face has k vertices, else
 * a list of int32 arrays. */
PyObject *jf_py_faces_out(const jf_cloud *c);
/* New uninitialised arrays. */
PyArrayObject *jf_py_empty(int nd, npy_intp d0, npy_intp d1, int type);

/* offthread.c */
/* Runs fn(arg) on a new thread (offthread.c says why) and waits, the GIL
 * released; every 0.1 s runs Python's signal handlers and sets *stop
 * (when stop is not NULL) if one raised.  Called with the GIL held. */
void jf_py_off_thread(void (*fn)(void *), void *arg, volatile int *stop);

/* options.c */
#define JF_PY_MAX_GIVEN 16
typedef struct {
    jf_estimate_opts o;
    jf_read_opts ro;  /* columns, bad_rows                              */
    char buf[512];    /* the keywords' values as text, for messages     */
    size_t used;
    struct {
        const char *param, *text;
    } given[JF_PY_MAX_GIVEN];
    int ngiven;
} jf_py_opts;
void jf_py_opts_init(jf_py_opts *po);
/* The keywords of estimate()/estimate_mesh() (neighbors as given). */
int jf_py_opts_parse(jf_py_opts *po, PyObject *neighbors, PyObject *degree,
                     PyObject *monge_degree, PyObject *fit, PyObject *frame,
                     PyObject *max_cond, PyObject *orient, PyObject *normal,
                     PyObject *robust, PyObject *scales, PyObject *degree_select,
                     PyObject *dist_weight, PyObject *robust_normals, PyObject *threads);
/* One option from a Python value: None skips it; int, float, str or a
 * sequence of numbers ("a,b,c") as text, to the library's parser of
 * parameter `param` (keyword kw in messages). */
int jf_py_opt(jf_py_opts *po, const char *param, const char *kw, PyObject *v, int kind);
enum { JF_PY_INT, JF_PY_FLOAT, JF_PY_STR, JF_PY_LIST };
int jf_py_opts_finish(jf_py_opts *po);

/* result.c */
extern PyTypeObject jf_py_ResultType;
/* A Result of n rows for Monge degree `monge` with its arrays allocated
 * (b, c None below 3, 4); sigma: the output table has the sigma column
 * (neighbors="auto"); keeps points and faces (may be NULL). */
PyObject *jf_py_result_new(size_t n, int monge, int sigma, PyObject *points, PyObject *faces);
/* Copies res[0..n-1] into the Result's arrays on `threads` OpenMP threads
 * (<= 0: all cores); no Python calls. */
void jf_py_result_fill(PyObject *result, const jf_result *res, size_t n, int threads);
/* jf_block_fn writing a block of results into the Result `result`
 * (jf_estimate_blocks' sink: straight into the arrays, no n results in
 * between; thread-safe, blocks are disjoint). */
jf_status jf_py_result_block(void *result, const uint32_t *idx, jf_result *res, size_t m);
/* The output file's columns and rows, as the command writes them. */
size_t jf_py_result_columns(PyObject *result, jf_column *cols);
int jf_py_result_monge(PyObject *result);
int jf_py_result_sigma(PyObject *result);
/* Sets the Result's auto_step0 to step 0's decision (jf_estimate_opts.
 * auto_chosen) in words; 0, or -1 with a Python error. */
int jf_py_result_step0(PyObject *result, int chosen);
/* Rows whose status has a flag of mask. */
size_t jf_py_result_count(PyObject *result, unsigned mask);

/* estimate.c, files.c, fitjet.c: module functions */
PyObject *jf_py_estimate(PyObject *self, PyObject *args, PyObject *kw);
PyObject *jf_py_estimate_mesh(PyObject *self, PyObject *args, PyObject *kw);
PyObject *jf_py_read(PyObject *self, PyObject *args, PyObject *kw);
PyObject *jf_py_write(PyObject *self, PyObject *args, PyObject *kw);
PyObject *jf_py_fit_jet(PyObject *self, PyObject *args, PyObject *kw);
extern PyTypeObject *jf_py_JetType;
int jf_py_fitjet_init(PyObject *m);

#endif

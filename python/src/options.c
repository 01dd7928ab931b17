/* options.c -- keyword arguments -> jf_estimate_opts.
 *
 * Each keyword is written as text (degree=3 -> "3", scales=[8, 16] ->
 * "8,16") and handed to the library's parser of that parameter
 * (jf_estimate_opts_set, the command's too): the same values are
 * accepted, the same defaults follow (Monge degree, max_neighbors, orient
 * input when normals are given), and a bad value raises ValueError with
 * the library's words, which name parameters ("degree=12: expected an
 * integer 1..9").  A value of the wrong Python type raises TypeError
 * naming the keyword. */
#include <math.h>

#include "jfpy.h"

static int bad(const char *kw, const char *val, const char *why)
{
    if (val && *val)
        PyErr_Format(PyExc_ValueError, "%s=%s: %s", kw, val, why ? why : "invalid value");
    else
        PyErr_Format(PyExc_ValueError, "%s: %s", kw, why ? why : "invalid value");
    return -1;
}

/* Text of a float that reads back to the same double (repr's rule). */
static int float_text(double d, char *buf, size_t len)
{
    char *s = PyOS_double_to_string(d, 'r', 0, Py_DTSF_ADD_DOT_0, NULL);
    if (!s) return -1;
    snprintf(buf, len, "%s", s);
    PyMem_Free(s);
    return 0;
}

/* One number as text; kind INT accepts int only (not bool), FLOAT int or
 * float. */
static int number_text(PyObject *v, int kind, const char *kw, char *buf, size_t len)
{
    if (PyBool_Check(v) || !(PyLong_Check(v) || (kind != JF_PY_INT && PyFloat_Check(v)))) {
        if (PyArray_IsScalar(v, Integer) || (kind != JF_PY_INT && PyArray_IsScalar(v, Floating))) {
            /* numpy scalars: as their Python value */
        } else {
            PyErr_Format(PyExc_TypeError, "%s: expected %s, got %s", kw,
                         kind == JF_PY_INT ? "an int" : "a number", Py_TYPE(v)->tp_name);
            return -1;
        }
    }
    if (PyLong_Check(v) || PyArray_IsScalar(v, Integer)) {
        /* its decimal digits, whatever its size: the parser judges them */
        PyObject *i = PyNumber_Index(v), *t = i ? PyObject_Str(i) : NULL;
        const char *u = t ? PyUnicode_AsUTF8(t) : NULL;
        if (u) snprintf(buf, len, "%s", u);
        Py_XDECREF(i);
        Py_XDECREF(t);
        return u ? 0 : -1;
    }
    double d = PyFloat_AsDouble(v);
    if (d == -1 && PyErr_Occurred()) return -1;
    return float_text(d, buf, len);
}

int jf_py_opt(jf_py_opts *po, const char *param, const char *kw, PyObject *v, int kind)
{
    if (!v || v == Py_None) return 0;
    char text[256];
    if (kind == JF_PY_STR) {
        if (!PyUnicode_Check(v)) {
            PyErr_Format(PyExc_TypeError, "%s: expected a str, got %s", kw, Py_TYPE(v)->tp_name);
            return -1;
        }
        Py_ssize_t n;
        const char *s = PyUnicode_AsUTF8AndSize(v, &n);
        if (!s) return -1;
        /* the C parser would stop at a NUL: 'knn:16\0junk' must not run
         * knn:16 (issue 33.10), as a path with a NUL is refused */
        if (strlen(s) != (size_t)n) {
            PyErr_Format(PyExc_ValueError, "%s: embedded null character", kw);
            return -1;
        }
        if ((size_t)n >= sizeof text) { /* never cut short either */
            PyErr_Format(PyExc_ValueError, "%s: value too long (%zd characters, at most %zu)", kw,
                         n, sizeof text - 1);
            return -1;
        }
        snprintf(text, sizeof text, "%s", s);
    } else if (kind == JF_PY_LIST) {
        /* scales: a sequence of ints, or one int */
        if (PyLong_Check(v)) return jf_py_opt(po, param, kw, v, JF_PY_INT);
        PyObject *seq = PySequence_Fast(v, "");
        if (!seq) {
            PyErr_Format(PyExc_TypeError, "%s: expected a sequence of ints, got %s", kw,
                         Py_TYPE(v)->tp_name);
            return -1;
        }
        size_t used = 0;
        text[0] = '\0';
        for (Py_ssize_t j = 0; j < PySequence_Fast_GET_SIZE(seq); j++) {
            char one[64];
            if (number_text(PySequence_Fast_GET_ITEM(seq, j), JF_PY_INT, kw, one, sizeof one)) {
                Py_DECREF(seq);
                return -1;
            }
            used += (size_t)snprintf(text + used, used < sizeof text ? sizeof text - used : 0,
                                     "%s%s", j ? "," : "", one);
        }
        Py_DECREF(seq);
        if (used >= sizeof text) text[sizeof text - 1] = '\0';
    } else if (number_text(v, kind, kw, text, sizeof text)) {
        return -1;
    }
    /* kept for a message of jf_py_opts_finish (the parameter's value) */
    size_t len = strlen(text) + 1;
    if (po->used + len > sizeof po->buf || po->ngiven == JF_PY_MAX_GIVEN) {
        PyErr_Format(PyExc_ValueError, "%s: value too long", kw);
        return -1;
    }
    po->given[po->ngiven].param = param;
    po->given[po->ngiven++].text = memcpy(po->buf + po->used, text, len);
    po->used += len;
    const char *why = NULL;
    jf_status st = !strcmp(param, "columns") || !strcmp(param, "bad_rows")
                       ? jf_read_opts_set(&po->ro, param, text, &why)
                       : jf_estimate_opts_set(&po->o, param, text, &why);
    return st == JF_OK ? 0 : bad(kw, text, why);
}

void jf_py_opts_init(jf_py_opts *po)
{
    jf_estimate_opts_init(&po->o);
    jf_read_opts_init(&po->ro);
    po->used = 0;
    po->ngiven = 0;
}

int jf_py_opts_finish(jf_py_opts *po)
{
    const char *param = NULL, *why = NULL;
    if (jf_estimate_opts_finish(&po->o, &param, &why) == JF_OK) return 0;
    const char *val = "";
    for (int i = 0; param && i < po->ngiven; i++)
        if (!strcmp(po->given[i].param, param)) val = po->given[i].text;
    return bad(param ? param : "options", val, why);
}

int jf_py_opts_parse(jf_py_opts *po, PyObject *neighbors, PyObject *degree,
                     PyObject *monge_degree, PyObject *fit, PyObject *frame,
                     PyObject *max_cond, PyObject *orient, PyObject *normal,
                     PyObject *robust, PyObject *scales, PyObject *degree_select,
                     PyObject *dist_weight, PyObject *robust_normals, PyObject *threads)
{
    jf_py_opts_init(po);
    /* --robust-normals is a preset that later keywords override, so it
     * goes first (the command's order of precedence) */
    if (robust_normals && robust_normals != Py_None) {
        int on = PyObject_IsTrue(robust_normals);
        if (on < 0) return -1;
        const char *why = NULL;
        if (on && jf_estimate_opts_set(&po->o, "robust_normals", NULL, &why) != JF_OK)
            return bad("robust_normals", "", why);
    }
    if (jf_py_opt(po, "neighbors", "neighbors", neighbors, JF_PY_STR) ||
        jf_py_opt(po, "degree", "degree", degree, JF_PY_INT) ||
        jf_py_opt(po, "monge_degree", "monge_degree", monge_degree, JF_PY_INT) ||
        jf_py_opt(po, "fit", "fit", fit, JF_PY_STR) ||
        jf_py_opt(po, "frame", "frame", frame, JF_PY_STR) ||
        jf_py_opt(po, "max_cond", "max_cond", max_cond, JF_PY_FLOAT) ||
        jf_py_opt(po, "orient", "orient", orient, JF_PY_STR) ||
        jf_py_opt(po, "normal", "normal", normal, JF_PY_STR) ||
        jf_py_opt(po, "robust", "robust", robust, JF_PY_STR) ||
        jf_py_opt(po, "scales", "scales", scales, JF_PY_LIST) ||
        jf_py_opt(po, "degree_select", "degree_select", degree_select, JF_PY_INT) ||
        jf_py_opt(po, "dist_weight", "dist_weight", dist_weight, JF_PY_FLOAT) ||
        jf_py_opt(po, "threads", "threads", threads, JF_PY_INT))
        return -1;
    return 0;
}

/*
 * io_ptx.c -- Leica/Faro PTX text reader (issue 13, item 3).
 *
 * design: a PTX file is one or more scans, each a header of 10 lines --
 *   cols / rows / scanner position (3) / scanner axes X, Y, Z (3 lines of
 *   3) / a 4x4 transform (4 lines of 4) -- then cols*rows point lines
 *   "x y z intensity [r g b]", one per cell of the scanner's grid.
 * Transform convention: ROW vectors, p' = [x y z 1] M, so the first three
 * rows hold the rotation, the last row the translation and the last column
 * is (0 0 0 1).  Why: the PTX description in the Leica Cyclone / Spatial
 * Analyzer manuals lists the matrix as "r11 r12 r13 0 / ... / tr1 tr2 tr3
 * 1"; a file whose last column is not (0 0 0 1) (e.g. written in the
 * column-vector convention) is refused rather than mis-registered.
 * Points are stored in the scanner's own frame and moved to the registered
 * frame by M.  The scanner position line is, per the same description, the
 * scanner's position "after any registration/transformation", i.e. already
 * in the registered frame: it is never transformed again.  But the same
 * text says M also holds the user coordinate system (UCS) active at export
 * ("the 4x4 matrix may not be identity if there is a UCS applied", e.g. an
 * unregistered scan, position line 0 0 0, exported in a UCS), which the
 * position line does not: then the points land in the UCS frame and the
 * scanner, at the origin of its own frame, lands at [0 0 0 1] M, the
 * translation row.  So c->scanner is the translation row when M is not the
 * identity (equal to the position line whenever no UCS was set, as in
 * Leica's examples), and the position line when M is the identity (points
 * exported already registered).  c->scan[i] names the scan of point i
 * (--orient scanner).
 * A point "0 0 0" is the scanner's "no return": kept as a row of NaN (the
 * pipeline marks it nonfinite) so rows stay one per grid cell.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "io_internal.h"

/* Next line holding anything but blanks (0 at the end of the file). */
static int next_nonblank(jf_text *t, const char **ls, const char **le)
{
    while (jf_text_line(t, ls, le)) {
        const char *p = *ls, *ts, *te;
        if (jf_next_token(&p, *le, 0, &ts, &te))
            return 1;
    }
    return 0;
}

/* Reads up to max numbers of [s, e) into v; returns how many, or -1 if a
 * token is not a number (or there are more than max tokens). */
static int numbers(const char *s, const char *e, double *v, int max)
{
    const char *ts, *te;
    int k = 0;
    while (jf_next_token(&s, e, 0, &ts, &te)) {
        if (k == max || !jf_parse_double(ts, te, &v[k]))
            return -1;
        k++;
    }
    return k;
}

static const char *const what[8] = {
    "scanner position", "scanner axis X", "scanner axis Y", "scanner axis Z",
    "transform row 1",  "transform row 2", "transform row 3", "transform row 4"};

/* How far the rotation rows m[0..2][0..2] are from orthonormal: the largest
 * |(R R^T - I)_ij|; *det their determinant. */
static double rotation_error(double (*m)[4], double *det)
{
    double e = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double d = m[i][0] * m[j][0] + m[i][1] * m[j][1] + m[i][2] * m[j][2] - (i == j);
            e = fabs(d) > e ? fabs(d) : e;
        }
    *det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    return e;
}

jf_status jf_read_ptx(const char *buf, size_t len, const char *name, jf_cloud *c,
                      jf_error *err)
{
    /* a UTF-8 byte order mark is not the column count */
    size_t bom = len >= 3 && !memcmp(buf, "\xEF\xBB\xBF", 3) ? 3 : 0;
    jf_text t = {buf + bom, buf + len, 0, 0};
    jf_dvec xyz = {0}, sc = {0};
    jf_uvec scan = {0};
    jf_status st = JF_OK;
    const char *ls, *le;
    size_t npts = 0, nscans = 0;
#define FAIL(s_, line_, ...)                                                \
    do {                                                                    \
        st = jf_io_fail(err, s_, name, line_, __VA_ARGS__);                 \
        goto out;                                                           \
    } while (0)
    while (next_nonblank(&t, &ls, &le)) {
        uint64_t dim[2];
        for (int d = 0; d < 2; d++) {
            if (d && !next_nonblank(&t, &ls, &le))
                FAIL(JF_ERR_FORMAT, t.line, "scan %zu: the file ends before its row count",
                     nscans + 1);
            const char *p = ls, *ts = ls, *te = ls, *xs, *xe;
            jf_next_token(&p, le, 0, &ts, &te);
            if (jf_next_token(&p, le, 0, &xs, &xe) ||
                !jf_parse_size(ts, te, JF_MAX_POINTS, &dim[d]) || dim[d] == 0)
                FAIL(JF_ERR_FORMAT, t.line, "scan %zu: expected the %s count (one integer "
                     "from 1 to %zu)", nscans + 1, d ? "row" : "column", JF_MAX_POINTS);
        }
        size_t head_line = t.line;
        double h[8][4];
        for (int r = 0; r < 8; r++) {
            int want = r < 4 ? 3 : 4;
            if (!next_nonblank(&t, &ls, &le))
                FAIL(JF_ERR_FORMAT, t.line, "scan %zu: the file ends before its %s",
                     nscans + 1, what[r]);
            if (numbers(ls, le, h[r], want) != want)
                FAIL(JF_ERR_FORMAT, t.line, "scan %zu: %s: expected %d numbers", nscans + 1,
                     what[r], want);
            for (int k = 0; k < want; k++)
                if (!isfinite(h[r][k]))
                    FAIL(JF_ERR_FORMAT, t.line, "scan %zu: %s: not finite", nscans + 1, what[r]);
        }
        double (*m)[4] = h + 4;
        if (m[0][3] != 0 || m[1][3] != 0 || m[2][3] != 0 || m[3][3] != 1)
            FAIL(JF_ERR_FORMAT, t.line, "scan %zu: transform: last column must be 0 0 0 1 "
                 "(rotation rows, then the translation row)", nscans + 1);
        /* a registration is a rigid motion: a scale, shear or mirror would
         * change the surfaces' curvature (or their side), so it is refused,
         * not guessed at; 1e-3 leaves room for matrices printed to 4 digits */
        double det, rerr = rotation_error(m, &det);
        if (!(rerr <= 1e-3) || det < 0)
            FAIL(JF_ERR_FORMAT, t.line, "scan %zu: transform: the rotation rows are %s "
                 "(|R R^T - I| = %.3g, determinant %.6g): a registration must be a rotation",
                 nscans + 1, rerr <= 1e-3 ? "a reflection" : "not orthonormal", rerr, det);
        uint64_t cnt = dim[0] * dim[1]; /* both <= 2^32: no overflow */
        /* the shortest point line, "0 0 0 0\n", has 8 bytes */
        if (cnt > JF_MAX_POINTS - npts || cnt > (uint64_t)(t.end - t.p) / 8 + 1)
            FAIL(JF_ERR_TOO_LARGE, head_line, "scan %zu: %llu x %llu points cannot fit in "
                 "the %zu bytes left (count too large or file truncated)", nscans + 1,
                 (unsigned long long)dim[0], (unsigned long long)dim[1],
                 (size_t)(t.end - t.p));
        if (nscans >= UINT32_MAX - 1)
            FAIL(JF_ERR_TOO_LARGE, head_line, "too many scans");
        if (!jf_dvec_reserve(&xyz, 3 * (npts + cnt)) || !jf_uvec_reserve(&scan, npts + cnt) ||
            !jf_dvec_reserve(&sc, 3 * (nscans + 1)))
            FAIL(JF_ERR_NOMEM, head_line, "out of memory for %llu points",
                 (unsigned long long)cnt);
        int identity = 1;
        for (int i = 0; i < 4; i++)
            for (int j = 0; j < 4; j++) identity &= m[i][j] == (i == j);
        memcpy(sc.v + 3 * nscans, identity ? h[0] : m[3], 3 * sizeof(double));
        for (uint64_t i = 0; i < cnt; i++) {
            if (!jf_text_line(&t, &ls, &le))
                FAIL(JF_ERR_FORMAT, t.line, "scan %zu: the file ends after %llu of its "
                     "%llu points", nscans + 1, (unsigned long long)i,
                     (unsigned long long)cnt);
            double v[7];
            int k = numbers(ls, le, v, 7);
            if (k != 4 && k != 7)
                FAIL(JF_ERR_FORMAT, t.line, "scan %zu: expected x y z intensity [r g b]",
                     nscans + 1);
            double *q = xyz.v + 3 * (npts + i);
            if (v[0] == 0 && v[1] == 0 && v[2] == 0) {
                q[0] = q[1] = q[2] = NAN; /* no return */
            } else {
                for (int a = 0; a < 3; a++)
                    q[a] = v[0] * m[0][a] + v[1] * m[1][a] + v[2] * m[2][a] + m[3][a];
            }
            scan.v[npts + i] = (uint32_t)nscans;
        }
        npts += (size_t)cnt;
        nscans++;
    }
    if (npts == 0)
        FAIL(JF_ERR_FORMAT, 0, "no scan in the file");
    c->n = npts;
    c->xyz = xyz.v;
    c->scan = scan.v;
    c->scanner = sc.v;
    c->nscans = nscans;
    return JF_OK;
out:
    free(xyz.v);
    free(scan.v);
    free(sc.v);
    return st;
#undef FAIL
}

/* gram_lanes.h -- gram_eig.c's kernels, written once for GL_N lanes and
 * included once per width (two lanes: SSE2; four: AVX or two SSE2
 * registers).  Each lane does exactly jf__sym_eigvals' tridiagonalisation
 * and the same Laguerre steps, so every width gives each lane the same
 * bits.  The includer defines:
 *   GL_N        lanes; GL_V, GL_M: the vector and lane-mask types
 *   GL_SEL, GL_ABS, GL_ALL(m): select, |x|, "every lane of m set"
 *   GL_SQRT(x)  IEEE square root of each lane
 *   GL_SQ_DECL, GL_SQ_PASS: an extra parameter carrying the sqrt (four
 *               lanes: simd.h's sqrt4_fn), or nothing
 *   GL_LOAD(g, i) the vector {g[0][i], ..., g[GL_N-1][i]}
 *   GL_FN(name) the name of this width's copy */
#define GL_ALWAYS static inline __attribute__((always_inline))

/* T = H A H for the GL_N n x n row-major matrices in the lanes of a
 * (destroyed): diagonal d, squared sub-diagonal e (e[n-1] = 0).  A lane
 * with a zero column keeps its values (mask). */
GL_ALWAYS void GL_FN(tridiag)(GL_V *a, size_t n, GL_V *d, GL_V *e GL_SQ_DECL)
{
    const GL_V zero = {0.0};
    for (size_t k = 0; k + 2 < n; k++) {
        const size_t m = n - k - 1, o = k + 1;
        GL_V v[GE_MAX], p[GE_MAX], nx = zero;
        for (size_t i = 0; i < m; i++) {
            v[i] = a[(o + i) * n + k];
            nx += v[i] * v[i];
        }
        d[k] = a[k * n + k];
        e[k] = nx;
        const GL_M skip = (GL_M)(nx == zero); /* that lane's `continue` */
        if (GL_ALL(skip)) continue;
        const GL_V x0 = v[0], rt = GL_SQRT(nx);
        const GL_V alpha = GL_SEL((GL_M)(x0 > zero), -rt, rt);
        v[0] = x0 - alpha;
        const GL_V vv = 2.0 * (nx - x0 * alpha), beta = 2.0 / vv;
        GL_V vp = zero;
        for (size_t i = 0; i < m; i++) {
            const GL_V *ai = a + (o + i) * n + o;
            GL_V t = zero;
            for (size_t j = 0; j < m; j++) t += ai[j] * v[j];
            p[i] = beta * t;
            vp += v[i] * p[i];
        }
        const GL_V kq = vp / vv;
        for (size_t i = 0; i < m; i++) p[i] -= kq * v[i];
        for (size_t i = 0; i < m; i++) {
            GL_V *ai = a + (o + i) * n + o;
            for (size_t j = 0; j < m; j++) ai[j] = GL_SEL(skip, ai[j], ai[j] - (v[i] * p[j] + p[i] * v[j]));
        }
    }
    if (n >= 2) {
        const GL_V t = a[(n - 1) * n + n - 2];
        d[n - 2] = a[(n - 2) * n + n - 2];
        e[n - 2] = t * t;
    }
    d[n - 1] = a[(n - 1) * n + n - 1];
    e[n - 1] = zero;
}

/* det(T - xI) and its first two derivatives at x (per lane). */
GL_ALWAYS void GL_FN(charpoly)(const GL_V *d, const GL_V *e, size_t n, GL_V x, GL_V *p, GL_V *p1,
                               GL_V *p2)
{
    const GL_V zero = {0.0};
    GL_V a = d[0] - x, a1 = zero - 1.0, a2 = zero;
    GL_V b = zero + 1.0, b1 = zero, b2 = zero;
    for (size_t k = 1; k < n; k++) {
        const GL_V t = d[k] - x, s = e[k - 1];
        const GL_V c = t * a - s * b, c1 = t * a1 - s * b1 - a, c2 = t * a2 - s * b2 - 2.0 * a1;
        b = a, b1 = a1, b2 = a2;
        a = c, a1 = c1, a2 = c2;
    }
    *p = a, *p1 = a1, *p2 = a2;
}

/* One Laguerre step for each lane of x (hi: toward the largest root from
 * above, else the smallest from below).  A lane stays put and is marked
 * done when it is already, when det(T - xI) is 0 or has the sign of the
 * roots' other side (rounding carried x across the root), or when the
 * step makes no progress in its direction; the lane is done after a
 * step of at most GE_TOL. */
GL_ALWAYS GL_V GL_FN(laguerre)(const GL_V *d, const GL_V *e, size_t n, GL_V x, int hi,
                               GL_M *done GL_SQ_DECL)
{
    GL_V p, p1, p2;
    GL_FN(charpoly)(d, e, n, x, &p, &p1, &p2);
    const GL_V zero = {0.0}, nn = zero + (double)n, one = zero + 1.0;
    /* outside the roots, det(T - xI) > 0 below them, (-1)^n p > 0 above */
    const GL_V sp = hi && (n & 1) ? -p : p;
    const GL_M live = ~*done & (GL_M)(sp > zero);
    const GL_V ps = GL_SEL(live, p, one);
    const GL_V g = p1 / ps, h = g * g - p2 / ps;
    GL_V disc = (nn - 1.0) * (nn * h - g * g);
    disc = GL_SQRT(GL_SEL((GL_M)(disc > zero), disc, zero));
    const GL_V den = hi ? g + disc : g - disc;
    const GL_V xn = x - nn / GL_SEL((GL_M)(den != zero), den, one);
    const GL_M ok = live & (GL_M)(den != zero) & (GL_M)(hi ? xn < x : xn > x);
    /* a step below the evaluation's rounding (T is scaled to norm ~1)
     * ends it: past that point the steps only wander in the noise */
    *done = ~ok | (GL_M)(GL_ABS(xn - x) <= zero + GE_TOL);
    return GL_SEL(ok, xn, x);
}

/* Largest and smallest eigenvalue of each lane's T; rc[lane] -1 when the
 * iteration did not settle (not finite, or GE_ITERS steps). */
GL_ALWAYS void GL_FN(extremes)(GL_V *d, GL_V *e, size_t n, GL_V *lmax, GL_V *lmin,
                               int rc[GL_N] GL_SQ_DECL)
{
    /* Gershgorin's interval, and a power of two bringing it to ~1 so the
     * recurrence neither over- nor underflows (exact scaling) */
    GL_V ub = d[0], lb = d[0], bprev = {0.0};
    for (size_t k = 0; k < n; k++) {
        const GL_V b = GL_SQRT(e[k]); /* |T[k+1][k]| */
        const GL_V hi = d[k] + (bprev + b), lo = d[k] - (bprev + b);
        ub = GL_SEL((GL_M)(hi > ub), hi, ub);
        lb = GL_SEL((GL_M)(lo < lb), lo, lb);
        bprev = b;
    }
    GL_V sc, isc;
    for (int L = 0; L < GL_N; L++) {
        int q = 0;
        frexp(fmax(fabs(ub[L]), fabs(lb[L])), &q);
        sc[L] = ldexp(1.0, -q);
        isc[L] = ldexp(1.0, q);
    }
    for (size_t k = 0; k < n; k++) {
        d[k] *= sc;
        e[k] *= sc * sc;
    }
    GL_V xh = ub * sc, xl = lb * sc;
    GL_M dh = {0}, dl = {0};
    for (int it = 0; it < GE_ITERS && !(GL_ALL(dh) && GL_ALL(dl)); it++) {
        /* a side done in every lane would only keep them: skipped */
        if (!GL_ALL(dh)) xh = GL_FN(laguerre)(d, e, n, xh, 1, &dh GL_SQ_PASS);
        if (!GL_ALL(dl)) xl = GL_FN(laguerre)(d, e, n, xl, 0, &dl GL_SQ_PASS);
    }
    *lmax = xh * isc;
    *lmin = xl * isc;
    for (int L = 0; L < GL_N; L++)
        rc[L] = dh[L] && dl[L] && isfinite((*lmax)[L]) && isfinite((*lmin)[L]) ? 0 : -1;
}

/* The extremes of the Gram matrices g[0..GL_N-1] (cols x cols, cols <=
 * GE_MAX), lane by lane, into hi[L], lo[L]; rc[L] as above. */
GL_ALWAYS void GL_FN(extremes_of)(const double *const g[GL_N], size_t cols, double hi[GL_N],
                                  double lo[GL_N], int rc[GL_N] GL_SQ_DECL)
{
    GL_V a[GE_MAX * GE_MAX], d[GE_MAX], e[GE_MAX], h, l;
    for (size_t i = 0; i < cols * cols; i++) a[i] = GL_LOAD(g, i);
    GL_FN(tridiag)(a, cols, d, e GL_SQ_PASS);
    GL_FN(extremes)(d, e, cols, &h, &l, rc GL_SQ_PASS);
    for (int L = 0; L < GL_N; L++) hi[L] = h[L], lo[L] = l[L];
}

/* Degree 2 (6 columns) and 3 (10) with the size a constant, which the
 * compiler unrolls: the same operations in the same order, the same bits. */
GL_ALWAYS void GL_FN(gram_extremes)(const double *const g[GL_N], size_t cols, double hi[GL_N],
                                    double lo[GL_N], int rc[GL_N] GL_SQ_DECL)
{
    if (cols == 6 && jf__fixed_sizes) GL_FN(extremes_of)(g, 6, hi, lo, rc GL_SQ_PASS);
    else if (cols == 10 && jf__fixed_sizes) GL_FN(extremes_of)(g, 10, hi, lo, rc GL_SQ_PASS);
    else GL_FN(extremes_of)(g, cols, hi, lo, rc GL_SQ_PASS);
}

#undef GL_ALWAYS

/* surf_sample.c -- samplings of the test surfaces (random clouds, the
 * §6.1 perturbed triangulated grids, closed UV meshes) and the noise
 * models of `jetfit generate` (Gaussian, PCPNet's uniform "white" noise,
 * outliers).  Every random draw comes from the caller's jf_rng, in a fixed
 * order, so a seed reproduces the sample bit for bit. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "surfaces.h"

#define MAX_VERTS 50000000u /* refuse absurd grids before allocating */

void jf_sample_free(jf_sample *s)
{
    if (!s)
        return;
    free(s->uv);
    free(s->xyz);
    free(s->truth);
    free(s->face_off);
    free(s->face_idx);
    memset(s, 0, sizeof *s);
}

static jf_status alloc_sample(jf_sample *s, size_t n, size_t nfaces)
{
    memset(s, 0, sizeof *s);
    s->n = n;
    s->uv = malloc(2 * n * sizeof *s->uv);
    s->xyz = malloc(3 * n * sizeof *s->xyz);
    s->truth = malloc(n * sizeof *s->truth);
    s->nfaces = nfaces;
    if (nfaces) {
        s->face_off = malloc((nfaces + 1) * sizeof *s->face_off);
        s->face_idx = malloc(3 * nfaces * sizeof *s->face_idx);
    }
    if (!s->uv || !s->xyz || !s->truth ||
        (nfaces && (!s->face_off || !s->face_idx))) {
        jf_sample_free(s);
        return JF_ERR_NOMEM;
    }
    if (nfaces)
        for (size_t f = 0; f <= nfaces; f++)
            s->face_off[f] = 3 * f;
    return JF_OK;
}

/* Sets vertex i from parameters (u, v): position and exact truth. */
static void set_vertex(jf_sample *s, jf_surface surf, size_t i, double u,
                       double v)
{
    s->uv[2 * i] = u;
    s->uv[2 * i + 1] = v;
    jf_surface_truth(surf, u, v, &s->truth[i]);
    memcpy(s->xyz + 3 * i, s->truth[i].xyz, sizeof(double) * 3);
}

/* The x range of the surface, for the density models. */
static void x_range(jf_surface s, double *x0, double *x1)
{
    double lo[2], hi[2], X[3];
    if (jf_surface_is_graph(s)) {
        jf_surface_domain(s, lo, hi);
        *x0 = lo[0];
        *x1 = hi[0];
    } else {
        /* widest point on +x (torus: phi = 0, on the outer equator) */
        jf_surface_point(s, s == JF_SURF_TORUS ? 0.0 : M_PI / 2, 0.0, X);
        *x0 = -X[0];
        *x1 = X[0];
    }
}

static int keep_for_density(jf_density d, double t, jf_rng *rng)
{
    if (d == JF_DENSITY_GRADIENT)
        return jf_rng_uniform(rng) < 0.05 + 0.95 * t;
    if (d == JF_DENSITY_STRIPES) {
        int stripe = (int)floor(10.0 * t);
        if (stripe & 1)
            return jf_rng_uniform(rng) < 0.1;
    }
    return 1;
}

jf_status jf_sample_random(jf_surface surf, size_t n, jf_density d,
                           jf_rng *rng, jf_sample *out)
{
    if ((unsigned)surf >= JF_SURF_COUNT || n == 0 || n > MAX_VERTS)
        return n > MAX_VERTS ? JF_ERR_TOO_LARGE : JF_ERR_INVALID;
    jf_status st = alloc_sample(out, n, 0);
    if (st)
        return st;
    double lo[2], hi[2], x0, x1;
    jf_surface_domain(surf, lo, hi);
    x_range(surf, &x0, &x1);
    size_t kept = 0;
    while (kept < n) {
        double u, v, X[3];
        if (surf == JF_SURF_SPHERE || surf == JF_SURF_ELLIPSOID) {
            /* area-uniform on the sphere: z uniform (Archimedes) */
            u = acos(2.0 * jf_rng_uniform(rng) - 1.0);
            v = 2.0 * M_PI * jf_rng_uniform(rng);
            if (surf == JF_SURF_ELLIPSOID) {
                /* ellipsoid area element over the sphere's, max ab */
                double a = 1.0, b = 0.75, c = 0.5, st_ = sin(u);
                double g = sqrt(pow(b * c * st_ * cos(v), 2) +
                                pow(a * c * st_ * sin(v), 2) +
                                pow(a * b * cos(u), 2));
                if (jf_rng_uniform(rng) * a * b >= g)
                    continue;
            }
        } else if (surf == JF_SURF_TORUS) {
            /* area element (R + r cos psi) dphi dpsi, at most R + r */
            u = 2.0 * M_PI * jf_rng_uniform(rng);
            v = 2.0 * M_PI * jf_rng_uniform(rng);
            if (jf_rng_uniform(rng) * 1.4 >= 1.0 + 0.4 * cos(v))
                continue;
        } else {
            u = lo[0] + (hi[0] - lo[0]) * jf_rng_uniform(rng);
            v = lo[1] + (hi[1] - lo[1]) * jf_rng_uniform(rng);
        }
        if (d != JF_DENSITY_UNIFORM) {
            jf_surface_point(surf, u, v, X);
            double t = (X[0] - x0) / (x1 - x0);
            if (!keep_for_density(d, fmin(fmax(t, 0.0), 0.999999), rng))
                continue;
        }
        set_vertex(out, surf, kept++, u, v);
    }
    return JF_OK;
}

double jf_sample_grid_h_for(jf_surface s, size_t n)
{
    double lo[2], hi[2];
    if (n < 4)
        n = 4;
    if (jf_surface_is_graph(s)) {
        jf_surface_domain(s, lo, hi);
        return (hi[0] - lo[0]) / (sqrt((double)n) - 1.0);
    }
    if (s == JF_SURF_CYLINDER) /* (2 pi R / h)(2 / h) vertices */
        return sqrt(4.0 * M_PI * 0.5 / (double)n);
    if (s == JF_SURF_TORUS) /* (2 pi 1 / h)(2 pi 0.4 / h) vertices */
        return 2.0 * M_PI * sqrt(0.4 / (double)n);
    return M_PI * sqrt(2.0 / (double)n); /* (pi / h)(2 pi / h) */
}

/* Triangles of an nu x nv vertex grid (vertex (i,j) = j*nu + i), split
 * along the (i,j)-(i+1,j+1) diagonal, counter-clockwise in (u,v);
 * wrap_u joins column nu-1 to column 0 (a seam), wrap_v row nv-1 to row 0
 * (the torus). */
static void grid_faces2(uint32_t *idx, size_t nu, size_t nv, int wrap_u,
                        int wrap_v, uint32_t base)
{
    size_t f = 0, cols = wrap_u ? nu : nu - 1, rows = wrap_v ? nv : nv - 1;
    for (size_t j = 0; j < rows; j++)
        for (size_t i = 0; i < cols; i++) {
            uint32_t i1 = (uint32_t)((i + 1) % nu);
            size_t j1 = (j + 1) % nv;
            uint32_t a = base + (uint32_t)(j * nu + i);
            uint32_t b = base + (uint32_t)(j * nu + i1);
            uint32_t c = base + (uint32_t)(j1 * nu + i);
            uint32_t d = base + (uint32_t)(j1 * nu + i1);
            uint32_t t[6] = {a, b, d, a, d, c};
            memcpy(idx + 3 * f, t, sizeof t);
            f += 2;
        }
}

static void grid_faces(uint32_t *idx, size_t nu, size_t nv, int wrap_u,
                       uint32_t base)
{
    grid_faces2(idx, nu, nv, wrap_u, 0, base);
}

jf_status jf_sample_graph_grid(jf_surface s, double h, int m, double perturb,
                               jf_rng *rng, jf_sample *out)
{
    if (!jf_surface_is_graph(s) || !(h > 0) || m < 1 || !(perturb >= 0))
        return JF_ERR_INVALID;
    size_t nu = 2 * (size_t)m + 1;
    if (nu * nu > MAX_VERTS)
        return JF_ERR_TOO_LARGE;
    jf_status st = alloc_sample(out, nu * nu, 2 * (nu - 1) * (nu - 1));
    if (st)
        return st;
    for (size_t j = 0; j < nu; j++)
        for (size_t i = 0; i < nu; i++) {
            /* §6.1: (u + delta h, v + delta' h), delta in [0, perturb] */
            double du = perturb * jf_rng_uniform(rng);
            double dv = perturb * jf_rng_uniform(rng);
            set_vertex(out, s, j * nu + i, ((double)i - m + du) * h,
                       ((double)j - m + dv) * h);
        }
    grid_faces(out->face_idx, nu, nu, 0, 0);
    return JF_OK;
}

/* Closed UV sphere/ellipsoid: north pole, rings 1..m-1, south pole. */
static jf_status uv_sphere(jf_surface s, double h, double perturb,
                           int with_faces, jf_rng *rng, jf_sample *out)
{
    double mm = fmax(2.0, round(M_PI / h)), nn = fmax(3.0, round(2 * M_PI / h));
    if ((mm - 1) * nn + 2 > MAX_VERTS)
        return JF_ERR_TOO_LARGE;
    size_t m = (size_t)mm, np = (size_t)nn, n = (m - 1) * np + 2;
    size_t nf = with_faces ? 2 * np + 2 * np * (m - 2) : 0;
    jf_status st = alloc_sample(out, n, nf);
    if (st)
        return st;
    double dt = M_PI / (double)m, dp = 2 * M_PI / (double)np;
    set_vertex(out, s, 0, 0.0, 0.0);
    for (size_t i = 1; i < m; i++)
        for (size_t j = 0; j < np; j++) {
            double du = perturb * jf_rng_uniform(rng);
            double dv = perturb * jf_rng_uniform(rng);
            set_vertex(out, s, 1 + (i - 1) * np + j, ((double)i + du) * dt,
                       ((double)j + dv) * dp);
        }
    set_vertex(out, s, n - 1, M_PI, 0.0);
    if (!with_faces)
        return JF_OK;
    uint32_t *idx = out->face_idx, S = (uint32_t)(n - 1);
    size_t f = 0;
    for (size_t j = 0; j < np; j++) { /* fans, outward (see grid_faces) */
        uint32_t a = (uint32_t)(1 + j), b = (uint32_t)(1 + (j + 1) % np);
        uint32_t la = (uint32_t)(1 + (m - 2) * np + j);
        uint32_t lb = (uint32_t)(1 + (m - 2) * np + (j + 1) % np);
        uint32_t t[6] = {0, a, b, la, S, lb};
        memcpy(idx + 3 * f, t, sizeof t);
        f += 2;
    }
    /* rings as a grid with v = ring index, u = phi, wrapping; (theta,
     * phi) orientation is outward, so swap the grid's (u,v) order */
    grid_faces(idx + 3 * f, np, m - 1, 1, 1);
    for (size_t k = f; k < nf; k++) { /* reverse: (u,v) = (phi,theta) */
        uint32_t tmp = idx[3 * k + 1];
        idx[3 * k + 1] = idx[3 * k + 2];
        idx[3 * k + 2] = tmp;
    }
    return JF_OK;
}

jf_status jf_sample_grid(jf_surface s, double h, double perturb,
                         int with_faces, jf_rng *rng, jf_sample *out)
{
    if ((unsigned)s >= JF_SURF_COUNT || !(h > 0) || !(perturb >= 0) ||
        !isfinite(h))
        return JF_ERR_INVALID;
    if (s == JF_SURF_SPHERE || s == JF_SURF_ELLIPSOID)
        return uv_sphere(s, h, perturb, with_faces, rng, out);
    double lo[2], hi[2];
    jf_surface_domain(s, lo, hi);
    size_t nu, nv;
    double hu = h, hv = h;
    int wrap = 0, wrap_v = 0;
    if (s == JF_SURF_TORUS) { /* phi: arc h on the central circle (R = 1),
                                 psi: arc h on the tube (r = 0.4) */
        double ku = fmax(3.0, round(2 * M_PI / h)), kv = fmax(3.0, round(2 * M_PI * 0.4 / h));
        if (ku * kv > MAX_VERTS)
            return JF_ERR_TOO_LARGE;
        nu = (size_t)ku, nv = (size_t)kv;
        hu = 2 * M_PI / ku, hv = 2 * M_PI / kv;
        wrap = wrap_v = 1;
    } else if (s == JF_SURF_CYLINDER) { /* u = phi (arc step h on radius 0.5) */
        double k = fmax(3.0, round(2 * M_PI * 0.5 / h));
        if (k > MAX_VERTS)
            return JF_ERR_TOO_LARGE;
        nu = (size_t)k;
        hu = 2 * M_PI / (double)nu;
        wrap = 1;
    } else {
        double k = floor((hi[0] - lo[0]) / h + 1e-9) + 1;
        if (k > MAX_VERTS)
            return JF_ERR_TOO_LARGE;
        nu = (size_t)k;
    }
    if (!wrap_v) {
        double kv = floor((hi[1] - lo[1]) / h + 1e-9) + 1;
        if (kv * (double)nu > MAX_VERTS)
            return JF_ERR_TOO_LARGE;
        nv = (size_t)kv;
    }
    if (nu < 2 || nv < 2)
        return JF_ERR_INVALID;
    size_t nf = with_faces ? 2 * (wrap ? nu : nu - 1) * (wrap_v ? nv : nv - 1) : 0;
    jf_status st = alloc_sample(out, nu * nv, nf);
    if (st)
        return st;
    for (size_t j = 0; j < nv; j++)
        for (size_t i = 0; i < nu; i++) {
            double du = perturb * jf_rng_uniform(rng);
            double dv = perturb * jf_rng_uniform(rng);
            set_vertex(out, s, j * nu + i, lo[0] + ((double)i + du) * hu,
                       lo[1] + ((double)j + dv) * hv);
        }
    if (with_faces)
        grid_faces2(out->face_idx, nu, nv, wrap, wrap_v, 0);
    return JF_OK;
}

/* ---------------- noise models ---------------- */
static void bbox(const double *xyz, size_t n, double lo[3], double hi[3])
{
    for (int k = 0; k < 3; k++) {
        lo[k] = INFINITY;
        hi[k] = -INFINITY;
    }
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], xyz[3 * i + k]);
            hi[k] = fmax(hi[k], xyz[3 * i + k]);
        }
}

void jf_bbox_measure(const double *xyz, size_t n, double *diag,
                     double *largest_side)
{
    double lo[3], hi[3];
    bbox(xyz, n, lo, hi);
    double d2 = 0, big = 0;
    for (int k = 0; k < 3; k++) {
        double e = n ? hi[k] - lo[k] : 0.0;
        d2 += e * e;
        big = fmax(big, e);
    }
    *diag = sqrt(d2);
    *largest_side = big;
}

void jf_noise_gauss(jf_sample *s, double sigma_frac, jf_rng *rng)
{
    double diag, side;
    jf_bbox_measure(s->xyz, s->n, &diag, &side);
    double sigma = sigma_frac * diag;
    for (size_t i = 0; i < 3 * s->n; i++)
        s->xyz[i] += sigma * jf_rng_gauss(rng);
}

void jf_noise_uniform(jf_sample *s, double frac, jf_rng *rng)
{
    double diag, side;
    jf_bbox_measure(s->xyz, s->n, &diag, &side);
    for (size_t i = 0; i < 3 * s->n; i++)
        s->xyz[i] += (jf_rng_uniform(rng) - 0.5) * frac * side;
}

void jf_noise_outliers(jf_sample *s, double frac, jf_rng *rng)
{
    double lo[3], hi[3];
    bbox(s->xyz, s->n, lo, hi);
    size_t want = (size_t)llround(fmin(fmax(frac, 0.0), 1.0) * (double)s->n);
    size_t chosen = 0;
    /* Knuth's selection sampling: each subset of size `want` equally
     * likely, in one pass, without a scratch array */
    for (size_t i = 0; i < s->n && chosen < want; i++) {
        if ((double)(s->n - i) * jf_rng_uniform(rng) >= (double)(want - chosen))
            continue;
        jf_truth *t = &s->truth[i];
        for (int k = 0; k < 3; k++) {
            s->xyz[3 * i + k] = lo[k] + (hi[k] - lo[k]) * jf_rng_uniform(rng);
            t->xyz[k] = s->xyz[3 * i + k];
            t->normal[k] = t->d1[k] = t->d2[k] = NAN;
        }
        t->k1 = t->k2 = NAN;
        t->valid = 0;
        chosen++;
    }
    s->noutliers = chosen;
}

/* test_surfaces.c -- the exact truth of src/synth/surfaces.c against central
 * finite differences of each parametrisation (an independent route: the
 * truth uses analytic derivatives or the implicit equation), known
 * closed-form values, and the samplings' invariants. */
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "surfaces.h"
#include "jf_test.h"

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double a[3], const double b[3], double c[3])
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

/* Normal, k1 >= k2 and d1 of X at (u,v) from central differences:
 * I, II and the Weingarten map W = I^-1 II (Table 1), eigen by hand. */
static void fd_truth(jf_surface s, double u, double v, double n[3],
                     double *k1, double *k2, double d1[3])
{
    const double e = 1e-4;
    double P[3][3][3]; /* P[i][j] = X(u + (i-1)e, v + (j-1)e) */
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            jf_surface_point(s, u + (i - 1) * e, v + (j - 1) * e, P[i][j]);
    double Xu[3], Xv[3], Xuu[3], Xuv[3], Xvv[3];
    for (int k = 0; k < 3; k++) {
        Xu[k] = (P[2][1][k] - P[0][1][k]) / (2 * e);
        Xv[k] = (P[1][2][k] - P[1][0][k]) / (2 * e);
        Xuu[k] = (P[2][1][k] - 2 * P[1][1][k] + P[0][1][k]) / (e * e);
        Xvv[k] = (P[1][2][k] - 2 * P[1][1][k] + P[1][0][k]) / (e * e);
        Xuv[k] = (P[2][2][k] - P[2][0][k] - P[0][2][k] + P[0][0][k]) /
                 (4 * e * e);
    }
    cross3(Xu, Xv, n);
    double l = sqrt(dot3(n, n));
    for (int k = 0; k < 3; k++)
        n[k] /= l;
    double E = dot3(Xu, Xu), F = dot3(Xu, Xv), G = dot3(Xv, Xv);
    double L = dot3(Xuu, n), M = dot3(Xuv, n), N = dot3(Xvv, n);
    double det = E * G - F * F;
    double W[2][2] = {{(G * L - F * M) / det, (G * M - F * N) / det},
                      {(E * M - F * L) / det, (E * N - F * M) / det}};
    double H = 0.5 * (W[0][0] + W[1][1]);
    double K = W[0][0] * W[1][1] - W[0][1] * W[1][0];
    double r = sqrt(fmax(H * H - K, 0.0));
    *k1 = H + r;
    *k2 = H - r;
    /* null vector of W - k1 I, the better row */
    double a, b;
    if (fabs(W[0][0] - *k1) + fabs(W[0][1]) > fabs(W[1][0]) + fabs(W[1][1] - *k1)) {
        a = -W[0][1];
        b = W[0][0] - *k1;
    } else {
        a = W[1][1] - *k1;
        b = -W[1][0];
    }
    for (int k = 0; k < 3; k++)
        d1[k] = a * Xu[k] + b * Xv[k];
    l = sqrt(dot3(d1, d1));
    for (int k = 0; k < 3; k++)
        d1[k] /= l;
}

static void check_point(jf_surface s, double u, double v)
{
    jf_truth t;
    double n[3], k1, k2, d1[3], c[3];
    jf_surface_truth(s, u, v, &t);
    fd_truth(s, u, v, n, &k1, &k2, d1);
    ck_assert_int_eq(t.valid, 1);
    double scale = fmax(1.0, fmax(fabs(k1), fabs(k2)));
    cross3(n, t.normal, c);
    ck_assert_msg(dot3(n, t.normal) > 0 && sqrt(dot3(c, c)) < 1e-6,
                  "%s normal at (%g,%g)", jf_surface_name(s), u, v);
    ck_assert_msg(fabs(t.k1 - k1) < 1e-6 * scale && fabs(t.k2 - k2) < 1e-6 * scale,
                  "%s (%g,%g): k1 %.12g vs fd %.12g, k2 %.12g vs %.12g",
                  jf_surface_name(s), u, v, t.k1, k1, t.k2, k2);
    if (t.k1 - t.k2 > 1e-3 * scale) { /* directions well defined */
        ck_assert_msg(fabs(fabs(dot3(d1, t.d1)) - 1.0) < 1e-6,
                      "%s d1 at (%g,%g)", jf_surface_name(s), u, v);
        cross3(t.d1, t.d2, c);
        for (int k = 0; k < 3; k++)
            ck_assert(fabs(c[k] - t.normal[k]) < 1e-12);
        ck_assert(fabs(dot3(t.d1, t.normal)) < 1e-12);
    }
}

START_TEST(truth_matches_finite_differences)
{
    jf_rng r;
    jf_rng_seed(&r, 7);
    for (int s = 0; s < JF_SURF_COUNT; s++) {
        double lo[2], hi[2];
        jf_surface_domain((jf_surface)s, lo, hi);
        for (int i = 0; i < 40; i++) {
            double u = lo[0] + (hi[0] - lo[0]) * (0.02 + 0.96 * jf_rng_uniform(&r));
            double v = lo[1] + (hi[1] - lo[1]) * (0.02 + 0.96 * jf_rng_uniform(&r));
            if (s == JF_SURF_REVOLUTION && hypot(u, v) < 0.1)
                continue; /* the cone point and its steep neighbourhood */
            check_point((jf_surface)s, u, v);
        }
    }
}
END_TEST

START_TEST(closed_form_values)
{
    jf_truth t;
    /* sphere, outward normal: k1 = k2 = -1, umbilic: d NaN */
    jf_surface_truth(JF_SURF_SPHERE, 0.7, 2.0, &t);
    ck_assert(fabs(t.k1 + 1) < 1e-14 && fabs(t.k2 + 1) < 1e-14);
    ck_assert(isnan(t.d1[0]) && isnan(t.d2[2]));
    ck_assert(fabs(dot3(t.normal, t.xyz) - 1) < 1e-14);
    /* sphere poles, where the parametrisation degenerates */
    jf_surface_truth(JF_SURF_SPHERE, 0.0, 0.0, &t);
    ck_assert(t.normal[2] == 1.0 && fabs(t.k1 + 1) < 1e-14);
    /* cylinder radius 0.5: k1 = 0 along the axis, k2 = -2 */
    jf_surface_truth(JF_SURF_CYLINDER, 1.0, 0.3, &t);
    ck_assert(fabs(t.k1) < 1e-14 && fabs(t.k2 + 2) < 1e-14);
    ck_assert(fabs(fabs(t.d1[2]) - 1) < 1e-14);
    /* paraboloid z = 2x^2 + y^2 at 0: k1 = 4 along x, k2 = 2 */
    jf_surface_truth(JF_SURF_PARABOLOID, 0.0, 0.0, &t);
    ck_assert(fabs(t.k1 - 4) < 1e-14 && fabs(t.k2 - 2) < 1e-14);
    ck_assert(fabs(fabs(t.d1[0]) - 1) < 1e-14);
    /* its umbilics: (+-1/4, 0), W^2 = 2, k = 2/sqrt(2) */
    jf_surface_truth(JF_SURF_PARABOLOID, 0.25, 0.0, &t);
    ck_assert(fabs(t.k1 - sqrt(2.0)) < 1e-13 && fabs(t.k2 - sqrt(2.0)) < 1e-13);
    ck_assert(isnan(t.d1[0]));
    /* ellipsoid vertex (a,0,0): k = -a/b^2 and -a/c^2 */
    jf_surface_truth(JF_SURF_ELLIPSOID, M_PI / 2, 0.0, &t);
    ck_assert(fabs(t.k1 + 1 / 0.5625) < 1e-13 && fabs(t.k2 + 4) < 1e-13);
    /* exp graph at 0: f = 0.1, fx = 0.2, fy = 0.1, fxx = 0.4, fxy = 0.2,
     * fyy = -0.1: K = (fxx fyy - fxy^2)/W^4 */
    jf_surface_truth(JF_SURF_EXP, 0.0, 0.0, &t);
    double W2 = 1 + 0.04 + 0.01;
    ck_assert(fabs(t.k1 * t.k2 - (0.4 * -0.1 - 0.04) / (W2 * W2)) < 1e-14);
    /* revolution: the cone point has no truth */
    jf_surface_truth(JF_SURF_REVOLUTION, 0.0, 0.0, &t);
    ck_assert(t.valid == 0 && isnan(t.k1) && isnan(t.normal[0]));
}
END_TEST

START_TEST(random_samples_lie_on_surface)
{
    jf_rng r;
    jf_sample s;
    jf_rng_seed(&r, 1);
    ck_assert_int_eq(jf_sample_random(JF_SURF_ELLIPSOID, 2000, JF_DENSITY_UNIFORM, &r, &s), JF_OK);
    for (size_t i = 0; i < s.n; i++) {
        const double *p = s.xyz + 3 * i;
        double F = p[0] * p[0] + p[1] * p[1] / 0.5625 + p[2] * p[2] / 0.25;
        ck_assert(fabs(F - 1) < 1e-12);
    }
    jf_sample_free(&s);
    /* density gradient: more points at +x than at -x (keep 0.05..1) */
    jf_rng_seed(&r, 2);
    ck_assert_int_eq(jf_sample_random(JF_SURF_PARABOLOID, 4000, JF_DENSITY_GRADIENT, &r, &s), JF_OK);
    size_t left = 0;
    for (size_t i = 0; i < s.n; i++)
        left += s.xyz[3 * i] < 0;
    ck_assert_msg(left < s.n / 3, "left %zu", left); /* expected ~26% */
    jf_sample_free(&s);
}
END_TEST

/* Normal of face f of s (not unit): (v1 - v0) x (v2 - v0). */
static void face_normal(const jf_sample *s, size_t f, double nf[3])
{
    const uint32_t *t = s->face_idx + 3 * f;
    double e1[3], e2[3];
    for (int k = 0; k < 3; k++) {
        e1[k] = s->xyz[3 * t[1] + k] - s->xyz[3 * t[0] + k];
        e2[k] = s->xyz[3 * t[2] + k] - s->xyz[3 * t[0] + k];
    }
    cross3(e1, e2, nf);
}

/* Every edge in exactly two faces (closed) and outward face normals. */
START_TEST(closed_meshes_are_closed_and_outward)
{
    jf_surface which[2] = {JF_SURF_SPHERE, JF_SURF_ELLIPSOID};
    for (int w = 0; w < 2; w++) {
        jf_rng r;
        jf_sample s;
        jf_rng_seed(&r, 3);
        /* unperturbed: the §6.1 perturbation may flip a thin triangle */
        ck_assert_int_eq(jf_sample_grid(which[w], 0.3, 0.0, 1, &r, &s), JF_OK);
        ck_assert_int_eq((long)s.n - (long)(3 * s.nfaces / 2) + (long)s.nfaces, 2);
        int *cnt = calloc(s.n * s.n, sizeof *cnt);
        for (size_t f = 0; f < s.nfaces; f++) {
            const uint32_t *t = s.face_idx + 3 * f;
            double nf[3], c[3];
            for (int k = 0; k < 3; k++)
                c[k] = s.xyz[3 * t[0] + k] + s.xyz[3 * t[1] + k] + s.xyz[3 * t[2] + k];
            face_normal(&s, f, nf);
            ck_assert_msg(dot3(nf, c) > 0, "face %zu inward", f);
            for (int k = 0; k < 3; k++)
                cnt[t[k] * s.n + t[(k + 1) % 3]]++; /* directed edges */
        }
        for (size_t a = 0; a < s.n; a++)
            for (size_t b = 0; b < s.n; b++)
                if (cnt[a * s.n + b]) /* consistently oriented manifold */
                    ck_assert(cnt[a * s.n + b] == 1 && cnt[b * s.n + a] == 1);
        free(cnt);
        jf_sample_free(&s);
    }
}
END_TEST

/* The open cylinder: faces outward (normal . (x, y, 0) > 0), the seam
 * joined: (2 pi R / h) x (2 / h + 1) vertices, no column twice, and the
 * seam's cells among the 2 (2 pi R / h) (2 / h) faces. */
START_TEST(cylinder_mesh_outward)
{
    jf_rng r;
    jf_sample s;
    jf_rng_seed(&r, 5);
    ck_assert_int_eq(jf_sample_grid(JF_SURF_CYLINDER, 0.1, 0.0, 1, &r, &s), JF_OK);
    ck_assert_uint_eq(s.n, 31 * 21);
    ck_assert_uint_eq(s.nfaces, 2 * 31 * 20);
    for (size_t f = 0; f < s.nfaces; f++) {
        const uint32_t *t = s.face_idx + 3 * f;
        double nf[3];
        face_normal(&s, f, nf);
        ck_assert(nf[0] * s.xyz[3 * t[0]] + nf[1] * s.xyz[3 * t[0] + 1] > 0);
    }
    jf_sample_free(&s);
}
END_TEST

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* The torus (R = 1, r = 0.4): closed-form values on its outer equator
 * (elliptic, k1 = -1/1.4 along the parallel), inner equator (hyperbolic,
 * k1 = +1/0.6), top circle (parabolic, k1 = 0), each point on the
 * implicit surface with the implicit gradient as normal; the closed mesh
 * (both seams joined: every edge in exactly two faces, faces outward);
 * area-uniform sampling (the outer half psi in (-pi/2, pi/2) holds
 * (pi R + 2 r) / (2 pi R) = 0.6273 of the area; the parameter-uniform
 * half would hold 0.5). */
START_TEST(torus)
{
    jf_truth t;
    jf_surface_truth(JF_SURF_TORUS, 0.3, 0.0, &t);
    ck_assert(fabs(t.k1 + 1 / 1.4) < 1e-14 && fabs(t.k2 + 2.5) < 1e-14);
    ck_assert(fabs(t.normal[0] - cos(0.3)) < 1e-15 && fabs(t.normal[1] - sin(0.3)) < 1e-15);
    ck_assert(fabs(t.d1[0] + sin(0.3)) < 1e-15 && fabs(t.d1[1] - cos(0.3)) < 1e-15); /* along the parallel */
    jf_surface_truth(JF_SURF_TORUS, 1.1, M_PI, &t);
    ck_assert(fabs(t.k1 - 1 / 0.6) < 1e-13 && fabs(t.k2 + 2.5) < 1e-14);
    ck_assert(fabs(hypot(t.xyz[0], t.xyz[1]) - 0.6) < 1e-15);
    ck_assert(t.normal[0] * t.xyz[0] + t.normal[1] * t.xyz[1] < 0); /* outward = towards the axis */
    jf_surface_truth(JF_SURF_TORUS, 2.0, M_PI / 2, &t);
    ck_assert(fabs(t.k1) < 1e-14 && fabs(t.k2 + 2.5) < 1e-14 && fabs(t.normal[2] - 1) < 1e-15);
    jf_rng r;
    jf_rng_seed(&r, 3);
    for (int i = 0; i < 200; i++) {
        double u = 2 * M_PI * jf_rng_uniform(&r), v = 2 * M_PI * jf_rng_uniform(&r);
        jf_surface_truth(JF_SURF_TORUS, u, v, &t);
        double rho = hypot(t.xyz[0], t.xyz[1]);
        ck_assert(fabs((rho - 1) * (rho - 1) + t.xyz[2] * t.xyz[2] - 0.16) < 1e-14);
        double g[3] = {2 * (rho - 1) * t.xyz[0] / rho, 2 * (rho - 1) * t.xyz[1] / rho, 2 * t.xyz[2]};
        double gl = sqrt(dot3(g, g));
        for (int k = 0; k < 3; k++)
            ck_assert(fabs(g[k] / gl - t.normal[k]) < 1e-12);
        ck_assert(t.k1 > t.k2);
    }

    jf_sample s;
    ck_assert_int_eq(jf_sample_grid(JF_SURF_TORUS, 0.05, 0.0, 1, &r, &s), JF_OK);
    size_t nu = (size_t)round(2 * M_PI / 0.05), nv = (size_t)round(2 * M_PI * 0.4 / 0.05);
    ck_assert_uint_eq(s.n, nu * nv);
    ck_assert_uint_eq(s.nfaces, 2 * nu * nv); /* closed: V - E + F = 0 */
    /* every directed edge once and its reverse once: closed, oriented */
    size_t ne = 3 * s.nfaces;
    uint64_t *e = malloc(ne * sizeof *e);
    for (size_t f = 0; f < s.nfaces; f++) {
        const uint32_t *q = s.face_idx + 3 * f;
        double nf[3];
        face_normal(&s, f, nf);
        ck_assert(dot3(nf, s.truth[q[0]].normal) > 0); /* outward */
        for (int k = 0; k < 3; k++)
            e[3 * f + k] = (uint64_t)q[k] * s.n + q[(k + 1) % 3];
    }
    qsort(e, ne, sizeof *e, cmp_u64);
    for (size_t k = 0; k + 1 < ne; k++)
        ck_assert(e[k] != e[k + 1]);
    for (size_t k = 0; k < ne; k++) {
        uint64_t rev = (e[k] % s.n) * s.n + e[k] / s.n;
        ck_assert(bsearch(&rev, e, ne, sizeof *e, cmp_u64) != NULL);
    }
    free(e);
    jf_sample_free(&s);

    size_t n = 40000, outer = 0;
    ck_assert_int_eq(jf_sample_random(JF_SURF_TORUS, n, JF_DENSITY_UNIFORM, &r, &s), JF_OK);
    for (size_t i = 0; i < n; i++)
        outer += cos(s.uv[2 * i + 1]) > 0;
    /* binomial sd sqrt(p q / n) = 0.0024: 5 sd */
    ck_assert(fabs((double)outer / n - (M_PI + 0.8) / (2 * M_PI)) < 0.012);
    jf_sample_free(&s);
}
END_TEST

START_TEST(graph_grid_layout_and_determinism)
{
    jf_rng r1, r2;
    jf_sample a, b;
    jf_rng_seed(&r1, 9);
    jf_rng_seed(&r2, 9);
    ck_assert_int_eq(jf_sample_graph_grid(JF_SURF_EXP, 0.125, 5, 0.9, &r1, &a), JF_OK);
    ck_assert_int_eq(jf_sample_graph_grid(JF_SURF_EXP, 0.125, 5, 0.9, &r2, &b), JF_OK);
    ck_assert_uint_eq(a.n, 121);
    ck_assert_uint_eq(a.nfaces, 200);
    ck_assert(memcmp(a.xyz, b.xyz, 3 * a.n * sizeof(double)) == 0);
    /* vertex (i,j) = (j+m)(2m+1) + i+m sits at ((i + delta) h, ...) */
    size_t c = 5 * 11 + 5;
    ck_assert(a.uv[2 * c] >= 0 && a.uv[2 * c] <= 0.9 * 0.125);
    ck_assert(a.xyz[3 * c + 2] == 0.1 * exp(2 * a.uv[2 * c] + a.uv[2 * c + 1] -
                                            a.uv[2 * c + 1] * a.uv[2 * c + 1]));
    jf_sample_free(&b);
    jf_rng_seed(&r2, 9); /* unperturbed (perturbing may flip a few) */
    ck_assert_int_eq(jf_sample_graph_grid(JF_SURF_EXP, 0.125, 5, 0.0, &r2, &b), JF_OK);
    ck_assert(memcmp(a.face_idx, b.face_idx, 3 * a.nfaces * sizeof(uint32_t)) == 0);
    for (size_t f = 0; f < b.nfaces; f++) { /* upward faces */
        const uint32_t *t = b.face_idx + 3 * f;
        double e1x = b.uv[2 * t[1]] - b.uv[2 * t[0]], e1y = b.uv[2 * t[1] + 1] - b.uv[2 * t[0] + 1];
        double e2x = b.uv[2 * t[2]] - b.uv[2 * t[0]], e2y = b.uv[2 * t[2] + 1] - b.uv[2 * t[0] + 1];
        ck_assert(e1x * e2y - e1y * e2x > 0);
    }
    jf_sample_free(&a);
    jf_sample_free(&b);
}
END_TEST

START_TEST(noise_models)
{
    jf_rng r;
    jf_sample s;
    jf_rng_seed(&r, 4);
    ck_assert_int_eq(jf_sample_random(JF_SURF_SPHERE, 1000, JF_DENSITY_UNIFORM, &r, &s), JF_OK);
    double diag, side;
    jf_bbox_measure(s.xyz, s.n, &diag, &side);
    double *clean = malloc(3 * s.n * sizeof *clean);
    memcpy(clean, s.xyz, 3 * s.n * sizeof *clean);
    jf_noise_uniform(&s, 0.1, &r);
    double maxd = 0;
    for (size_t i = 0; i < 3 * s.n; i++)
        maxd = fmax(maxd, fabs(s.xyz[i] - clean[i]));
    ck_assert(maxd <= 0.05 * side && maxd > 0.04 * side);
    memcpy(s.xyz, clean, 3 * s.n * sizeof *clean);
    jf_noise_gauss(&s, 0.01, &r);
    double ss = 0;
    for (size_t i = 0; i < 3 * s.n; i++)
        ss += pow(s.xyz[i] - clean[i], 2);
    double sd = sqrt(ss / (3.0 * s.n)) / diag;
    ck_assert_msg(fabs(sd - 0.01) < 0.001, "sd %g", sd);
    jf_noise_outliers(&s, 0.05, &r);
    size_t bad = 0;
    for (size_t i = 0; i < s.n; i++)
        bad += !s.truth[i].valid && isnan(s.truth[i].k1);
    ck_assert_uint_eq(bad, 50);
    ck_assert_uint_eq(s.noutliers, 50);
    free(clean);
    jf_sample_free(&s);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("surfaces");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, truth_matches_finite_differences);
    tcase_add_test(tc, closed_form_values);
    tcase_add_test(tc, random_samples_lie_on_surface);
    tcase_add_test(tc, closed_meshes_are_closed_and_outward);
    tcase_add_test(tc, cylinder_mesh_outward);
    tcase_add_test(tc, torus);
    tcase_add_test(tc, graph_grid_layout_and_determinism);
    tcase_add_test(tc, noise_models);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}

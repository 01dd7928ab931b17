/* surfaces.c -- the paper's test surfaces and their exact differential
 * quantities (the "exact values" of §6.1), and the deterministic PRNG.
 *
 * design: every surface yields, at a point, a unit normal n, an
 * orthonormal tangent basis (e1, e2) and the symmetric 2x2 matrix S of
 * the second fundamental form in that basis (the Weingarten map, Table 1,
 * written in an orthonormal basis so it is symmetric); k1 >= k2 and d1,
 * d2 are its eigenpairs.  Graphs get S from the exact derivatives of f
 * (I and II of the Monge patch X = (x, y, f)); quadrics from their
 * implicit equation F = 0: n = grad F/|grad F|, S = -P Hess(F) P/|grad F|
 * (regular everywhere, unlike the UV parametrisation at the poles).
 * The torus has its principal frame in closed form: d_phi along the
 * parallels, d_psi along the tube's circles, curvatures (outward normal)
 * -cos psi / (R + r cos psi) and -1/r (never equal: no umbilics). */
#include <math.h>
#include <string.h>

#include "surfaces.h"

#define ELL_A 1.0
#define ELL_B 0.75
#define ELL_C 0.5
#define CYL_R 0.5
#define TOR_R 1.0 /* central circle */
#define TOR_r 0.4 /* tube */

static const char *const names[JF_SURF_COUNT] = {
    "exp", "paraboloid", "revolution", "sphere", "ellipsoid", "cylinder", "torus"};

const char *jf_surface_name(jf_surface s)
{
    return (unsigned)s < JF_SURF_COUNT ? names[s] : "?";
}

int jf_surface_parse(const char *name, jf_surface *s)
{
    for (int i = 0; i < JF_SURF_COUNT; i++)
        if (!strcmp(name, names[i])) {
            *s = (jf_surface)i;
            return 0;
        }
    return -1;
}

int jf_surface_is_graph(jf_surface s)
{
    return s == JF_SURF_EXP || s == JF_SURF_PARABOLOID ||
           s == JF_SURF_REVOLUTION;
}

int jf_surface_has_directions(jf_surface s) { return s != JF_SURF_SPHERE; }

void jf_surface_domain(jf_surface s, double lo[2], double hi[2])
{
    switch (s) {
    case JF_SURF_EXP:
        lo[0] = lo[1] = -0.5;
        hi[0] = hi[1] = 0.5;
        break;
    case JF_SURF_PARABOLOID:
        lo[0] = lo[1] = -1.0;
        hi[0] = hi[1] = 1.0;
        break;
    case JF_SURF_REVOLUTION: /* parabolic circles r = pi/20, pi/10 inside */
        lo[0] = lo[1] = -0.4;
        hi[0] = hi[1] = 0.4;
        break;
    case JF_SURF_SPHERE:
    case JF_SURF_ELLIPSOID:
        lo[0] = 0.0;
        hi[0] = M_PI;
        lo[1] = 0.0;
        hi[1] = 2.0 * M_PI;
        break;
    case JF_SURF_TORUS:
        lo[0] = lo[1] = 0.0;
        hi[0] = hi[1] = 2.0 * M_PI;
        break;
    default: /* cylinder */
        lo[0] = 0.0;
        hi[0] = 2.0 * M_PI;
        lo[1] = -1.0;
        hi[1] = 1.0;
        break;
    }
}

/* f and its exact partial derivatives up to order 2 (graphs).
 * d = {f, fx, fy, fxx, fxy, fyy}; returns 0 at a singular point. */
static int graph_derivs(jf_surface s, double x, double y, double d[6])
{
    if (s == JF_SURF_EXP) {
        /* f = 0.1 e^g, g = 2x + y - y^2 (§6.1, Fig. 4) */
        double e = 0.1 * exp(2.0 * x + y - y * y), gy = 1.0 - 2.0 * y;
        d[0] = e;
        d[1] = 2.0 * e;
        d[2] = gy * e;
        d[3] = 4.0 * e;
        d[4] = 2.0 * gy * e;
        d[5] = (gy * gy - 2.0) * e;
        return 1;
    }
    if (s == JF_SURF_PARABOLOID) {
        d[0] = 2.0 * x * x + y * y;
        d[1] = 4.0 * x;
        d[2] = 2.0 * y;
        d[3] = 4.0;
        d[4] = 0.0;
        d[5] = 2.0;
        return 1;
    }
    /* revolution f = 0.1 sin(10 r): f_r = cos(10r), f_rr = -10 sin(10r);
     * a cone point at r = 0 (f ~ r), where nothing is defined */
    double r = hypot(x, y);
    d[0] = 0.1 * sin(10.0 * r);
    if (r < 1e-12)
        return 0;
    double c = cos(10.0 * r), sn = sin(10.0 * r), r2 = r * r, r3 = r2 * r;
    d[1] = c * x / r;
    d[2] = c * y / r;
    d[3] = -10.0 * sn * x * x / r2 + c * y * y / r3;
    d[4] = -10.0 * sn * x * y / r2 - c * x * y / r3;
    d[5] = -10.0 * sn * y * y / r2 + c * x * x / r3;
    return 1;
}

void jf_surface_point(jf_surface s, double u, double v, double X[3])
{
    double d[6];
    switch (s) {
    case JF_SURF_SPHERE:
        X[0] = sin(u) * cos(v);
        X[1] = sin(u) * sin(v);
        X[2] = cos(u);
        return;
    case JF_SURF_ELLIPSOID:
        X[0] = ELL_A * sin(u) * cos(v);
        X[1] = ELL_B * sin(u) * sin(v);
        X[2] = ELL_C * cos(u);
        return;
    case JF_SURF_CYLINDER:
        X[0] = CYL_R * cos(u);
        X[1] = CYL_R * sin(u);
        X[2] = v;
        return;
    case JF_SURF_TORUS:
        X[0] = (TOR_R + TOR_r * cos(v)) * cos(u);
        X[1] = (TOR_R + TOR_r * cos(v)) * sin(u);
        X[2] = TOR_r * sin(v);
        return;
    default:
        graph_derivs(s, u, v, d);
        X[0] = u;
        X[1] = v;
        X[2] = d[0];
    }
}

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

static void unit3(double a[3])
{
    double l = sqrt(dot3(a, a));
    a[0] /= l;
    a[1] /= l;
    a[2] /= l;
}

/* Eigen-decomposition of S = [[a,b],[b,c]] in basis (e1,e2) -> t. */
static void finish(double a, double b, double c, const double e1[3],
                   const double e2[3], jf_truth *t)
{
    double m = 0.5 * (a + c), h = 0.5 * (a - c), r = hypot(h, b);
    t->k1 = m + r;
    t->k2 = m - r;
    double big = fmax(fabs(t->k1), fabs(t->k2));
    if (r <= 1e-10 * big || r == 0.0) { /* umbilic: directions undefined */
        for (int i = 0; i < 3; i++)
            t->d1[i] = t->d2[i] = NAN;
        return;
    }
    /* eigenvector of k1, from the better-conditioned row */
    double v0, v1;
    if (h >= 0) {
        v0 = r + h;
        v1 = b;
    } else {
        v0 = b;
        v1 = r - h;
    }
    for (int i = 0; i < 3; i++)
        t->d1[i] = v0 * e1[i] + v1 * e2[i];
    unit3(t->d1);
    cross3(t->normal, t->d1, t->d2); /* d1 x d2 = n */
}

/* Graph: Monge patch X = (x, y, f), II_ij = f_ij / W along the upward
 * normal; S in the orthonormal basis e1 = Xu/|Xu|, e2 = n x e1. */
static void truth_graph(jf_surface s, double x, double y, jf_truth *t)
{
    double d[6];
    if (!graph_derivs(s, x, y, d)) {
        t->valid = 0;
        return;
    }
    double Xu[3] = {1, 0, d[1]}, Xv[3] = {0, 1, d[2]};
    double W = sqrt(1.0 + d[1] * d[1] + d[2] * d[2]);
    t->normal[0] = -d[1] / W;
    t->normal[1] = -d[2] / W;
    t->normal[2] = 1.0 / W;
    double E = dot3(Xu, Xu), F = dot3(Xu, Xv), G = dot3(Xv, Xv);
    double L = d[3] / W, M = d[4] / W, N = d[5] / W;
    double e1[3] = {Xu[0], Xu[1], Xu[2]}, e2[3];
    unit3(e1);
    cross3(t->normal, e1, e2);
    /* coordinates (alpha, beta) of e1, e2 in (Xu, Xv): Gram system */
    double det = E * G - F * F, c[2][2];
    const double *ev[2] = {e1, e2};
    for (int i = 0; i < 2; i++) {
        double p = dot3(ev[i], Xu), q = dot3(ev[i], Xv);
        c[i][0] = (G * p - F * q) / det;
        c[i][1] = (E * q - F * p) / det;
    }
    double S[2][2];
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++)
            S[i][j] = c[i][0] * (L * c[j][0] + M * c[j][1]) +
                      c[i][1] * (M * c[j][0] + N * c[j][1]);
    finish(S[0][0], 0.5 * (S[0][1] + S[1][0]), S[1][1], e1, e2, t);
}

/* Quadric F(p) = p^T D p - 1 (D diagonal; cylinder: D_zz = 0):
 * grad = 2 D p, Hess = 2 D. */
static void truth_quadric(const double D[3], jf_truth *t)
{
    double g[3], H[3];
    for (int i = 0; i < 3; i++) {
        g[i] = 2.0 * D[i] * t->xyz[i];
        H[i] = 2.0 * D[i];
    }
    double gl = sqrt(dot3(g, g));
    for (int i = 0; i < 3; i++)
        t->normal[i] = g[i] / gl;
    /* e1: the axis least aligned with n, made tangent */
    int k = 0;
    for (int i = 1; i < 3; i++)
        if (fabs(t->normal[i]) < fabs(t->normal[k]))
            k = i;
    double ax[3] = {0, 0, 0}, e1[3], e2[3];
    ax[k] = 1.0;
    cross3(ax, t->normal, e1);
    unit3(e1);
    cross3(t->normal, e1, e2);
    double a = 0, b = 0, c = 0;
    for (int i = 0; i < 3; i++) {
        a += e1[i] * H[i] * e1[i];
        b += e1[i] * H[i] * e2[i];
        c += e2[i] * H[i] * e2[i];
    }
    finish(-a / gl, -b / gl, -c / gl, e1, e2, t);
}

/* Torus at (phi, psi) = (u, v): outward normal (cos v cos u, cos v sin u,
 * sin v); e1 = d_phi = (-sin u, cos u, 0) with normal curvature
 * -cos v / (R + r cos v) (the parallel's curvature 1/(R + r cos v) times
 * the cosine of its angle with the surface), e2 = n x e1 (along the tube)
 * with -1/r.  S is diagonal in (e1, e2). */
static void truth_torus(double u, double v, jf_truth *t)
{
    double n[3] = {cos(v) * cos(u), cos(v) * sin(u), sin(v)};
    double e1[3] = {-sin(u), cos(u), 0.0}, e2[3];
    memcpy(t->normal, n, sizeof n);
    cross3(n, e1, e2);
    finish(-cos(v) / (TOR_R + TOR_r * cos(v)), 0.0, -1.0 / TOR_r, e1, e2, t);
}

void jf_surface_truth(jf_surface s, double u, double v, jf_truth *t)
{
    jf_surface_point(s, u, v, t->xyz);
    t->valid = 1;
    if (jf_surface_is_graph(s)) {
        truth_graph(s, u, v, t);
    } else if (s == JF_SURF_TORUS) {
        truth_torus(u, v, t);
    } else {
        double D[3];
        if (s == JF_SURF_SPHERE) {
            D[0] = D[1] = D[2] = 1.0;
        } else if (s == JF_SURF_ELLIPSOID) {
            D[0] = 1.0 / (ELL_A * ELL_A);
            D[1] = 1.0 / (ELL_B * ELL_B);
            D[2] = 1.0 / (ELL_C * ELL_C);
        } else {
            D[0] = D[1] = 1.0 / (CYL_R * CYL_R);
            D[2] = 0.0;
        }
        truth_quadric(D, t);
    }
    if (!t->valid) {
        t->k1 = t->k2 = NAN;
        for (int i = 0; i < 3; i++)
            t->normal[i] = t->d1[i] = t->d2[i] = NAN;
    }
}

/* ---------------- xoshiro256** seeded by splitmix64 ---------------- */
static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

void jf_rng_seed(jf_rng *r, uint64_t seed)
{
    uint64_t x = seed;
    for (int i = 0; i < 4; i++)
        r->s[i] = splitmix64(&x);
}

static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

uint64_t jf_rng_next(jf_rng *r)
{
    uint64_t *s = r->s, res = rotl(s[1] * 5, 7) * 9, t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return res;
}

double jf_rng_uniform(jf_rng *r)
{
    return (double)(jf_rng_next(r) >> 11) * 0x1.0p-53;
}

double jf_rng_gauss(jf_rng *r)
{
    /* Marsaglia's polar method: only +, *, log, sqrt (no sin/cos) */
    double a, b, q;
    do {
        a = 2.0 * jf_rng_uniform(r) - 1.0;
        b = 2.0 * jf_rng_uniform(r) - 1.0;
        q = a * a + b * b;
    } while (q >= 1.0 || q == 0.0);
    return a * sqrt(-2.0 * log(q) / q);
}

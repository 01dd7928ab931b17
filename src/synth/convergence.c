/* convergence.c -- the §6.1 experiment (see convergence.h for the setup).
 *
 * design: for each h (coarse to fine): build the perturbed grid and its
 * mesh adjacency once; for each mode and degree, fit the jet at every
 * selected vertex from its mesh-ring neighbourhood (jf_nb_query_mesh, the
 * rule of `--neighbors rings`) and accumulate the errors against the exact
 * values.  One fitter per (mode, degree), created before the loops. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "convergence.h"
#include "surfaces.h"

#define RING_MARGIN 10 /* rings beyond the lattice: approx. degree 9 needs 6 */
#define CAP 256        /* neighbourhood capacity (rings of 2 N_9 = 127)     */

void jf_conv_config_init(jf_conv_config *c, int quick)
{
    memset(c, 0, sizeof *c);
    c->seed = 1;
    c->deg_lo = 1;
    c->deg_hi = quick ? 4 : 9;
    c->interp = c->approx = 1;
    c->nh = 5;
    for (int k = 0; k < 5; k++)
        c->h[k] = ldexp(1.0, -(k + 2)); /* 2^-2 .. 2^-6 */
    c->lattice = quick ? 3 : 5;
}

static int nmodes(const jf_conv_config *c) { return (c->interp != 0) + (c->approx != 0); }

size_t jf_conv_row_count(const jf_conv_config *c)
{
    return (size_t)nmodes(c) * (size_t)(c->deg_hi - c->deg_lo + 1) * (size_t)c->nh;
}

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* sin of the angle between unit vectors: |a x b| */
static double sine(const double a[3], const double b[3])
{
    double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                   a[0] * b[1] - a[1] * b[0]};
    return sqrt(dot3(c, c));
}

/* Fits every selected vertex for one (mode, degree) into row r. */
static jf_status run_one(jf_fitter *f, const jf_mesh *mesh, const jf_sample *s,
                         const uint32_t *sel, size_t nsel, jf_fit_mode mode,
                         int degree, jf_conv_row *r)
{
    uint32_t idx[CAP];
    double nbr[3 * CAP];
    jf_nb_spec spec = {.kind = JF_NB_RINGS, .k = 0, .r = 0, .n = 0};
    size_t used = 0, nonfinite[3] = {0, 0, 0};
    for (int q = 0; q < 3; q++)
        r->avg[q] = r->max[q] = 0.0;
    for (size_t i = 0; i < nsel; i++) {
        uint32_t v = sel[i];
        size_t found;
        jf_status st = jf_nb_query_mesh(mesh, s->xyz, &spec, jf_jet_size(degree),
                                        mode, v, idx, CAP, &found);
        if (st)
            return st;
        for (size_t k = 0; k < found; k++)
            memcpy(nbr + 3 * k, s->xyz + 3 * (size_t)idx[k], 3 * sizeof(double));
        jf_result res;
        st = jf_fit_point(f, s->xyz + 3 * (size_t)v, nbr, found, &res);
        if (st)
            return st;
        if (res.status & JF_PT_FAILED) {
            r->failed++;
            continue;
        }
        if (res.degree < degree)
            r->lowered++;
        const jf_truth *t = &s->truth[v];
        jf_result_orient(&res, t->normal);
        double e[3] = {sine(res.normal, t->normal), fabs(res.k2 - t->k2) / fabs(t->k2),
                       fabs(res.k1 - t->k1) / fabs(t->k1)};
        for (int q = 0; q < 3; q++) {
            nonfinite[q] += !isfinite(e[q]); /* degree 1: no curvature */
            r->avg[q] += e[q];
            r->max[q] = fmax(r->max[q], e[q]);
        }
        used++;
    }
    for (int q = 0; q < 3; q++) {
        r->avg[q] = used ? r->avg[q] / (double)used : NAN;
        if (nonfinite[q])
            r->max[q] = NAN;
    }
    return JF_OK;
}

jf_status jf_conv_run(const jf_conv_config *c, jf_conv_row *rows)
{
    if (!c || !rows || c->deg_lo < 1 || c->deg_hi > JF_MAX_DEGREE ||
        c->deg_lo > c->deg_hi || c->nh < 1 || c->nh > JF_CONV_MAX_H ||
        c->lattice < 1 || c->lattice > 64 || !nmodes(c))
        return JF_ERR_INVALID;
    for (int k = 0; k < c->nh; k++)
        if (!(c->h[k] > 0) || c->h[k] < 1e-4 || (k && c->h[k] >= c->h[k - 1]))
            return JF_ERR_INVALID;
    int nd = c->deg_hi - c->deg_lo + 1, nm = nmodes(c);
    jf_fit_mode modes[2];
    int m0 = 0;
    if (c->interp)
        modes[m0++] = JF_FIT_INTERP;
    if (c->approx)
        modes[m0++] = JF_FIT_APPROX;

    jf_fitter **fit = calloc((size_t)(nm * nd), sizeof *fit);
    uint32_t *sel = malloc((size_t)c->lattice * c->lattice * sizeof *sel);
    jf_status st = fit && sel ? JF_OK : JF_ERR_NOMEM;
    for (int m = 0; m < nm && !st; m++)
        for (int d = 0; d < nd && !st; d++) {
            jf_params p;
            jf_params_init(&p);
            p.degree = c->deg_lo + d;
            p.fit = modes[m];
            p.max_cond = DBL_MAX; /* no adaptive degree: measure degree n */
            p.max_neighbors = CAP;
            st = jf_fitter_create(&p, &fit[m * nd + d]);
        }
    for (int k = 0; k < c->nh && !st; k++) {
        double h = c->h[k];
        int half = (int)ceil(0.25 / h - 1e-9), gm = half + RING_MARGIN;
        jf_rng rng;
        jf_rng_seed(&rng, c->seed * 0x9e3779b97f4a7c15ull + (uint64_t)k);
        jf_sample s;
        st = jf_sample_graph_grid(JF_SURF_EXP, h, gm, 0.9, &rng, &s);
        if (st)
            break;
        jf_mesh *mesh = NULL;
        st = jf_mesh_build(s.n, s.nfaces, s.face_off, s.face_idx, &mesh, NULL);
        /* selected vertices: nearest grid nodes to the lattice locations */
        size_t nsel = 0, side = 2 * (size_t)gm + 1;
        for (int a = 0; a < c->lattice; a++)
            for (int b = 0; b < c->lattice; b++) {
                double x = c->lattice > 1 ? -0.25 + 0.5 * a / (c->lattice - 1) : 0;
                double y = c->lattice > 1 ? -0.25 + 0.5 * b / (c->lattice - 1) : 0;
                long i = lround(x / h), j = lround(y / h);
                sel[nsel++] = (uint32_t)((size_t)(j + gm) * side + (size_t)(i + gm));
            }
        for (int m = 0; m < nm && !st; m++)
            for (int d = 0; d < nd && !st; d++) {
                jf_conv_row *r = &rows[((size_t)m * nd + d) * c->nh + k];
                memset(r, 0, sizeof *r);
                r->mode = modes[m];
                r->degree = c->deg_lo + d;
                r->h = h;
                r->npoints = nsel;
                st = run_one(fit[m * nd + d], mesh, &s, sel, nsel, modes[m],
                             r->degree, r);
            }
        jf_mesh_free(mesh);
        jf_sample_free(&s);
    }
    if (fit)
        for (int i = 0; i < nm * nd; i++)
            jf_fitter_free(fit[i]);
    free(fit);
    free(sel);
    return st;
}

double jf_conv_slope(const jf_conv_row *r, size_t n, int q, size_t *used)
{
    size_t k = 0;
    for (; k < n; k++) {
        double d = r[k].avg[q];
        if (!(d > 1e-13) || !isfinite(d))
            break;
        if (k && r[k - 1].avg[q] < 1e-6 && d > r[k - 1].avg[q] / sqrt(2.0))
            break; /* flattened: the rounding floor, not truncation */
    }
    *used = k;
    if (k < 2)
        return NAN;
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (size_t i = 0; i < k; i++) {
        double x = log(1.0 / r[i].h), y = log(1.0 / r[i].avg[q]);
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
    }
    double kk = (double)k;
    return (kk * sxy - sx * sy) / (kk * sxx - sx * sx);
}

/*
 * jetfit.h -- the one public header of libjetfit.
 *
 * jetfit estimates, at every sample of a point cloud or mesh, the normal, the
 * principal curvatures and directions and the 3rd/4th-order Monge
 * coefficients by fitting osculating jets (Cazals & Pouget, "Estimating
 * Differential Quantities Using Polynomial Fitting of Osculating Jets",
 * SGP 2003; section numbers below are the paper's).
 *
 * Conventions of the whole API
 *  - Every fallible call returns a jf_status (JF_OK == 0); jf_strerror() names
 *    it.  The library never prints, exits or aborts.  Calls that read files
 *    also fill a caller-owned jf_error with one line naming the file, the
 *    place (line or element) and the reason.
 *  - Per-point failure is data, not an error: jf_result.status holds
 *    JF_PT_* flags (0 = full fit at the requested degree).
 *  - Points are `const double *xyz` with 3 doubles per point, caller-owned.
 *    Element i of every output array belongs to input point i.
 *  - Handles (jf_fitter, jf_index, ...) are opaque, created once and reused;
 *    jf_*_free(NULL) is a no-op; a failed create frees what it made.
 *  - Thread safety: functions taking a const handle are safe to call from
 *    several threads at once; a jf_fitter is a per-thread workspace.
 */
#ifndef JETFIT_H
#define JETFIT_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define JF_VERSION_MAJOR 0
#define JF_VERSION_MINOR 1
#define JF_VERSION_PATCH 0
#define JF_VERSION_STRING "0.1.0"

/* Run-time version string ("0.1.0"). */
const char *jf_version(void);

/* The most threads any call runs (the command's --threads limit). */
#define JF_THREADS_MAX 4096

/* The thread count a call with threads <= 0 runs: OpenMP's default
 * (OMP_NUM_THREADS, else every processor) clamped to [1, the processors
 * this process may run on] and to JF_THREADS_MAX, so no environment value
 * can start thousands of threads.  *asked (may be NULL) gets OpenMP's
 * default before the clamp (the caller may say when they differ).
 * Thread-safe. */
int jf_default_threads(int *asked);

/* ------------------------------------------------------------------ */
/* Status codes (stable: values never change once released).          */
/* ------------------------------------------------------------------ */
typedef enum {
    JF_OK = 0,
    JF_ERR_INVALID = 1,     /* bad argument or parameter                 */
    JF_ERR_NOMEM = 2,       /* allocation failed                         */
    JF_ERR_IO = 3,          /* open/read/write/rename failed             */
    JF_ERR_FORMAT = 4,      /* malformed or unsupported file content     */
    JF_ERR_TOO_LARGE = 5,   /* more points/neighbours than the handle or
                               the file can hold                          */
    JF_ERR_NUMERIC = 6,     /* a numerical routine failed                */
    JF_ERR_UNSUPPORTED = 7, /* feature not built in (e.g. no CGAL)       */
    JF_ERR_INTERNAL = 8,    /* a bug: please report                      */
    JF_ERR_CANCELLED = 9    /* the caller's cancel hook asked to stop    */
} jf_status;

/* Static English name of a status; never NULL. */
const char *jf_strerror(jf_status s);

/* One-line message filled by calls that touch files (caller-owned). */
typedef struct {
    char msg[512];
} jf_error;

/* ------------------------------------------------------------------ */
/* Per-point status flags (jf_result.status, the output column).      */
/* 0 means: fitted at the requested degree, nothing to report.        */
/* ------------------------------------------------------------------ */
enum {
    JF_PT_LOWERED_COND = 1u << 0,  /* degree lowered: kappa > max_cond  */
    JF_PT_LOWERED_RANK = 1u << 1,  /* degree lowered: M' rank deficient */
    JF_PT_LOWERED_FEW = 1u << 2,   /* degree lowered: N < N_n           */
    JF_PT_UMBILIC = 1u << 3,       /* k1 == k2 (relative 1e-10):
                                      d1, d2 an arbitrary orthonormal
                                      tangent pair (never NaN)          */
    JF_PT_FAILED = 1u << 4,        /* no fit even at degree 1 (fewer than
                                      3 usable points, collinear...):
                                      quantities are NaN                */
    JF_PT_NONFINITE = 1u << 5,     /* the input point is NaN/Inf; it is
                                      nobody's neighbour; row is NaN    */
    JF_PT_FEW_NEIGHBORS = 1u << 6, /* neighbourhood smaller than asked  */
    JF_PT_NORMAL_POLES = 1u << 7,  /* natural: tangent plane from pole  */
    JF_PT_NORMAL_MINCIRC = 1u << 8,/* natural: min-circumradius normal  */
    JF_PT_NORMAL_FALLBACK = 1u << 9,/* natural: pole unreliable, the
                                      fallback normal was used          */
    JF_PT_ROBUST_NOCONV = 1u << 10,/* robust reweighting did not converge */
    JF_PT_ORIENT_UNKNOWN = 1u << 11,/* orientation could not be decided
                                      (e.g. mst: isolated point)        */
    JF_PT_NORMAL_INPUT = 1u << 12, /* natural: tangent plane from the
                                      normal read from the file         */
    JF_PT_SCALE_SELECTED = 1u << 13,/* scale selection chose a K other
                                      than the largest candidate        */
    JF_PT_MESH_NONMANIFOLD = 1u << 14,/* rings: the vertex is on a mesh
                                      edge shared by more than 2 faces  */
    JF_PT_NORMAL_JET = 1u << 15,   /* natural: tangent plane from the jet
                                      of the N nearest points, ring on
                                      the jet-projected cloud (noisy
                                      cloud, docs/natural.md)           */
    JF_PT_NORMAL_PCA = 1u << 16,   /* natural: tangent plane from the PCA
                                      of the 16 nearest points (clean
                                      cloud, or --normal pca)           */
    JF_PT_AUTO = 1u << 17,         /* neighbourhood auto: K (n_used) and
                                      degree were chosen per point
                                      (params.auto_select)              */
    JF_PT_AUTO_CAPPED = 1u << 18,  /* auto: K at most params.auto_select
                                      (jf_estimate: the cloud's cross-
                                      validation, docs/robustness.md
                                      step 0), below the largest
                                      candidate the list held           */
    JF_PT_AUTO_WEIGHTED = 1u << 19,/* auto, jf_estimate: the normal is
                                      the neighbours' fits' weighted
                                      trapezoid mean over K/8 of them
                                      (K/4 if capped; the noise large
                                      against the fit's spread, or step
                                      0's bias test: step 6), not their
                                      plain carry                       */
    JF_PT_AUTO_SPREAD = 1u << 20   /* auto, jf_estimate: the plain carry
                                      over every 4th of the K/2 nearest
                                      (the cloud's fits hold a cubic
                                      term's bias: step 6), not over the
                                      K/8 nearest (K/4 if capped)       */
};

/* Writes a '|'-separated list of flag names of `status` into buf
 * ("ok" for 0).  Returns buf.  Thread-safe. */
char *jf_point_status_str(unsigned status, char *buf, size_t len);

/* ------------------------------------------------------------------ */
/* Parameters                                                          */
/* ------------------------------------------------------------------ */
#define JF_MAX_DEGREE 9         /* largest jet degree (N_9 = 55)       */
#define JF_MAX_MONGE_DEGREE 4
#define JF_MAX_NEIGHBORS ((size_t)1 << 20) /* largest neighbourhood a fit takes */

typedef enum { JF_FIT_APPROX = 0, JF_FIT_INTERP = 1 } jf_fit_mode;
typedef enum { JF_FRAME_PCA = 0, JF_FRAME_AXIS = 1 } jf_frame_mode;
typedef enum {
    JF_ROBUST_NONE = 0,
    JF_ROBUST_HUBER = 1,
    JF_ROBUST_TUKEY = 2
} jf_robust_mode;

typedef struct {
    int degree;              /* jet degree n, 1..JF_MAX_DEGREE (default 2) */
    int monge_degree;        /* 2..4 and <= max(degree, 2); 3 gives b0..b3,
                                4 also c0..c4 (default 2)                  */
    jf_fit_mode fit;         /* approximation (N > N_n) or interpolation
                                (the N_n nearest points)  (default approx) */
    jf_frame_mode frame;     /* fitting frame, §5.2 (default pca)          */
    double max_cond;         /* adaptive degree: lower the degree while
                                kappa(M') > max_cond; >= 1, +INFINITY
                                disables the test (default 1e3, measured:
                                docs/numerics.md "Per point")             */
    size_t max_neighbors;    /* largest N a fitter accepts (default 256)   */
    jf_robust_mode robust;   /* IRLS weights on residuals (default none)   */
    int robust_iters;        /* IRLS iteration cap (default 10)            */
    int nscales;             /* scale selection: number of candidate K in
                                scales[] (0 = off, default)               */
    size_t scales[8];        /* candidate neighbourhood sizes, ascending  */
    int degree_select;       /* per-point degree selection (robust.c):
                                0 = off (default), else the lowest degree
                                tried, 1..degree                          */
    double dist_weight;      /* Gaussian distance weights (robust.c):
                                sigma = dist_weight x the farthest
                                neighbour's distance; 0 = off (default)   */
    int auto_select;         /* 1: per point, choose K among the first
                                entries of nbr (nearest first) and the
                                degree (2 or 3), estimating the noise
                                (src/robust/auto.c; the neighbourhood
                                JF_NB_AUTO sets it); overrides robust,
                                scales, degree_select, dist_weight and
                                degree.  This is one point's own fit;
                                jf_estimate with JF_NB_AUTO then takes
                                each row's normal and curvatures from
                                its nearest points' fits (docs/
                                robustness.md, step 6).  0 = off
                                (default); 16..JF_NB_AUTO_KMAX: the same,
                                K at most that (jf_estimate sets it from
                                the cloud's cross-validation, step 0,
                                where it is 1); either may carry
                                JF_AUTO_FLAGS                           */
} jf_params;

/* OR'd into params.auto_select (with 1 or a cap): no cubic on fewer than
 * 48 points, whatever the noise (jf_estimate sets it where the cloud's
 * cross-validation finds the cubic on the 16 nearest predicts p better
 * than the quadric at no more than half its sample: docs/robustness.md,
 * step 0) */
#define JF_AUTO_CUBIC_MIN48 1024
/* OR'd into params.auto_select (with 1 or a cap): step 6 takes the normal
 * of every row not capped from its neighbours' fits weighted by their
 * slopes' precision, carried by their own and the mean shape operator,
 * however small the noise (jf_estimate sets it where no row is capped and
 * the quadric's normal on 256 points is as near the cubic's as the noise
 * alone would put it: docs/robustness.md, step 0) */
#define JF_AUTO_WEIGHTED_MEAN 2048
/* OR'd into params.auto_select (with 1 or a cap): step 6's plain carry
 * reads the point and every 4th of its K/2 nearest, not its K/8 nearest,
 * which averages out the slope bias a cubic term leaves in the quadric
 * (jf_estimate sets it where no row is capped and the quadric's normal on
 * 256 points is off the cubic's by a little more than the noise explains,
 * the sample's median statistic in (1, 4]: docs/robustness.md, step 0) */
#define JF_AUTO_SPREAD_CARRY 4096
/* OR'd into params.auto_select (with a cap): step 6 takes the weighted
 * trapezoid mean on capped rows too, not the plain carry, and no capped
 * row's K is below 32 or the cap, the smaller (jf_estimate sets it, with
 * a cap of at least 32, where the cloud is capped and the quadric's
 * normal on 32 points is off the cubic's by a little more than the noise
 * explains, the sample's median statistic in (1, 4]: the range scans;
 * docs/robustness.md, step 0) */
#define JF_AUTO_CAPPED_WEIGHTED 8192
/* the four flags */
#define JF_AUTO_FLAGS \
    (JF_AUTO_CUBIC_MIN48 | JF_AUTO_WEIGHTED_MEAN | JF_AUTO_SPREAD_CARRY | JF_AUTO_CAPPED_WEIGHTED)
/* A decision of step 0 (params.auto_select's form: jf_estimate_opts.
 * auto_chosen) in words into buf: "K capped at 32; no cubic below K = 48;
 * capped rows: the weighted mean, K at least 32", or "no cap on K" (1 or
 * JF_NB_AUTO_KMAX) and the flags'.  Returns buf.  Thread-safe. */
char *jf_auto_step0_str(int chosen, char *buf, size_t len);

/* Fills defaults.  Never fails. */
void jf_params_init(jf_params *p);

/* Checks every field.  Returns JF_OK (and sets *bad_field to NULL), or
 * JF_ERR_INVALID and, if `bad_field` is not NULL, sets it to the name of
 * the first bad field (static string).  Thread-safe. */
jf_status jf_params_validate(const jf_params *p, const char **bad_field);

/* Number of coefficients N_n of an n-jet of a surface: (n+1)(n+2)/2
 * (0 for n < 0). */
size_t jf_jet_size(int degree);

/* ------------------------------------------------------------------ */
/* Result of one fit                                                   */
/* ------------------------------------------------------------------ */
/* Conventions of a fit (jet.c, monge.c):
 *  - The normal points to the +z side of the fitting frame (PCA: the
 *    pinned smallest-variance axis, whose largest-|component| is positive;
 *    axis: the positive world axis) until jf_result_orient/flip.
 *  - The Monge frame is (d1, d2, normal) at the jet's point above p
 *    (0, 0, A00 in the fitting frame); k1 >= k2 and b, c are signed
 *    w.r.t. `normal`: z = (k1 x^2 + k2 y^2)/2 + (b0 x^3 + 3 b1 x^2 y
 *    + 3 b2 x y^2 + b3 y^3)/6 + (c0 x^4 + 4 c1 x^3 y + 6 c2 x^2 y^2
 *    + 4 c3 x y^3 + c4 y^4)/24 + ...
 *  - A quantity of higher order than the degree used is NaN, never a
 *    silent 0: k1, k2 at degree 1 (d1, d2 are then a tangent pair), b at
 *    degree < 3 (if monge_degree >= 3), c at degree < 4 (if 4).
 *  - FAILED and NONFINITE rows: degree 0, every quantity NaN. */
typedef struct {
    unsigned status;      /* JF_PT_* flags                              */
    int degree;           /* degree actually used (0 when FAILED)       */
    int n_used;           /* number of points in the fit (FAILED: the
                             number of usable neighbours offered)       */
    double cond;          /* kappa(M') = sigma_max/sigma_min of the
                             preconditioned Vandermonde matrix (§2.3) at
                             the degree used (FAILED: the last one tried,
                             +Inf if singular, NaN if none was built)   */
    double residual;      /* RMS of the fit residuals z_i - J(x_i,y_i)
                             over the points used, in length units
                             (weighted fits: sqrt(sum w^2 r^2 / sum w^2)) */
    double pca_eval[3];   /* covariance eigenvalues, ascending          */
    double normal[3];     /* unit normal                                */
    double k1, k2;        /* principal curvatures, k1 >= k2, signed
                             w.r.t. `normal`                            */
    double d1[3], d2[3];  /* principal directions (unit, d1 x d2 = n)   */
    double b[4];          /* Monge b0..b3 (monge_degree >= 3, else 0)   */
    double c[5];          /* Monge c0..c4 (monge_degree >= 4, else 0)   */
    double sigma;         /* params.auto_select: the noise the choice
                             assumed (std. dev. along the normal, length
                             units); NaN otherwise                      */
} jf_result;

/* Flips the orientation of a result in place: normal -> -normal, every
 * Monge coefficient negated, k1<->k2, d1<->d2, b0<->b3, b1<->b2,
 * c0<->c4, c1<->c3 (docs/design.md; the convention of CGAL's
 * Monge_via_jet_fitting).  d1 x d2 = n is kept. */
void jf_result_flip(jf_result *r);

/* Flips `r` if its normal points away from `dir` (n . dir < 0).
 * Both are no-ops on NULL.  Thread-safe (on distinct results). */
void jf_result_orient(jf_result *r, const double dir[3]);

/* ------------------------------------------------------------------ */
/* Fitter: a per-thread workspace                                      */
/* ------------------------------------------------------------------ */
typedef struct jf_fitter jf_fitter;

/* Creates a workspace for the parameters `p` (validated; copied).  All
 * memory a fit needs is allocated here: jf_fit_point never allocates.
 * Returns JF_OK, the validation status, or JF_ERR_NOMEM; *out is NULL on
 * failure.  The first call turns GSL's abort-on-error handler off for the
 * whole process (gsl_set_error_handler_off, once, under pthread_once): the
 * library checks its inputs so GSL never has to report.  Thread-safe. */
jf_status jf_fitter_create(const jf_params *p, jf_fitter **out);
void jf_fitter_free(jf_fitter *f);

/* Fits the osculating jet at point p from its n neighbours nbr[3*i..]
 * (p itself may be one of them; it is the origin of the fit).  Always
 * fills *out (status flags say what happened) and returns JF_OK, or
 * JF_ERR_INVALID / JF_ERR_TOO_LARGE (n > max_neighbors) for bad
 * arguments.  Steps: translate to p; drop non-finite neighbours; fitting
 * frame from the covariance of all remaining neighbours; approximation
 * uses them all, interpolation the N_n nearest distinct ones (exact
 * duplicates skipped; ties by index).  Adaptive degree (§5.2): while
 * N < N_d (LOWERED_FEW), M' is rank deficient (sigma_min <= sigma_max *
 * rows * DBL_EPSILON: LOWERED_RANK) or kappa > max_cond (LOWERED_COND),
 * try d - 1; below 1: FAILED.  Deterministic: a reused fitter gives
 * bit-identical results to a fresh one.
 * Not thread-safe on one fitter; use one fitter per thread. */
jf_status jf_fit_point(jf_fitter *f, const double p[3], const double *nbr,
                       size_t n, jf_result *out);

/* Same, with one finite weight per neighbour (>= 0, else JF_ERR_INVALID)
 * multiplying its equation; weight-0 neighbours are left out of the fit
 * and of the frame (whose covariance is weighted by w). */
jf_status jf_fit_point_weighted(jf_fitter *f, const double p[3],
                                const double *nbr, const double *w,
                                size_t n, jf_result *out);

/* Signed residuals z_i - J(x_i, y_i) of each of the n neighbours given to
 * the last fit on this fitter (in the fitting frame, in the order given;
 * interpolation: points not used also get their residual; NaN for
 * non-finite neighbours and when the fit FAILED).  res has n entries.
 * JF_ERR_INVALID if n differs from the last fit's n, or the last call on
 * this fitter was jf_fit_curve or none. */
jf_status jf_fitter_residuals(const jf_fitter *f, double *res, size_t n);

/* The parameters the fitter was created with. */
const jf_params *jf_fitter_params(const jf_fitter *f);

/* The full per-point fit used by the command (src/robust/scale.c, robust.c,
 * select.c).
 *  - params.robust: iteratively reweighted least squares on the height
 *    residuals; scale s = 1.4826 median|r|; Huber (c = 1.345 s) or Tukey
 *    (c = 4.685 s, after two Huber steps) weights; at most robust_iters
 *    refits, stopping when the normal and curvatures move by less than 10%
 *    of the noise scale over the neighbourhood; otherwise (or when fewer
 *    than N_n + 1 points keep a weight) JF_PT_ROBUST_NOCONV.
 *  - params.scales: per-point choice of K among scales[] (the first K of
 *    nbr, which must be sorted nearest first; K > n is clamped to n) by
 *    least estimated mean squared error of the normal: squared bias from
 *    the difference to a fit one degree higher on the same K points and
 *    to each smaller K's normal (less their noise), plus twice the
 *    normal's variance; costs two fits per candidate.
 *    JF_PT_SCALE_SELECTED when the chosen K is not the largest.
 *    out->n_used tells the K used.
 *  - params.degree_select = dmin >= 1: per-point choice of the degree among
 *    degree..dmin by an interval rule (noise variance from the
 *    top-degree fit): a lower degree is kept while its normal stays within
 *    1.5 sd (sum of both) of every higher degree's, and none is tried when
 *    the top degree's sd is below 0.2 rad (a noise-dominated neighbourhood
 *    has sd >= noise / radius, that floor shrinking like sqrt(50 / n)
 *    above 50 points); out->degree tells the degree used (at 1, k1/k2 are
 *    NaN as for any 1-jet).  With noise on a small K the plane or quadric
 *    wins, on clean data or large K the full degree.
 *  - params.dist_weight = c > 0: Gaussian weights exp(-d^2 / (2 (c dmax)^2))
 *    on each neighbour's distance d to p (dmax: the farthest); with
 *    degree_select the weighted top-degree fit heads the chain (kept
 *    unless the unweighted normal agrees within the intervals).  Lowers
 *    truncation error on clean data, costs variance under noise.  The
 *    command's --robust-normals is degree_select 1 with dist_weight 0.55
 *    (docs/robustness.md: below CGAL's jet in every PCPNet cell on the same points).
 * The degree-selection fitters of lower degrees are kept in f (made on
 * first use; remade only when the parameters change) and freed with it:
 * the library keeps no state outside the caller's fitter.  Defaults (off)
 * and constants: docs/robustness.md, bench_pcpnet.  With none set it is
 * exactly jf_fit_point.  Returns what jf_fit_point returns, or
 * JF_ERR_NOMEM (n > 512 with robust or dist_weight: a buffer in f is
 * allocated once, grown when a larger n is first seen; or a lower-degree
 * fitter could not be created).  Not thread-safe on one fitter, as
 * jf_fit_point. */
jf_status jf_fit_point_full(jf_fitter *f, const double p[3],
                            const double *nbr, size_t n, jf_result *out);

/* Fits every point i of a cloud from the neighbour lists
 * idx[off[i] .. off[i+1]-1] (CSR; off has n+1 entries, off[0] = 0; each
 * index < n, else JF_ERR_INVALID) with jf_fit_point_full (so robust and
 * scales are honoured; with scales, lists nearest first).  Non-finite points
 * get JF_PT_NONFINITE (and are skipped as neighbours).  The workspaces
 * hold the longest list even beyond p->max_neighbors.  OpenMP, one
 * fitter per thread; threads <= 0 means all cores.  Results are
 * bit-identical for any thread count.  Returns JF_OK, JF_ERR_INVALID or
 * JF_ERR_NOMEM. */
jf_status jf_fit_cloud(const jf_params *p, const double *xyz, size_t n,
                       const size_t *off, const uint32_t *idx, int threads,
                       jf_result *out);

/* ------------------------------------------------------------------ */
/* Plane curves (§4): 2D samples, jet y = f(x) of degree n             */
/* ------------------------------------------------------------------ */
typedef struct {
    unsigned status;     /* JF_PT_* flags                              */
    int degree;          /* degree used (0 when FAILED: all NaN)       */
    double cond;         /* kappa of the preconditioned system         */
    double coef[JF_MAX_DEGREE + 1]; /* B0..Bn in the fitting frame     */
    double normal[2];    /* unit normal                                */
    double tangent[2];   /* unit tangent                               */
    double k;            /* curvature 2B2/(1+B1^2)^(3/2), signed w.r.t.
                            normal (NaN at degree 1)                    */
    double dk;           /* dk/ds = [f'''(1+f'^2) - 3 f' f''^2]/(1+f'^2)^3
                            at x = 0, s along `tangent`; 0 if degree < 3
                            was asked, NaN if lowered below 3           */
} jf_curve_result;

/* Fits a curve jet at p from n 2D samples xy[2*i..] (n <= the fitter's
 * max_neighbors, else JF_ERR_TOO_LARGE).  The frame: translate to p, PCA
 * of the samples, x along the largest-variance axis (sign pinned: its
 * largest-|component| positive), y = x turned +90 degrees; `normal` is on
 * the +y side, (tangent, normal) direct.  degree 1..JF_MAX_DEGREE
 * whatever the fitter's degree; the same preconditioning (h = mean |x_i|),
 * SVD, adaptive degree and flags as surfaces; uses the fitter's
 * workspace and max_cond.  Not thread-safe on one fitter. */
jf_status jf_fit_curve(jf_fitter *f, const double p[2], const double *xy,
                       size_t n, int degree, jf_fit_mode mode,
                       jf_curve_result *out);

/* ------------------------------------------------------------------ */
/* Spatial index (k-d tree): exact k-NN and radius queries             */
/* ------------------------------------------------------------------ */
typedef struct jf_index jf_index;

/* Builds an index over the finite points of xyz (non-finite points are
 * left out: nobody's neighbour).  The finite points are copied (the index
 * takes about 28-32 bytes per point), so xyz may change or go after the
 * call.  n must be < UINT32_MAX (else JF_ERR_TOO_LARGE).  O(n log n).
 * Returns JF_OK, JF_ERR_INVALID (NULL out, or NULL xyz with n > 0) or
 * JF_ERR_NOMEM.  Free with jf_index_free (NULL is a no-op). */
jf_status jf_index_build(const double *xyz, size_t n, jf_index **out);
void jf_index_free(jf_index *ix);

/* Number of (finite) points indexed; bytes the index holds. */
size_t jf_index_size(const jf_index *ix);
size_t jf_index_memory(const jf_index *ix);

/* The k nearest indexed points to q, nearest first, in the exact order of
 * (squared distance, index): ties go to the smaller index, so results are
 * deterministic.  A query at a data point finds it first (distance 0;
 * among exact duplicates the smallest index comes first).  Writes
 * *found = min(k, jf_index_size) indices to idx (caller-owned, k entries)
 * and their squared distances to d2 (k entries) unless d2 is NULL.
 * Distances are computed as dx*dx + dy*dy + dz*dz, in that order.
 * Allocation-free, except when d2 == NULL and k > 1024 (a scratch buffer
 * is then allocated for the call).  Returns JF_ERR_INVALID for a
 * non-finite q or NULL pointers.  Thread-safe. */
jf_status jf_index_knn(const jf_index *ix, const double q[3], size_t k,
                       uint32_t *idx, double *d2, size_t *found);

/* The points within distance r >= 0 of q (inclusive: d2 <= r*r), nearest
 * first in the same (d2, index) order, at most `max` of them (the `max`
 * nearest when more lie within r); *found is their number.  Same buffers,
 * allocation rule and errors as jf_index_knn; a negative or non-finite r
 * is JF_ERR_INVALID.  Thread-safe. */
jf_status jf_index_radius(const jf_index *ix, const double q[3], double r,
                          size_t max, uint32_t *idx, double *d2,
                          size_t *found);

/* A cache-friendly processing order: the Morton (Z-order) permutation of
 * the points (63-bit keys: 21 bits per axis over the cubic bounding box of
 * the finite points; equal keys in index order; non-finite points last,
 * in index order).  Fills order[0..n-1] (caller-owned) with a permutation
 * of 0..n-1; deterministic.  Allocates 20 bytes per point during the call.
 * Returns JF_OK, JF_ERR_INVALID, JF_ERR_TOO_LARGE (n >= UINT32_MAX) or
 * JF_ERR_NOMEM.  Thread-safe. */
jf_status jf_spatial_order(const double *xyz, size_t n, uint32_t *order);

/* ------------------------------------------------------------------ */
/* Neighbourhoods (--neighbors): parse a spec, query it                */
/* ------------------------------------------------------------------ */
typedef enum {
    JF_NB_KNN,        /* knn:K       the K nearest points               */
    JF_NB_RADIUS,     /* radius:R    the points within R (inclusive)    */
    JF_NB_KNN_RADIUS, /* knn:K,radius:R  up to K nearest within R, with
                         a minimum-count fallback (jf_nb_query)         */
    JF_NB_RINGS,      /* rings[:N]   mesh rings (jf_nb_query_mesh)      */
    JF_NB_NATURAL,    /* natural[:N] §5.1 natural neighbours (the CGAL
                         bridge); n = 0 means its default              */
    JF_NB_AUTO        /* auto: per point, K among the JF_NB_AUTO_KMAX
                         nearest and the degree chosen without being
                         told the noise (params.auto_select; the
                         estimate runs it as knn:JF_NB_AUTO_KMAX), the
                         row's normal and curvatures then the mean of
                         its nearest points' fits (step 6)              */
} jf_nb_kind;

#define JF_NB_AUTO_KMAX 256 /* neighbors auto: the largest K it considers */

typedef struct {
    jf_nb_kind kind;
    size_t k;         /* knn, knn_radius: K >= 1                         */
    double r;         /* radius, knn_radius: R > 0, finite              */
    size_t n;         /* rings, natural: N >= 1, or 0 for the default   */
} jf_nb_spec;

/* Parses "knn:K", "radius:R", "knn:K,radius:R" (either order), "rings",
 * "rings:N", "natural", "natural:N", "auto" (no spaces; K, N positive decimal
 * integers; R a positive finite decimal number).  On error returns
 * JF_ERR_INVALID, leaves *spec unchanged and sets *why (if why != NULL)
 * to a static English reason.  Thread-safe. */
jf_status jf_nb_parse(const char *text, jf_nb_spec *spec, const char **why);

/* Writes the canonical text of a spec (what jf_nb_parse reads) into buf;
 * returns buf. */
char *jf_nb_format(const jf_nb_spec *s, char *buf, size_t len);

/* The neighbourhood of q for a point-cloud spec, nearest first in
 * (squared distance, index) order, into caller-owned idx (and d2 unless
 * NULL), `cap` entries each; *found is the count.  A query at a data
 * point returns it first.
 *  - knn:K          the min(K, cap) nearest.
 *  - radius:R       the points within R, capped by `cap` (the cap
 *                   nearest when more lie within R).
 *  - knn:K,radius:R the points within R, at most min(K, cap); if fewer
 *                   than M = min(min_count, K, cap) lie within R, the M
 *                   nearest regardless of R (min_count: what the fit
 *                   needs, e.g. N_n for the degree; K always bounds).
 *  - auto           the min(JF_NB_AUTO_KMAX, cap) nearest (the choice
 *                   among them is the fit's: params.auto_select).
 * rings and natural: JF_ERR_INVALID (use jf_nb_query_mesh / the bridge).
 * Allocation-free when d2 != NULL.  Thread-safe. */
jf_status jf_nb_query(const jf_index *ix, const jf_nb_spec *s,
                      size_t min_count, const double q[3], uint32_t *idx,
                      double *d2, size_t cap, size_t *found);

/* ------------------------------------------------------------------ */
/* Meshes (§5.1 mesh case): vertex adjacency and rings                 */
/* ------------------------------------------------------------------ */
typedef struct jf_mesh jf_mesh;

enum {                      /* per-vertex flags, jf_mesh_vertex_flags  */
    JF_MESH_ISOLATED = 1,   /* in no valid face: no neighbours         */
    JF_MESH_NONMANIFOLD = 2,/* on an edge shared by more than 2 faces  */
    JF_MESH_BOUNDARY = 4    /* on an edge of only one face             */
};

typedef struct {
    size_t degenerate_faces;    /* < 3 vertices or a repeated vertex:
                                   skipped                              */
    size_t nonmanifold_edges;   /* edges in more than 2 faces           */
    size_t nonmanifold_vertices;/* vertices on such an edge             */
    size_t boundary_edges;      /* edges in exactly one face            */
    size_t isolated_vertices;   /* vertices in no valid face            */
} jf_mesh_stats;

/* Builds the vertex adjacency of a polygon mesh of n vertices whose face f
 * has vertices face_idx[face_off[f] .. face_off[f+1]-1] (jf_cloud's
 * layout).  Degenerate faces are skipped and counted; non-manifold edges
 * and isolated vertices are reported (jf_mesh_get_stats, per-vertex
 * flags), never an error.  A vertex index >= n or decreasing offsets give
 * JF_ERR_FORMAT with err->msg = "face F: vertex index I out of range (n
 * vertices)" (err may be NULL).  Other returns: JF_OK, JF_ERR_INVALID,
 * JF_ERR_TOO_LARGE (n or nfaces >= UINT32_MAX), JF_ERR_NOMEM.  The arrays
 * are not kept.  Free with jf_mesh_free (NULL is a no-op). */
jf_status jf_mesh_build(size_t n, size_t nfaces, const size_t *face_off,
                        const uint32_t *face_idx, jf_mesh **out,
                        jf_error *err);
void jf_mesh_free(jf_mesh *m);

size_t jf_mesh_vertex_count(const jf_mesh *m);
/* n flags (JF_MESH_*), owned by the mesh. */
const uint8_t *jf_mesh_vertex_flags(const jf_mesh *m);
void jf_mesh_get_stats(const jf_mesh *m, jf_mesh_stats *s);
/* The distinct neighbours of v, ascending (owned by the mesh); returns
 * their number (0 for v out of range). */
size_t jf_mesh_neighbors(const jf_mesh *m, uint32_t v, const uint32_t **nbr);

/* The §5.1 mesh neighbourhood of vertex v: v first, then ring 1 (the
 * vertices one edge away), ring 2, ... each ring nearest to v first in
 * (squared distance, index) order; every vertex of the first k-1 rings,
 * then the nearest vertices of the k-th ring, until N points in all (or
 * cap: idx has cap entries, caller-owned).  *found < min(N, cap) when v's
 * connected component is smaller.  Vertices with non-finite coordinates
 * are left out (and not walked through).  JF_ERR_INVALID for N == 0, v out
 * of range or non-finite.  Allocation-free; thread-safe. */
jf_status jf_mesh_rings(const jf_mesh *m, const double *xyz, uint32_t v,
                        size_t N, uint32_t *idx, size_t cap, size_t *found);

/* Same order, but whole rings only: the fewest full rings holding at
 * least min_count points (v included); only `cap` can cut the last ring
 * (to its nearest vertices). */
jf_status jf_mesh_rings_full(const jf_mesh *m, const double *xyz, uint32_t v,
                             size_t min_count, uint32_t *idx, size_t cap,
                             size_t *found);

/* The neighbourhood of mesh vertex v for a rings spec:
 *  - rings:N   jf_mesh_rings(N).
 *  - rings     (n == 0, the default) interpolation: jf_mesh_rings(min_count)
 *              (min_count = N_n: interpolation uses exactly N_n points);
 *              approximation: jf_mesh_rings_full(2 * min_count), whole
 *              rings with at least 2 N_n points (degree 2 on a regular
 *              triangulation: 2 rings, 19 points; degree 4: 3 rings, 37).
 *              Why: whole rings keep the neighbourhood symmetric about v,
 *              and twice the unknowns keeps least squares well
 *              overdetermined -- the paper (§6.1) reports its degree-7
 *              approximation worse than expected because the rings gave
 *              only one point more than interpolation.
 * Other kinds: JF_ERR_INVALID.  Thread-safe. */
jf_status jf_nb_query_mesh(const jf_mesh *m, const double *xyz,
                           const jf_nb_spec *s, size_t min_count,
                           jf_fit_mode fit, uint32_t v, uint32_t *idx,
                           size_t cap, size_t *found);

/* ------------------------------------------------------------------ */
/* Clouds, meshes and files                                            */
/* ------------------------------------------------------------------ */
/* Per-point attributes carried from the input to the output (issue 13.4;
 * src/io/io_attrs.c): every PLY vertex property other than x y z (lists
 * excepted), every header-named CSV/XYZ column other than x y z, every LAS
 * dimension and Extra Byte.  Kept compact: one packed record of `stride`
 * bytes per point, each value in its input type, little endian (a PLY
 * `uchar red` costs one byte a point, not a double).  For a LAS input the
 * record IS the LAS point record, unchanged (X Y Z and the bit fields
 * included), so a LAS output can copy it byte for byte. */
typedef enum {
    JF_ATTR_I8 = 0, JF_ATTR_U8, JF_ATTR_I16, JF_ATTR_U16, JF_ATTR_I32,
    JF_ATTR_U32, JF_ATTR_I64, JF_ATTR_U64, JF_ATTR_F32, JF_ATTR_F64
} jf_attr_type;

typedef struct {
    char name[64];       /* as the input names it (characters a PLY or
                            CSV header cannot hold -- blanks, ',', '#'
                            -- replaced by '_')                         */
    jf_attr_type type;   /* the input's type                            */
    uint32_t offset;     /* byte offset of the value in a record        */
    uint8_t shift, bits; /* bits > 0: an unsigned bit field of the byte
                            at offset, (b >> shift) & (2^bits - 1)
                            (LAS return numbers, flags); type U8        */
    double scale_factor, add_offset; /* scale_factor != 0: the value
                            is raw * scale_factor + add_offset (a LAS
                            Extra Byte with the scale or offset option;
                            netCDF's names), written out as a double;
                            0: the raw value                            */
} jf_attr;

typedef struct {
    size_t nattrs;       /* 0: no attributes (and the rest NULL/0 but
                            las_head)                                   */
    jf_attr *attr;       /* nattrs descriptions                         */
    size_t stride;       /* bytes per point record                      */
    unsigned char *rec;  /* n * stride bytes, point i at rec + i*stride */
    unsigned char *las_head; /* LAS input only: the header block and
                            VLRs verbatim (las_head_len bytes, up to the
                            offset to point data); rec holds the point
                            records (NULL under no_attrs: las_head is
                            then kept for the CRS VLRs); else NULL      */
    size_t las_head_len;
    unsigned char *las_evlr; /* LAS 1.3/1.4 input: its EVLRs verbatim,
                            or NULL                                     */
    size_t las_evlr_len;
} jf_attrs;

/* Attribute j of point i as a double (bit fields decoded; 64-bit integers
 * beyond 2^53 rounded).  NaN if j or i is out of range (n is not known
 * here: the caller keeps i < the cloud's n).  Thread-safe. */
double jf_attr_get(const jf_attrs *a, size_t j, size_t i);

/* Index of the attribute named `name`, or -1. */
int jf_attr_find(const jf_attrs *a, const char *name);

/* Frees the arrays and zeroes *a (NULL or zeroed: no-op); jf_cloud_free
 * calls it. */
void jf_attrs_free(jf_attrs *a);

typedef struct {
    size_t n;            /* number of points                           */
    double *xyz;         /* 3n coordinates                             */
    double *nrm;         /* 3n normals read from the file, or NULL     */
    size_t nfaces;       /* mesh faces (0 for a cloud)                 */
    size_t *face_off;    /* nfaces+1 offsets into face_idx, or NULL    */
    uint32_t *face_idx;  /* polygon vertex indices, or NULL            */
    size_t nbad;         /* text rows that did not parse, kept as NaN
                            points (jf_read_opts.bad_rows = skip)      */
    size_t bad_line[10]; /* the first min(nbad, 10) of their lines     */
    uint32_t *scan;      /* PTX: scan of each point (n), else NULL     */
    double *scanner;     /* PTX: 3 nscans scanner positions in the
                            registered frame, else NULL                */
    size_t nscans;       /* PTX: number of scans, else 0               */
    jf_attrs attrs;      /* the input's other per-point values (above);
                            empty when jf_read_opts.no_attrs           */
} jf_cloud;

/* The phases of a run, as a progress hook (jf_phase_fn) names them. */
typedef enum {
    JF_PHASE_READ,   /* parsing the input (units: bytes of the file)     */
    JF_PHASE_ORDER,  /* the spatial order (Morton) of the points          */
    JF_PHASE_INDEX,  /* the k-d tree (its leaf order is the walk)         */
    JF_PHASE_FIT,    /* fitting (points; 2n with mst in blocks)           */
    JF_PHASE_WRITE   /* formatting and writing the rows (rows)            */
} jf_phase;

/* Progress of a phase: `done` of `total` units, non-decreasing within a
 * phase, reported once with done == total when the phase ends (0 to
 * total for a phase that is not split).  Called on the thread that called
 * the library function only (never concurrently); it must not call back
 * into the same object.  The library never prints: a command draws its
 * progress line from these calls. */
typedef void (*jf_phase_fn)(void *user, jf_phase phase, size_t done, size_t total);

typedef struct {
    int columns[6];      /* .xyz/.pts/.txt/.csv: 0-based column of x,y,z
                            [,nx,ny,nz]; -1 = default.  Defaults: xyz/txt
                            x y z first, and nx ny nz in columns 3..5
                            when rows have exactly 6 columns and the
                            first row's (3..5) has length 0.9..1.1 (so
                            "x y z r g b" is not read as normals); .pts
                            never takes default normals; .csv finds the
                            header names x,y,z[,nx,ny,nz] (any case).
                            x,y,z must be all set or all -1; normals
                            likewise.                                  */
    int bad_rows;        /* text formats: 0 (default) an unparsable row
                            is an error; 1 it is kept as a row of NaN
                            (so every later row keeps its index; the
                            pipeline marks it nonfinite) and counted in
                            jf_cloud.nbad / bad_line                   */
    int no_attrs;        /* 0 (default) read the attributes into
                            jf_cloud.attrs; 1 skip them (--keep none:
                            no memory spent on them)                   */
    int threads;         /* text formats: rows parsed in blocks on this
                            many OpenMP threads (<= 0, the default: all
                            cores); the cloud and every message are the
                            same for any count                          */
    jf_phase_fn progress; /* may be NULL (default): JF_PHASE_READ, in
                            bytes of the file                          */
    void *progress_user;
} jf_read_opts;

/* Sets every column to -1 (the defaults above).  Never fails. */
void jf_read_opts_init(jf_read_opts *o);

/* Reads a cloud or mesh; format from the extension, any case (.ply,
 * .xyz, .pts, .txt, .csv, .off).
 *  - PLY: ascii, binary_little_endian, binary_big_endian; vertex x y z
 *    (any numeric type), nx ny nz when all present; other properties,
 *    elements and lists are skipped; a `face` element (list
 *    vertex_indices or vertex_index) fills the face arrays.
 *  - XYZ/PTS/TXT: whitespace (or ',' ';') separated, 3 or more columns,
 *    '#' and '//' comments, blank lines skipped; a line holding one
 *    integer (a point count, as PTS files start) is skipped; a first line
 *    of names only is a header (x,y,z[,nx,ny,nz] found by name as CSV).
 *  - CSV: comma separated; a header line naming the columns, or no header
 *    (all-numeric first line: x y z first).
 *  - OFF (also COFF/NOFF/STOFF variants; NOFF normals are read): polygons
 *    of any size >= 3; indices are checked against the vertex count.
 *  - PTX: one or more scans (header: cols, rows, scanner position, axes,
 *    4x4 row-vector transform); points moved to the registered frame;
 *    "0 0 0" (no return) kept as a NaN row; fills scan/scanner/nscans.
 *  - LAS 1.0-1.4, point formats 0-10: x = X * scale + offset.
 *  - LAZ (.laz, or .las with the compression bit): LASzip, point formats
 *    0-3 and 6-8, decoded on the OpenMP threads, then read as that LAS.
 * Attributes (jf_cloud.attrs, unless o->no_attrs): PLY every scalar
 * vertex property but x y z, in its type; CSV/XYZ with a header line
 * every named column but x y z whose fields are all numbers (empty: NaN),
 * packed as uchar, ushort or int when every value is such an integer,
 * else double; LAS the record whole, described as laspy names its
 * dimensions (intensity, return_number, ..., gps_time, red, ...) and the
 * Extra Bytes by their descriptions (scalar types), plus the header,
 * VLRs and EVLRs verbatim.
 * "nan", "inf" are read as such (a NaN coordinate is kept, not an error).
 * A file without points (empty, comments only, 0 vertices) is an error.
 * o may be NULL (defaults).  c is overwritten (not freed first).
 * On failure returns the status (JF_ERR_IO, JF_ERR_FORMAT,
 * JF_ERR_TOO_LARGE, JF_ERR_NOMEM, JF_ERR_INVALID, JF_ERR_UNSUPPORTED),
 * fills err (may be NULL) with one line "FILE:LINE: reason" (text) or
 * "FILE: element vertex 12: reason" (binary PLY), and leaves *c zeroed
 * with nothing allocated.  Thread-safe (no shared state). */
jf_status jf_cloud_read(const char *path, const jf_read_opts *o,
                        jf_cloud *c, jf_error *err);

/* Frees the arrays and zeroes *c; c may be NULL or already zeroed. */
void jf_cloud_free(jf_cloud *c);

/* ------------------------------------------------------------------ */
/* Writing tables and meshes                                           */
/* ------------------------------------------------------------------ */
/* A table: one row per point, named columns; format from the extension:
 *  .ply  binary little endian (or ascii), element `vertex` with one
 *        property per column named as the column (CloudCompare/MeshLab
 *        show them as scalar fields); F64 -> double, F32 -> float,
 *        I32 -> int.
 *  .csv  one header line "x,y,z,...", then comma separated rows.
 *  .xyz/.txt  one header line "# x y z ...", then space separated rows.
 * Text is exact: F64 with %.17g, F32 with %.9g (both read back bit for
 * bit); NaN is written "nan", infinities "inf"/"-inf".  I32 values are
 * rounded to nearest; NaN or out-of-range values become INT32_MIN.
 * The file is written to a temporary ".NAME.tmp.PID" in the same folder
 * and renamed onto NAME only by a successful jf_writer_commit: after a
 * failure or jf_writer_abort no file with the final name is created (an
 * existing one is left untouched).  A writer is used by one thread.
 * F32_Q16 is F32 of the value rounded to the nearest multiple of 2^-16
 * (a unit vector's components: error <= 2^-17, 7.6e-6; the float's low
 * mantissa bits are zero, which LASzip's extra-byte coder stores almost
 * for free: jetfit estimate's .laz, docs/formats.md). */
typedef enum { JF_COL_F64 = 0, JF_COL_F32 = 1, JF_COL_I32 = 2, JF_COL_F32_Q16 = 3 } jf_col_type;

typedef struct {
    const char *name;    /* column / property name (copied at open)    */
    jf_col_type type;
} jf_column;

typedef struct jf_writer jf_writer;

/* The estimate's output table: x y z nx ny nz k1 k2 d1x d1y d1z d2x d2y d2z,
 * then b0..b3 when monge >= 3 and c0..c4 when monge >= 4 (the Monge degree
 * of the fit), then degree neighbors cond residual, then sigma when sigma
 * is non-zero (the noise estimate of neighbors auto), then status (I32
 * for degree, neighbors and status).  jf_result_columns fills cols (at least
 * JF_RESULT_MAX_COLS entries; names are static) and returns their number;
 * jf_result_row writes point p's row of r into v in that order and
 * returns the number of values.  The command, jetfit-mpi and the Python
 * module write this one list.  Thread-safe. */
#define JF_RESULT_MAX_COLS 32
size_t jf_result_columns(int monge, int sigma, jf_column *cols);
size_t jf_result_row(const double p[3], const jf_result *r, int monge, int sigma, double *v);

/* Opens a table of ncols columns and exactly nrows rows (the PLY header
 * needs the count; commit fails if a different number was written).
 * ascii != 0 asks for ascii PLY (ignored for text formats).  Names must
 * be non-empty without whitespace, ',' or '#'.  On failure *w is NULL, err
 * (may be NULL) says why, nothing is left on disk. */
jf_status jf_writer_open(const char *path, const jf_column *cols,
                         size_t ncols, size_t nrows, int ascii,
                         jf_writer **w, jf_error *err);

/* LAS output (.las: LAS 1.4, point format 0 holding x y z, every other
 * column an Extra Byte named as the column; x y z must be the first three
 * columns): the coordinates are stored as int32 counts of a scale chosen
 * from the cloud's bounding box (0.1 um where the extent allows, 1e-7 m
 * up to ~200 m), so the cloud must be given before the first row.  A
 * no-op for other formats.  JF_ERR_INVALID after the first row. */
jf_status jf_writer_las_frame(jf_writer *w, const double *xyz, size_t n);

/* jf_writer_las_frame with the scale and offset of each axis given
 * (scale[a] > 0; either array may be NULL: that one by the rule, the
 * offset being the minimum).  Without a scale given, a warning
 * (jf_writer_warnings) names each axis the rule's scale rounds by more than
 * 1e-6 of the cloud's bulk size (the largest range of the middle 99% of
 * the points over the axes: an outlier widening the extent).  Coordinates
 * that cannot be stored as int32 counts (an extent beyond the largest
 * double, a scale too small for them) are refused here: JF_ERR_TOO_LARGE,
 * the writer failed (commit says which axis and extent, no file is made).
 * JF_ERR_INVALID for a scale <= 0 or not finite, after the first row. */
jf_status jf_writer_las_frame_given(jf_writer *w, const double *xyz, size_t n,
                                    const double scale[3], const double offset[3]);

/* The writer's warnings so far, lines "FILE: reason" each ending in a
 * newline ("" if none), for the caller to show: LAS, an Extra Bytes name
 * over 32 bytes shortened (to its first bytes and "~N", the first N giving
 * a name no other holds), the
 * rule's scale rounding coordinates (above), input VLRs that run past the
 * point data and are not copied.  Owned by w; valid until the next call on
 * w.  Never NULL. */
const char *jf_writer_warnings(jf_writer *w);

/* Carries a cloud's attributes (jf_cloud.attrs) into the table: their
 * columns go after x y z (columns 0-2) and before the others, each named
 * as in the input with `in_` put before the name while it clashes with a
 * column of the table or an earlier attribute (an input `nx` is written
 * `in_nx`).  PLY: each property in its input type (64-bit integers as
 * double); text: integers exact, floats and doubles %.17g (the exact
 * value, so a reader gets the same number back); LAS: from a
 * LAS input (a->las_head and a->rec) the input's point records are written unchanged
 * -- same point format, scale, offset, header fields, VLRs and EVLRs --
 * with the table's columns 3.. appended as Extra Bytes after the input's
 * own (x y z of the rows are then not used, and jf_writer_las_frame is
 * not needed); from another input, format 0 with the attributes as Extra
 * Bytes of their type ahead of the table's (a LAS input read without its
 * records, no_attrs: format 0 with the input's CRS VLRs copied).  Row r of the table carries
 * the attributes of point r (rows are in input order): `a` is read while
 * rows are written and must stay valid until commit.  Call before the
 * first row.  A table with no attribute (nattrs 0, not LAS) is a no-op.
 * Returns JF_OK, JF_ERR_INVALID (rows already written, called twice,
 * fewer than 3 columns, a name that cannot be made unique),
 * JF_ERR_TOO_LARGE (LAS: a record over 65535 bytes or more than 341
 * Extra Bytes), JF_ERR_NOMEM. */
jf_status jf_writer_attrs(jf_writer *w, const jf_attrs *a);

/* PLY only (ignored by text formats): also write a `face` element
 * (list uchar int vertex_indices; list uint int when a polygon has more
 * than 255 vertices) from nfaces polygons idx[off[f] .. off[f+1]-1], so
 * a mesh keeps its faces.  Call before the first row; the arrays are read
 * at commit and must stay valid until then.  JF_ERR_INVALID if rows were
 * already written, the offsets decrease or an index is >= nrows (or
 * over INT32_MAX). */
jf_status jf_writer_faces(jf_writer *w, size_t nfaces, const size_t *off,
                          const uint32_t *idx);

/* Appends one row: vals[0..ncols-1], in column order.  Buffered (no
 * system call per row).  After the first failure every call returns it
 * and commit reports it. */
jf_status jf_writer_row(jf_writer *w, const double *vals);

/* Appends nrows rows, vals[r * ncols + j] (row-major), exactly as nrows
 * calls of jf_writer_row would, formatting them on `threads` OpenMP
 * threads (<= 0: the OpenMP default) and writing them in order: blocks
 * of rows handed out one at a time, each written when its turn comes
 * while the other threads format the next ones.  Writing the file is
 * otherwise serial: this is what keeps it off the critical path of a
 * parallel run (text output above all).  Allocates about threads x 4096
 * x (32 ncols + 2) bytes for the call.  Same errors as jf_writer_row. */
jf_status jf_writer_rows(jf_writer *w, const double *vals, size_t nrows,
                         int threads);

/* Progress of the rows' formatting and writing: fn(user,
 * JF_PHASE_WRITE, rows written, nrows) after each round of
 * jf_writer_rows (jf_writer_commit's, for positioned rows), on the
 * calling thread.  fn may be NULL (none).  Call before the first row. */
void jf_writer_progress(jf_writer *w, jf_phase_fn fn, void *user);

/* Positioned rows, for results that arrive out of order
 * (jf_estimate_blocks): jf_writer_begin_put once, on one thread, after
 * jf_writer_las_frame / jf_writer_faces and instead of any
 * jf_writer_row(s); then jf_writer_put from any number of threads at
 * once; then jf_writer_commit.  The file's bytes are exactly those that
 * jf_writer_rows would write with the rows in row order, for every
 * format.  The rows go as raw doubles to a second temporary in the
 * output's folder (a jf_tmpfile: removed on failure, abort or a signal;
 * about nrows x (8 ncols + 8) bytes), bucketed by row number so that its
 * writes are large whatever the order; commit reads it back in row order
 * (one bucket of up to 32 MiB at a time), formats the rows with
 * jf_writer_rows on `threads` threads (<= 0: the OpenMP default) and
 * removes it.  Memory: 64 KiB of staging per 32 MiB of rows.  Begin:
 * JF_ERR_INVALID after a row was written, else the header's write or
 * the spool's creation status. */
jf_status jf_writer_begin_put(jf_writer *w, int threads);

/* Writes m rows: vals[j * ncols ..] is row rows[j] (< nrows), in any
 * order; over the writer's life each row must be put exactly once
 * (commit checks).  Thread-safe against other jf_writer_put calls on w;
 * no allocation.  After a failure (a write error, a row out of range)
 * every call returns it and commit reports it. */
jf_status jf_writer_put(jf_writer *w, const uint32_t *rows, const double *vals, size_t m);

/* Flushes, closes, checks the row count and renames the temporary onto
 * the final name.  Frees w whatever happens (w may be NULL: invalid).
 * On failure the temporary is removed and err says why. */
jf_status jf_writer_commit(jf_writer *w, jf_error *err);

/* Removes the temporary and frees w.  NULL is a no-op. */
void jf_writer_abort(jf_writer *w);

/* Writes a cloud or mesh (vertices, normals if c->nrm, faces if
 * c->nfaces) with the same temporary-then-rename rule; format from the
 * extension: .off (NOFF when normals are present), .ply (binary little
 * endian, or ascii if ascii != 0; x y z [nx ny nz] as double, face
 * element list uchar int vertex_indices), .xyz/.txt/.csv (vertices and
 * normals only; faces are not written), .las (LAS 1.4 format 0, the frame
 * of jf_writer_las_frame; normals as Extra Bytes nx ny nz; faces are not
 * written).  The rows are formatted on the OpenMP threads
 * (jf_writer_rows; the bytes do not depend on their count).  Thread-safe. */
jf_status jf_cloud_write(const char *path, const jf_cloud *c, int ascii,
                         jf_error *err);

/* ------------------------------------------------------------------ */
/* Evaluation (src/eval/eval.c): error measures against ground truth        */
/* ------------------------------------------------------------------ */

/* Unoriented angle between two directions in degrees, in [0, 90]:
 * acos(|a.b| / (|a||b|)) (PCPNet's measure).  NaN if either is zero or
 * non-finite.  Thread-safe. */
double jf_normal_angle_deg(const double a[3], const double b[3]);

/* PCPNet's curvature error |k - k_true| / max(|k_true|, 1). */
double jf_curv_error_rel(double k, double k_true);

/* Errors of estimated curvatures (k1 >= k2 w.r.t. n) against the truth
 * (k1_true >= k2_true w.r.t. n_true): the estimate is first oriented along
 * n_true (flip: k1, k2 -> -k2, -k1).  Fills err_abs[2] |k - k_true| and
 * err_rel[2] (jf_curv_error_rel) for k1 and k2; either may be NULL. */
void jf_curv_compare(const double n[3], double k1, double k2,
                     const double n_true[3], double k1_true, double k2_true,
                     double err_abs[2], double err_rel[2]);

/* Summary of a sample of errors. */
typedef struct {
    size_t n;          /* finite values summarised                      */
    size_t nonfinite;  /* NaN/Inf values left out                       */
    double rms, mean, median, p95, max; /* quantiles interpolate
                          linearly between order statistics (numpy's
                          default); NaN when n == 0                     */
} jf_err_stats;

/* Summarises v[0..n-1].  Reorders v in place (finite values first,
 * sorted).  JF_ERR_INVALID on NULL.  Thread-safe on distinct arrays. */
jf_status jf_err_stats_compute(double *v, size_t n, jf_err_stats *s);

/* A table of numbers with named columns, row-major. */
typedef struct {
    size_t nrows, ncols;
    char (*names)[32];   /* ncols names ("" when unknown)              */
    double *v;           /* nrows * ncols values                       */
} jf_eval_table;

/* Reads a whole table; columns are named by: .csv a header line; .xyz,
 * .txt, .pts the last "# name name ..." comment before the data (jetfit's
 * and generate's outputs); .ply the vertex element's properties (ascii or
 * binary_little_endian; other elements must come after it and are
 * ignored); .las x y z then every dimension and Extra Byte as
 * jf_cloud_read's attributes name them (a LAS jetfit wrote: its columns); headerless files by extension: .normals nx ny nz, .curv k1 k2
 * (PCPNet's column order, not re-sorted), .pidx index, otherwise
 * x y z nx ny nz k1 k2.  On failure fills err ("FILE:LINE: reason") and
 * leaves *t empty.  The table is owned by the caller: jf_eval_table_free. */
jf_status jf_eval_table_read(const char *path, jf_eval_table *t,
                             jf_error *err);

/* Index of the column named `name`, or -1. */
int jf_eval_table_col(const jf_eval_table *t, const char *name);

void jf_eval_table_free(jf_eval_table *t); /* NULL or zeroed: no-op */

/* ------------------------------------------------------------------ */
/* Orientation (src/spatial/orient.c)                                          */
/* ------------------------------------------------------------------ */
/* Each call flips whole results (jf_result_flip: curvature signs, k1/k2,
 * d1/d2 and Monge coefficients follow the normal).  Results with
 * JF_PT_FAILED or JF_PT_NONFINITE, or a non-finite normal, are left
 * alone; a point whose side cannot be decided (n.dir == 0, isolated point)
 * gets JF_PT_ORIENT_UNKNOWN.  Not thread-safe on one res array. */
typedef enum {
    JF_ORIENT_NONE = 0,      /* as fitted                                */
    JF_ORIENT_INPUT = 1,     /* agree with the normals read from the file */
    JF_ORIENT_VIEWPOINT = 2, /* point towards a scanner position          */
    JF_ORIENT_MST = 3,       /* propagate along a k-NN minimum spanning
                                tree (Hoppe et al. 1992)                 */
    JF_ORIENT_SCANNER = 4,   /* towards the scanner that measured each
                                point (jf_cloud.scan / scanner: PTX)     */
    JF_ORIENT_AUTO = 5       /* the estimate's default: scanner when the
                                cloud has scanner positions, else input
                                when it has normals, else none
                                (jf_orient_resolve)                      */
} jf_orient_mode;

/* The mode JF_ORIENT_AUTO stands for on a cloud that has (non-zero) or
 * has not normals and scanner positions: JF_ORIENT_SCANNER, else
 * JF_ORIENT_INPUT, else JF_ORIENT_NONE; any other mode is returned as it
 * is.  The one place of the rule, for callers that hold no jf_cloud
 * (jetfit-mpi); jf_estimate* apply it themselves.  Thread-safe. */
jf_orient_mode jf_orient_resolve(jf_orient_mode m, int has_normals, int has_scanners);

/* res[i] agrees with nrm[3i..3i+2] (n_i . nrm_i >= 0).  nrm is caller-owned. */
jf_status jf_orient_input(jf_result *res, size_t n, const double *nrm);

/* res[i] points towards vp: n_i . (vp - p_i) >= 0. */
jf_status jf_orient_viewpoint(jf_result *res, const double *xyz, size_t n,
                              const double vp[3]);

/* res[i] points towards the scanner of its scan: n_i . (scanner[3 scan[i]]
 * - p_i) >= 0.  JF_ERR_INVALID if a scan index is >= nscans. */
jf_status jf_orient_scanner(jf_result *res, const double *xyz, size_t n,
                            const uint32_t *scan, const double *scanner, size_t nscans);

/* Consistent orientation by Prim's algorithm on the graph of the k nearest
 * neighbours (ix built over xyz), weights 1 - |ni.nj|: each newly reached
 * normal is flipped to agree with its tree parent.  Components are
 * handled separately: each starts at its point of largest z, oriented
 * towards +z (outward on a closed surface).  Memory O(n) (about 24 bytes
 * per point; neighbours are queried again, not stored), single-threaded,
 * deterministic.  k in 1..1024 (8 is a good default). */
jf_status jf_orient_mst(jf_result *res, const double *xyz, size_t n,
                        const jf_index *ix, size_t k);

/* Same on a stored graph: nbr[i*k .. i*k+k-1] are point i's neighbours
 * (nearest first; UINT32_MAX = none; i itself is ignored), e.g. the first
 * k of each fitting neighbourhood, as jf_estimate does (no queries). */
jf_status jf_orient_mst_graph(jf_result *res, const double *xyz, size_t n,
                              const uint32_t *nbr, size_t k);

/* ------------------------------------------------------------------ */
/* Natural neighbourhoods (§5.1, point clouds; src/spatial/natural.c over */
/* CGAL bridge)                                                        */
/* ------------------------------------------------------------------ */
typedef enum {
    JF_NORMAL_POLES = 0,   /* Amenta-Bern pole, mincirc where unreliable */
    JF_NORMAL_MINCIRC = 1, /* minimum-circumradius triangle (§5.1)       */
    JF_NORMAL_PCA = 2,     /* the caller's (not computed here)           */
    JF_NORMAL_INPUT = 3,   /* the caller's (not computed here)           */
    JF_NORMAL_JET = 4,     /* jf_estimate: jet normal of knn:N, natural
                              rings on the points projected on their jet,
                              and those projected points fitted (the
                              residual is still the raw ring's; not
                              computed here)                             */
    JF_NORMAL_AUTO = 5     /* jf_estimate's default: JET when the cloud is
                              noisy (JF_NATURAL_NOISY_*), else PCA; the
                              cells from k-NN candidates (no
                              triangulation: jf_natural_create_knn)     */
} jf_normal_source;

/* A pole whose reliability (pole distance / nearest-neighbour distance)
 * is below this is replaced by the mincirc normal.  Measured by
 * `bench_natural reliability` (20k samples of a sphere and of the §6.1
 * surface, normal noise 0 / 0.1 / 0.3 / 1 x the spacing): in every
 * reliability bin >= 1 the pole's mean error is below mincirc's (e.g.
 * [1,2): 21 vs 35 deg); below 1 mincirc wins on the clean rim of the
 * open patch (0.1 vs 26 deg) and on the noisy sphere (61 vs 68 deg). */
#define JF_NATURAL_MIN_RELIABILITY 1.0

/* JF_NORMAL_AUTO calls a cloud noisy when the median, over up to 2000
 * points, of the RMS residual of a degree-2 jet fitted to 20 natural
 * neighbours, relative to their RMS distance to the point, is above this
 * (a clean surface leaves a residual of higher order; docs/natural.md). */
#define JF_NATURAL_NOISY_RESIDUAL 0.02

/* The 3D Delaunay triangulation of a cloud, kept as plain arrays (vertex
 * map, adjacency, poles, a copy of the coordinates): xyz may be freed
 * after create.  About 170 bytes per point (mean Delaunay degree ~18);
 * create peaks at ~750 bytes per point while CGAL's triangulation exists
 * (1M points of the §6.1 surface: 751 MiB vs 645 MiB for a plain CGAL
 * Delaunay_triangulation_3; tests/bench/bench_natural.cpp). */
typedef struct jf_natural jf_natural;

/* Builds it over the finite points of xyz[3n] (non-finite points are left
 * out: nobody's neighbour, no normal); identical points are merged into
 * one vertex (jf_natural_kept).  Coplanar, collinear or fewer than 4
 * points are accepted (jf_natural_stats says the dimension).  Returns
 * JF_OK, JF_ERR_INVALID (NULL args), JF_ERR_TOO_LARGE (n >= 2^32 - 1),
 * JF_ERR_NOMEM, JF_ERR_INTERNAL (CGAL threw).  Uses every core; the
 * _threads form takes the count (<= 0: every core).  The result is the
 * same bit for bit for any count (docs/natural.md, "Speed"). */
jf_status jf_natural_create(const double *xyz, size_t n, jf_natural **out);
jf_status jf_natural_create_threads(const double *xyz, size_t n, int threads,
                                    jf_natural **out);
void jf_natural_free(jf_natural *nt);

/* The same neighbourhoods without a triangulation: each cell is clipped
 * by the point's 16 nearest samples from a k-d tree (queried when the
 * cell is made; about 40 bytes per point with the tree), and is exact
 * (the same as the triangulation's up to rounding) once a certificate
 * holds: every vertex of the cell is within half the distance inside
 * which every sample has cut it (the last candidate's, or the reach of
 * the leaves their search read), or no sample lies in a ball enclosing
 * the others' empty-circle balls; the query widens to 144 candidates
 * before a cell is accepted as clipped by the box (the rim of an open
 * scan).  No vertex merging (identical
 * points stay separate; only one of them is anyone's neighbour), no
 * poles: jf_natural_normals returns JF_ERR_INVALID on it, the caller
 * brings the normals (jf_estimate: PCA or jet).  jf_natural_get_stats
 * reports dimension 3 and no timings.  Same returns as create; the
 * result does not depend on the thread count. */
jf_status jf_natural_create_knn(const double *xyz, size_t n, int threads,
                                jf_natural **out);

typedef struct {
    int dimension;       /* 3; 2 = all coplanar (no poles: mincirc);
                            1 = collinear; 0 = one point; -1 = none     */
    size_t nvertices;    /* distinct finite points                      */
    size_t nduplicates;  /* finite points identical to a kept one       */
    size_t nnonfinite;   /* points with a NaN/Inf coordinate            */
    double seconds[3];   /* wall time of create's spatial sort, CGAL's
                            (sequential) insertion and the (parallel)
                            extraction of adjacency and poles          */
    double cpu_seconds[3]; /* the same in CPU time (the process's, all
                            threads; bench_natural's profile)          */
} jf_natural_stats;

/* Fills *st.  Thread-safe. */
void jf_natural_get_stats(const jf_natural *nt, jf_natural_stats *st);

/* The input index carrying point i's vertex: i itself, or the smallest
 * index of a point identical to i; SIZE_MAX if i is non-finite or out of
 * range.  i is a merged duplicate iff the result differs from i. */
size_t jf_natural_kept(const jf_natural *nt, size_t i);

/* Tangent-plane normals of every point for src = POLES (mincirc fallback
 * where the pole is unreliable) or MINCIRC (JF_ERR_INVALID for the
 * others): nrm[3n] (unit, unoriented), flags[n] |= JF_PT_NORMAL_POLES /
 * JF_PT_NORMAL_MINCIRC / JF_PT_NORMAL_FALLBACK (flags are or-ed in, not
 * cleared), reliability[n] (may be NULL) gets the pole figure in both
 * modes (0 where there is no usable pole).  A merged duplicate gets the
 * normal and flags of its kept point.  Points that get no normal
 * (collinear neighbourhood, non-finite) get NaN and JF_PT_FAILED (plus
 * JF_PT_NONFINITE).  threads <= 0: all cores; output independent of it. */
jf_status jf_natural_normals(const jf_natural *nt, jf_normal_source src,
                             int threads, double *nrm, unsigned *flags,
                             double *reliability);

/* Per-thread workspace for the neighbour queries (about 4 bytes per
 * point plus buffers; allocated once, grown only on rare huge rings). */
typedef struct jf_natural_ws jf_natural_ws;
jf_status jf_natural_ws_create(const jf_natural *nt, jf_natural_ws **out);
void jf_natural_ws_free(jf_natural_ws *ws);

/* The natural neighbours of point i in the plane through it with normal
 * nrm (need not be unit): the samples whose power cells are adjacent in
 * the power diagram of the samples projected on that plane with weights
 * -(distance to the plane)^2 (the trace of the 3D Voronoi diagram, exact
 * up to floating-point rounding); grown ring by ring (neighbours of
 * neighbours) until N points, each ring sorted nearest first, the last
 * one cut.  idx[0] = i; *found <= min(N, cap) (smaller when the cloud
 * runs out; JF_PT_FEW_NEIGHBORS is the caller's).  A non-finite point
 * gets *found = 0.  Returns JF_OK, or JF_ERR_INVALID (bad i, NULL, nrm
 * zero or non-finite), JF_ERR_NOMEM.  Thread-safe on a const nt with one
 * ws per thread. */
jf_status jf_natural_neighbors(const jf_natural *nt, jf_natural_ws *ws,
                               size_t i, const double nrm[3], size_t N,
                               uint32_t *idx, size_t cap, size_t *found);

/* Same neighbourhood by whole rings: idx gets i then planar rings
 * 1..nrings complete (each nearest first); ring_end[r] (may be NULL;
 * nrings+1 entries) is the end of ring r in idx.  JF_ERR_TOO_LARGE if
 * cap is too small. */
jf_status jf_natural_rings(const jf_natural *nt, jf_natural_ws *ws,
                           size_t i, const double nrm[3], int nrings,
                           uint32_t *idx, size_t cap, size_t *found,
                           size_t *ring_end);

/* ------------------------------------------------------------------ */
/* Output files that appear whole or not at all (src/io/io_tmpfile.c)  */
/* ------------------------------------------------------------------ */
/* Every writer of the library goes through this; it is public so that a
 * program writing its own files (a picture, a report) gets the same
 * guarantees.  The temporary is created beside the final file, under an
 * unpredictable name, exclusively (a planted file or link is never
 * followed), even for a final name near the 255-byte limit.  A final path
 * that is a symbolic link is written through to its target (as cp does).
 * The new file keeps the mode of the file it replaces, else 0666 less the
 * umask. */
typedef struct {
    int fd;          /* write here (open, O_RDWR: a spool reads back)  */
    char *tmp;       /* the temporary's path                           */
    char *target;    /* the file that commit replaces                  */
    int slot;        /* internal: its place in the signal-safe list    */
} jf_tmpfile;

/* Creates the temporary for `final`.  JF_OK, or JF_ERR_IO / _INVALID /
 * _NOMEM with err "FINAL: reason" and *t holding nothing (an existing
 * final that is a folder, FIFO, device or socket: JF_ERR_IO).
 * Thread-safe. */
jf_status jf_tmpfile_open(const char *final, jf_tmpfile *t, jf_error *err);
/* Closes the temporary and renames it onto its target; on failure removes
 * it.  JF_ERR_IO when the temporary's name no longer holds the file t->fd
 * is open on (another process replaced it).  Either way *t holds nothing
 * afterwards. */
jf_status jf_tmpfile_commit(jf_tmpfile *t, const char *final, jf_error *err);
/* Closes and removes the temporary (t may be NULL or empty). */
void jf_tmpfile_discard(jf_tmpfile *t);
/* Removes every temporary of this process that is not yet committed or
 * discarded: unlink(2) only, async-signal-safe, for a SIGINT/SIGTERM
 * handler. */
void jf_tmpfiles_remove_all(void);
/* 1 when a and b name the same existing file (device and inode, links
 * followed), else 0. */
int jf_same_file(const char *a, const char *b);

/* ------------------------------------------------------------------ */
/* Estimation pipeline (src/estimate/): a whole cloud, with OpenMP    */
/* ------------------------------------------------------------------ */
#define JF_ESTIMATE_DEFAULT_K 32   /* knn:32, the command's default    */

/* Progress report: `done` of `total` points fitted.  Called on the
 * thread that called jf_estimate only (never concurrently), a few
 * hundred points apart, and once with done == total. */
typedef void (*jf_progress_fn)(void *user, size_t done, size_t total);

/* Cancellation hook: returns nonzero to stop.  Polled on the thread that
 * called jf_estimate only (never concurrently): after each block of a few
 * hundred points that thread fits, and between the stages (index or
 * triangulation, fitting, orientation).  Once it says stop, every thread
 * leaves the fit after its current block and jf_estimate returns
 * JF_ERR_CANCELLED (out is then partly filled).  A stage that is not
 * split into blocks (the k-d tree, the natural neighbours' Delaunay
 * triangulation and tangent-plane normals, the mst orientation) runs to
 * its end first.  `jetfit study`'s Ctrl-C and the Python module's
 * KeyboardInterrupt go through it. */
typedef int (*jf_cancel_fn)(void *user);

typedef struct {
    jf_params params;        /* the fit (params.max_neighbors must hold
                                the neighbourhood: knn K, rings N, ...)  */
    jf_nb_spec nb;           /* neighbourhood (default knn:32; K and N
                                count the point itself).  natural with
                                n = 0: max(2 N_n, 12) points            */
    jf_normal_source normal; /* natural only: tangent planes from auto
                                (default: jet on a noisy cloud, else
                                pca), poles, mincirc, pca (PCA of the
                                16 nearest points), jet (jet normal of
                                the N nearest, rings on the cloud
                                projected on those jets) or input       */
    jf_orient_mode orient;   /* default JF_ORIENT_AUTO (jf_orient_resolve) */
    double viewpoint[3];     /* JF_ORIENT_VIEWPOINT                     */
    size_t orient_k;         /* JF_ORIENT_MST: k of the k-NN graph (8)  */
    int threads;             /* <= 0: all cores (OpenMP default)        */
    jf_progress_fn progress; /* may be NULL                             */
    void *progress_user;
    jf_cancel_fn cancel;     /* may be NULL (jf_cancel_fn)              */
    void *cancel_user;
    jf_phase_fn phase;       /* may be NULL: JF_PHASE_INDEX or _ORDER
                                (0 then n), then JF_PHASE_FIT (as
                                progress counts); jf_estimate_parts:
                                per part, with the part's counts        */
    void *phase_user;
    int *auto_chosen;        /* may be NULL: where the estimate decides
                                step 0 (neighbors auto, params.auto_select
                                1 with or without flags), the decision, in
                                params.auto_select's form (the cap on K or
                                1 for none, | JF_AUTO_FLAGS), is written
                                here; untouched otherwise                */
} jf_estimate_opts;

/* Fills defaults (params.monge_degree 0: from the degree, see
 * jf_monge_degree_of).  Never fails. */
void jf_estimate_opts_init(jf_estimate_opts *o);

/* The options as text, by parameter name (src/estimate/options.c): the
 * one parser the command, jetfit-mpi, jetfit study and the Python module
 * share, so a value means the same in each.  Names: neighbors (as
 * jf_nb_parse), degree (1..9), monge_degree (2..4), fit (approx|interp),
 * frame (pca|axis), max_cond (>= 1), orient (none|input|scanner|mst[:K]|
 * viewpoint:X,Y,Z), normal (auto|poles|mincirc|pca|jet|input), robust
 * (none|huber|tukey), scales (K1,K2,... ascending, >= 3, at most 8),
 * degree_select (1..9), dist_weight (> 0), threads (1..4096), and
 * robust_normals (a preset: degree_select 1, dist_weight 0.55; value
 * ignored).  JF_OK, or JF_ERR_INVALID with *why (static English, naming
 * parameters, never flags) and o's field unchanged.  Thread-safe. */
jf_status jf_estimate_opts_set(jf_estimate_opts *o, const char *name, const char *value,
                               const char **why);
/* After the last set: the Monge degree from the degree where it is 0
 * (jf_monge_degree_of; a larger one given is refused), params.max_neighbors
 * raised to the largest neighbourhood (K, N, the scales, auto's 256), and
 * every rule of the parameters checked (jf_params_validate).  JF_OK, or
 * JF_ERR_INVALID with *param (the parameter at fault) and *why. */
jf_status jf_estimate_opts_finish(jf_estimate_opts *o, const char **param, const char **why);
/* The Monge degree an estimate of this jet degree uses by default:
 * min(max(degree, 2), 4) (degree 1 has no curvature: its columns are NaN). */
int jf_monge_degree_of(int degree);
/* The reading options as text: columns ("x,y,z" or six 0-based column
 * numbers) and bad_rows (error|skip).  As jf_estimate_opts_set. */
jf_status jf_read_opts_set(jf_read_opts *o, const char *name, const char *value,
                           const char **why);

/* Fits every point of c (out has c->n entries, caller-owned; out[i]
 * belongs to point i): builds what the neighbourhood needs (k-d tree,
 * mesh adjacency, or Delaunay triangulation and tangent-plane normals),
 * fits the points with one fitter per thread (jf_fit_point_full) in a
 * cache-friendly order (knn/radius: the k-d tree's leaf order, the
 * neighbours' coordinates read from the tree's own copy; rings, natural:
 * Z-order), then orients.  Non-finite points get
 * JF_PT_NONFINITE and NaN values and are nobody's neighbour; a point
 * whose neighbourhood is smaller than asked gets JF_PT_FEW_NEIGHBORS.
 * The results are bit-identical for any thread count.  Peak memory
 * besides c and out: about 40 bytes per point (knn/radius: the k-d tree;
 * rings: the adjacency and order; natural: the bridge's ~100 + 28), plus
 * 4 * orient_k for mst, which runs on the fit's own neighbourhoods (the
 * orient_k nearest of each).  Measured at 1M points, knn:16, the whole
 * command peaks at 263-264 MiB (1-2 threads; bench_estimate), 294 MiB
 * with mst.
 * Returns JF_OK, JF_ERR_INVALID (bad options, rings without faces,
 * orient/normal input without normals; err says which), JF_ERR_NOMEM,
 * JF_ERR_CANCELLED (o->cancel said stop),
 * JF_ERR_FORMAT (bad face indices), or the failing stage's status; err
 * (may be NULL) gets one line.  Thread-safe on distinct outputs. */
jf_status jf_estimate(const jf_cloud *c, const jf_estimate_opts *o,
                      jf_result *out, jf_error *err);

/* A block of results from jf_estimate_blocks: res[j] belongs to input
 * point idx[j], j < m (m <= JF_BLOCK_MAX); the results are final (oriented).
 * Return JF_OK to go on; any other status stops the estimate, which
 * returns it.  Called concurrently from the OpenMP threads of the fit
 * (blocks are disjoint): it must be thread-safe.  res and idx are the
 * library's, valid during the call only (res may be changed). */
#define JF_BLOCK_MAX 256
typedef jf_status (*jf_block_fn)(void *user, const uint32_t *idx, jf_result *res, size_t m);

/* jf_estimate without the n results in memory: the same results, bit for
 * bit, handed to `sink` a block at a time as they are fitted (in the
 * walk's order: the k-d tree's leaf order for knn/radius, else Z-order;
 * non-finite points first), each point exactly once.  Orientation none,
 * input, viewpoint and scanner are applied per block.  mst needs every
 * normal before any row is final: it runs the fit twice -- the first pass
 * keeps the normals, statuses and orient_k graph edges (28 + 4 orient_k
 * bytes per point), Prim decides a flip per point, the second pass fits
 * again and hands over the flipped rows (twice the time; the progress
 * hook then counts 2n).  Peak memory besides c: the index (about 40
 * bytes per point for knn/radius) and, per thread, one block of results.
 * Same statuses and errors as jf_estimate; a sink's status stops it
 * (blocks already handed over stay handed over).  Thread-safe on distinct
 * sinks. */
jf_status jf_estimate_blocks(const jf_cloud *c, const jf_estimate_opts *o,
                             jf_block_fn sink, void *user, jf_error *err);

/* jf_estimate_blocks in bounded memory: the finite points are cut into
 * nparts parts of near-equal count along the Morton order, and the parts
 * are processed one at a time on all threads, each with an exact halo
 * (the points of other parts that can be among its points' neighbours,
 * found by scans of c's coordinates), so that the index is never built
 * over the whole cloud: about 4 bytes per point, two grids of <= 8 MiB,
 * and (n / nparts) x 88 bytes besides c at a time.
 * The same results, bit for bit, as jf_estimate_blocks (neighbourhoods
 * over own points + halo in input order break ties by input index as the
 * whole cloud's do); the blocks come part after part, non-finite points
 * first.  knn, radius, knn+radius only, and orientation none, input,
 * viewpoint or scanner: JF_ERR_UNSUPPORTED otherwise (rings, natural and
 * mst need the whole cloud).  nparts == 1 is jf_estimate_blocks.  The
 * progress hook is called once, at the end.  Costs two index builds and
 * three scans of the coordinates per part.  Errors as jf_estimate_blocks. */
jf_status jf_estimate_parts(const jf_cloud *c, const jf_estimate_opts *o, int nparts,
                            jf_block_fn sink, void *user, jf_error *err);

#ifdef __cplusplus
}
#endif
#endif /* JETFIT_H */

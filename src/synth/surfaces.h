/* surfaces.h -- the paper's test surfaces with exact differential truth,
 * their samplings (random clouds, perturbed triangulated grids) and the
 * noise models of `jetfit generate` (internal header: src/synth/surfaces.c,
 * src/synth/surf_sample.c; used by cmd_generate.c, cmd_convergence.c and tests).
 *
 * Conventions (docs/design.md): the normal is unit; k1 >= k2 are signed w.r.t.
 * it, i.e. near the point the surface is z = (k1 x^2 + k2 y^2)/2 along the
 * normal with x along d1, y along d2, and d1 x d2 = n.  Graphs z = f(x,y)
 * use the upward normal (-f_x, -f_y, 1)/W; closed surfaces (sphere,
 * ellipsoid, cylinder, torus) the outward normal, so their convex curvatures are
 * negative (sphere of radius 1: k1 = k2 = -1).
 * Nothing here prints or allocates per point except the sampling calls,
 * which allocate their output arrays once.  Everything is deterministic
 * for a seed (own PRNG, xoshiro256** seeded by splitmix64; no rand()). */
#ifndef JF_SURFACES_H
#define JF_SURFACES_H

#include <stddef.h>
#include <stdint.h>

#include "jetfit.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

typedef enum {
    JF_SURF_EXP = 0,     /* §6.1: z = 0.1 exp(2x + y - y^2), [-.5,.5]^2  */
    JF_SURF_PARABOLOID,  /* Fig. 1: z = 2x^2 + y^2, [-1,1]^2             */
    JF_SURF_REVOLUTION,  /* Fig. 2: z = 0.1 sin(10 r), [-.4,.4]^2; r = 0
                            is a cone point (truth NaN there)           */
    JF_SURF_SPHERE,      /* radius 1, centre 0                            */
    JF_SURF_ELLIPSOID,   /* x^2/1 + y^2/0.75^2 + z^2/0.5^2 = 1 (4 umbilics
                            in the xz plane)                              */
    JF_SURF_CYLINDER,    /* x^2 + y^2 = 0.5^2, z in [-1, 1], open         */
    JF_SURF_TORUS,       /* (sqrt(x^2 + y^2) - 1)^2 + z^2 = 0.4^2: closed,
                            with a hole; elliptic outside, hyperbolic
                            inside, parabolic on its top/bottom circles */
    JF_SURF_COUNT
} jf_surface;

/* Exact differential quantities at one surface point. */
typedef struct {
    double xyz[3];
    double normal[3];
    double k1, k2;       /* k1 >= k2 w.r.t. normal                        */
    double d1[3], d2[3]; /* NaN at umbilics (|k1-k2| <= 1e-10 max|k|)     */
    int valid;           /* 0: singular point (cone tip): all NaN but xyz */
} jf_truth;

/* Name ("exp", "paraboloid", "revolution", "sphere", "ellipsoid",
 * "cylinder", "torus") <-> surface.  jf_surface_parse returns -1 if unknown. */
const char *jf_surface_name(jf_surface s);
int jf_surface_parse(const char *name, jf_surface *s);

/* 1 for graphs z = f(x,y) (parameters are x,y), 0 for closed surfaces. */
int jf_surface_is_graph(jf_surface s);

/* 1 where principal directions are defined generically (all but the
 * sphere, whose every point is umbilic). */
int jf_surface_has_directions(jf_surface s);

/* The parameter rectangle: graphs (x,y); sphere/ellipsoid (theta polar
 * in [0,pi], phi in [0,2pi)); cylinder (phi in [0,2pi), z in [-1,1]);
 * torus (phi around the z axis, psi around the tube, both [0,2pi):
 * X = ((1 + 0.4 cos psi) cos phi, (1 + 0.4 cos psi) sin phi, 0.4 sin psi)). */
void jf_surface_domain(jf_surface s, double lo[2], double hi[2]);

/* The parametrisation X(u,v) (what tests differentiate numerically). */
void jf_surface_point(jf_surface s, double u, double v, double X[3]);

/* Exact truth at X(u,v): graphs from the analytic derivatives of f
 * (first and second fundamental forms, Table 1); quadrics from the
 * implicit equation (gradient and Hessian), which is regular at the
 * poles of their parametrisation. */
void jf_surface_truth(jf_surface s, double u, double v, jf_truth *t);

/* ---------------- deterministic random numbers ---------------- */
typedef struct {
    uint64_t s[4];
} jf_rng;

void jf_rng_seed(jf_rng *r, uint64_t seed);
uint64_t jf_rng_next(jf_rng *r);
double jf_rng_uniform(jf_rng *r);   /* [0, 1), 53 bits              */
double jf_rng_gauss(jf_rng *r);     /* N(0,1), Box-Muller (polar)    */

/* ---------------- samplings (src/synth/surf_sample.c) ---------------- */
typedef enum {
    JF_DENSITY_UNIFORM = 0,
    JF_DENSITY_GRADIENT,   /* keep probability 0.05 + 0.95 t, t in [0,1]
                              along x over the surface's x range        */
    JF_DENSITY_STRIPES     /* 10 stripes across x; odd stripes keep 10% */
} jf_density;

/* A sampled surface: n points with their parameters and exact truth;
 * faces (triangles, CSR) when it is a mesh.  Owned: jf_sample_free. */
typedef struct {
    size_t n;
    double *uv;          /* 2n parameters                                 */
    double *xyz;         /* 3n positions (after noise)                    */
    jf_truth *truth;     /* n exact rows, at the noise-free point; outlier
                            rows: valid = 0, xyz = the outlier           */
    size_t nfaces;
    size_t *face_off;    /* nfaces + 1 */
    uint32_t *face_idx;  /* 3 nfaces   */
    size_t noutliers;
} jf_sample;

void jf_sample_free(jf_sample *s);

/* n random points: graphs and the cylinder uniform in parameters (for
 * the cylinder that is area-uniform); sphere and ellipsoid area-uniform
 * (ellipsoid by rejection on the sphere's area element), the torus
 * area-uniform (rejection on its area element 1 + 0.4 cos psi).  A density
 * other than uniform thins by rejection until n points are kept. */
jf_status jf_sample_random(jf_surface s, size_t n, jf_density d,
                           jf_rng *rng, jf_sample *out);

/* A triangulated grid of side h in the parameter domain, each vertex's
 * parameters moved by (delta h, delta' h), delta, delta' uniform in
 * [0, perturb] (§6.1 uses 0.9).  Graphs: nodes lo + i h covering the
 * domain, squares split along the (i,j)-(i+1,j+1) diagonal (interior
 * valence 6).  Sphere/ellipsoid: a closed UV sphere, rings of constant
 * theta (spacing pi/round(pi/h)), phi wrapping at the seam, one vertex
 * per pole with a triangle fan (poles are not perturbed).  Cylinder: an
 * open tube, phi wrapping.  Torus: phi and psi both wrapping (arc step
 * about h on the tube and on the central circle).  with_faces = 0 gives the vertices only. */
jf_status jf_sample_grid(jf_surface s, double h, double perturb,
                         int with_faces, jf_rng *rng, jf_sample *out);

/* The grid spacing giving about n vertices for jf_sample_grid. */
double jf_sample_grid_h_for(jf_surface s, size_t n);

/* A §6.1 graph grid: nodes (i h, j h) for i, j in [-m, m] (so the origin
 * is a vertex), perturbed as above, triangulated as above.  Vertex (i,j)
 * has index (j + m)(2m + 1) + (i + m). */
jf_status jf_sample_graph_grid(jf_surface s, double h, int m, double perturb,
                               jf_rng *rng, jf_sample *out);

/* ---------------- noise models (src/synth/surf_sample.c) ---------------- */
/* Diagonal and largest side of the bounding box of the n points. */
void jf_bbox_measure(const double *xyz, size_t n, double *diag,
                     double *largest_side);

/* Adds N(0, (sigma_frac diag)^2) to each coordinate. */
void jf_noise_gauss(jf_sample *s, double sigma_frac, jf_rng *rng);

/* PCPNet's "white" noise: each coordinate + U[-1/2, 1/2] * frac * the
 * largest side of the bounding box. */
void jf_noise_uniform(jf_sample *s, double frac, jf_rng *rng);

/* Replaces round(frac n) points, chosen at random (selection sampling),
 * by points uniform in the bounding box of the sample; their truth rows
 * become invalid (NaN, xyz = the outlier). */
void jf_noise_outliers(jf_sample *s, double frac, jf_rng *rng);

#endif /* JF_SURFACES_H */

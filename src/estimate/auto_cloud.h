/* auto_cloud.h -- neighbors auto's step 0, the cloud's cap on K
 * (auto_cloud.c; not part of the public API).  The whole-cloud estimate,
 * the parts and jetfit-mpi's ranks each compute their share of one
 * sample and decide from all of it. */
#ifndef JF_AUTO_CLOUD_H
#define JF_AUTO_CLOUD_H
#include <stddef.h>
#include <stdint.h>

#include "jetfit.h"
#include "robust_internal.h" /* JF_AUTO_CV_N */

/* One sampled point: its input index and jf__auto_cv_point's values. */
typedef struct {
    uint32_t gid;
    double v[JF_AUTO_CV_N];
} jf__cvrec;

/* What the decision saw (for tests). */
typedef struct {
    size_t used;   /* sample points with every candidate's CV         */
    int pick;      /* the K of least CV (0: too few points)           */
    double median; /* median sigma / r16                              */
    int cubic_min48; /* at K = 16 the cubic's leave-one-out residual is
                        below the quadric's (each in its points' own
                        frame) at no more than half the sample: no cubic
                        on fewer than 48 points                          */
    double bias;     /* median of the sample's JF_AUTO_CV_BIAS (about
                        ln 2 where the noise alone parts the two normals) */
    double bias32;   /* median of the sample's JF_AUTO_CV_BIAS32         */
    int cap;         /* params.auto_select: the cap (JF_NB_AUTO_KMAX none),
                        | JF_AUTO_CUBIC_MIN48 where cubic_min48,
                        | JF_AUTO_WEIGHTED_MEAN where no cap and bias is
                        at most 1, | JF_AUTO_SPREAD_CARRY where no cap
                        and bias is above 1, at most 4,
                        | JF_AUTO_CAPPED_WEIGHTED and a cap of at least
                        32 where capped and bias32 is above 1, at most 4 */
} jf__auto_cv_why;

/* Whether an estimate with p and nb decides the cap itself (auto, the
 * cap not given: params.auto_select 1, knn:JF_NB_AUTO_KMAX). */
int jf__auto_cv_wanted(const jf_params *p, const jf_nb_spec *nb);

/* Every stride-th input index is sampled (n: the whole cloud's count). */
size_t jf__auto_cv_stride(size_t ntotal);

/* The sample points among the n of xyz (own: those of this part, NULL:
 * all; gid: their input indices, NULL: the local ones; ntotal: the whole
 * cloud's count), each on its JF_NB_AUTO_KMAX nearest from ix (NULL:
 * built here on nt threads), into *out (malloc'd, *nout records). */
jf_status jf__auto_cv_sample(const double *xyz, size_t n, const uint8_t *own, const uint32_t *gid,
                             size_t ntotal, const jf_index *ix, const jf_params *pr, int nt,
                             jf__cvrec **out, size_t *nout);

/* The cap from every sample record (sorted here by input index, so any
 * split sums in one order); *why (may be NULL) what it saw. */
int jf__auto_cv_decide(jf__cvrec *r, size_t n, jf__auto_cv_why *why);

/* params.auto_select for the fits of an estimate with p: the decision,
 * with JF_AUTO_CUBIC_MIN48 also where p gave it. */
int jf__auto_cv_select(const jf_params *p, jf__cvrec *r, size_t n);
#endif

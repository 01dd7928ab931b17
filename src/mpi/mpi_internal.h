/* mpi_internal.h -- the pieces of `jetfit-mpi estimate` (src/mpi/): one
 * rank's share of the cloud, from its byte range of the input to the
 * local cloud it fits (mpi_dist.c), and the rows it writes (jetfit_mpi.c).
 *
 * Every step is collective.  A rank that fails records one line in
 * jf_mpi.msg and keeps calling the collectives of the step; jf_mpi_check
 * (after each step) makes every rank see the failure, the lowest failing
 * rank prints its line, and all of them stop. */
#ifndef JF_MPI_INTERNAL_H
#define JF_MPI_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include <mpi.h>

#include "io_internal.h"
#include "jetfit.h"
#include "parts.h"

typedef struct {
    MPI_Comm comm;
    int rank, size;
    int failed;         /* this rank failed (msg says why)              */
    char msg[600];
    double t_exchange;  /* seconds spent in the partition and halo      */
} jf_mpi;

/* Records this rank's failure (the first one wins).  Returns 1. */
int jf_mpi_fail(jf_mpi *m, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* Collective: 1 if any rank failed (the lowest failing one has printed
 * "jetfit-mpi: MSG"), else 0. */
int jf_mpi_check(jf_mpi *m);

/* One rank's cloud after the exchange: its own points (those of its part,
 * and the non-finite points it read), the halo, ascending input index. */
typedef struct {
    size_t n;           /* all local points                             */
    double *xyz;        /* 3n                                           */
    double *nrm;        /* 3n when normals are read, else NULL          */
    uint32_t *gid;      /* n input indices, ascending                   */
    uint8_t *own;       /* n: 1 = fitted and written here, 0 = halo     */
    size_t nown;
    uint64_t total;     /* points in the input                          */
    size_t nhalo;       /* halo points                                  */
    size_t fetched;     /* candidates received (before the merge)       */
} jf_mpi_cloud;

void jf_mpi_cloud_free(jf_mpi_cloud *c);

/* Reads the header of the binary PLY `path` (every rank, no collective).
 * On failure m->failed. */
void jf_mpi_probe(jf_mpi *m, const char *path, jf_row_layout *l);

/* Reads this rank's rows of the binary PLY `path` (1/size of them),
 * partitions the finite points into one part per rank (parts.h: Morton
 * order, equal runs), exchanges them, and fetches the halo that the query
 * q needs.  normals: read nx ny nz too (the file must have them).
 * threads for the local trees.  Collective; on failure m->failed. */
void jf_mpi_load(jf_mpi *m, const char *path, const jf_row_layout *l, const jf_part_query *q,
                 int normals, int threads, jf_mpi_cloud *c);

#endif

/* bench_parts.c -- halo figures of the partition (src/estimate/parts.c) for
 * docs/scale.md "Halo fraction": P parts simulated in one process.
 *
 * For knn:16 and knn:64 at P = 2, 8, 64, 512 it prints the halo fraction
 * (points fetched from other parts / points owned, summed over the parts),
 * the largest part's fraction, the requests sent per owned point, and the
 * time to compute the halos.  The cloud: n random samples (default 10^6)
 * of the §6.1 surface z = 0.1 exp(2x + y - y^2) (what `jetfit generate exp`
 * writes), or a binary/ascii PLY or XYZ file given as argv[1].
 *
 * Usage: bench_parts [N | FILE] [threads]
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "jetfit.h"
#include "parts.h"
#include "surfaces.h"

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int main(int argc, char **argv)
{
    size_t n = 1000000;
    int threads = argc > 2 ? atoi(argv[2]) : 0;
    jf_cloud c = {0};
    jf_sample smp = {0};
    const char *what = "exp surface, random samples";
    if (argc > 1 && strspn(argv[1], "0123456789") != strlen(argv[1])) {
        jf_error err;
        if (jf_cloud_read(argv[1], NULL, &c, &err) != JF_OK) {
            fprintf(stderr, "bench_parts: %s\n", err.msg);
            return 1;
        }
        what = argv[1];
    } else {
        if (argc > 1) n = strtoull(argv[1], NULL, 10);
        jf_rng rng;
        jf_rng_seed(&rng, 12);
        if (jf_sample_random(JF_SURF_EXP, n, JF_DENSITY_UNIFORM, &rng, &smp) != JF_OK) {
            fprintf(stderr, "bench_parts: sampling failed\n");
            return 1;
        }
        c.n = smp.n;
        c.xyz = smp.xyz;
    }
    printf("# halo fraction = points fetched from other parts / points owned\n");
    printf("# cloud: %s, %zu points\n", what, c.n);
    printf("# fetched = distinct candidates the answers carry (a distributed run's traffic)\n");
    printf("%-7s %5s %10s %10s %10s %10s %10s %8s\n", "nb", "parts", "pts/part", "halo_frac",
           "max_part", "fetched", "req/point", "secs");
    const char *specs[] = {"knn:16", "knn:64"};
    const int parts[] = {2, 8, 64, 512};
    int32_t *part = malloc(c.n * sizeof *part);
    if (!part) return 1;
    for (int s = 0; s < 2; s++) {
        jf_estimate_opts o;
        jf_estimate_opts_init(&o);
        jf_nb_parse(specs[s], &o.nb, NULL);
        jf_part_query q;
        if (jf__part_query_init(&o, &q) != JF_OK) return 1;
        for (int pi = 0; pi < 4; pi++) {
            int P = parts[pi];
            size_t *off = malloc(((size_t)P + 1) * sizeof *off);
            jf_halo_stats hs;
            uint32_t *halo = NULL;
            double t0 = now_s();
            if (jf__parts_split(c.xyz, c.n, P, part) != JF_OK ||
                jf__parts_halos(c.xyz, c.n, part, P, &q, threads, off, &halo, &hs) != JF_OK) {
                fprintf(stderr, "bench_parts: halo computation failed\n");
                return 1;
            }
            double secs = now_s() - t0, worst = 0;
            size_t per = c.n / (size_t)P;
            for (int a = 0; a < P; a++) {
                double f = per ? (double)(off[a + 1] - off[a]) / (double)per : 0;
                if (f > worst) worst = f;
            }
            printf("%-7s %5d %10zu %10.4f %10.4f %10.4f %10.3f %8.2f\n", specs[s], P, per,
                   (double)off[P] / (double)c.n, worst, (double)hs.fetched / (double)c.n,
                   (double)hs.requests / (double)c.n, secs);
            fflush(stdout);
            free(off);
            free(halo);
        }
    }
    free(part);
    if (smp.xyz) jf_sample_free(&smp);
    else jf_cloud_free(&c);
    return 0;
}

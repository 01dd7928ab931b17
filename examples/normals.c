/* normals.c -- libjetfit by example: read a cloud, fit a 2-jet at every
 * point on its 32 nearest neighbours, print a summary.
 * Build against an installed jetfit:
 *   cc normals.c $(pkg-config --cflags --libs jetfit) -o normals
 * or with CMake (examples/CMakeLists.txt: find_package(jetfit)). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <jetfit.h>

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: normals CLOUD.ply\n");
        return 2;
    }
    jf_cloud c;
    jf_error err;
    if (jf_cloud_read(argv[1], NULL, &c, &err) != JF_OK) {
        fprintf(stderr, "normals: %s\n", err.msg);
        return 1;
    }
    jf_estimate_opts o;
    jf_estimate_opts_init(&o); /* knn:32, degree 2, all cores */
    jf_result *r = malloc(c.n * sizeof *r);
    jf_status s = r ? jf_estimate(&c, &o, r, &err) : JF_ERR_NOMEM;
    if (s != JF_OK) {
        fprintf(stderr, "normals: %s\n", r ? err.msg : jf_strerror(s));
        free(r);
        jf_cloud_free(&c);
        return 1;
    }
    size_t ok = 0;
    double mean_h = 0, max_k = 0;
    for (size_t i = 0; i < c.n; i++) {
        if (r[i].status & (JF_PT_FAILED | JF_PT_NONFINITE))
            continue;
        ok++;
        mean_h += 0.5 * (r[i].k1 + r[i].k2);
        if (fabs(r[i].k1) > max_k) max_k = fabs(r[i].k1);
        if (fabs(r[i].k2) > max_k) max_k = fabs(r[i].k2);
    }
    printf("jetfit %s: %zu points, %zu fitted\n", jf_version(), c.n, ok);
    printf("point 0: normal %.6f %.6f %.6f  k1 %.6g  k2 %.6g\n", r[0].normal[0],
           r[0].normal[1], r[0].normal[2], r[0].k1, r[0].k2);
    printf("mean curvature (average) %.6g, largest |k| %.6g\n", ok ? mean_h / ok : NAN, max_k);
    free(r);
    jf_cloud_free(&c);
    return 0;
}

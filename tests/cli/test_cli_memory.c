/* test_cli_memory.c -- `jetfit estimate --memory SIZE` as a budget for the
 * whole process (docs/scale.md, "Memory budget"): a SIZE too small is
 * refused at the start in one line naming the least that works, with no
 * output made; that least is exact (1K less is refused, it runs), and runs
 * in parts give the bytes of the unbounded run for every k-d tree
 * neighbourhood and text or binary output. */
#include <check.h>
#include <fcntl.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "test_cli_util.h"
#include "jf_test.h"

/* The least SIZE the refusal names, in bytes (K or M), or 0. */
static unsigned long long least_named(void)
{
    const char *p = strstr(cli_err, "the least that works is --memory ");
    unsigned long long v = 0;
    char unit = 0;
    if (!p || sscanf(p + strlen("the least that works is --memory "), "%llu%c", &v, &unit) != 2)
        return 0;
    return unit == 'K' ? v << 10 : unit == 'M' ? v << 20 : 0;
}

static int run_budget(const char *out, const char *nb, unsigned long long bytes)
{
    char mem[32];
    snprintf(mem, sizeof mem, "%lluK", bytes >> 10);
    return cli_run("estimate", cli_path("in.ply"), "-o", cli_path(out), "--neighbors", nb,
                   "--threads", "2", "--memory", mem, NULL);
}

START_TEST(too_small_is_refused_with_the_least)
{
    ck_assert_int_eq(cli_run("generate", "exp", "--n", "20000", "--seed", "3", "-o",
                             cli_path("in.ply"), NULL),
                     0);
    ck_assert_int_eq(cli_run("estimate", cli_path("in.ply"), "-o", cli_path("w.ply"), "--neighbors",
                             "knn:16", "--threads", "2", "--quiet", NULL),
                     0);
    ck_assert_int_eq(cli_run("estimate", cli_path("in.ply"), "-o", cli_path("p.ply"), "--neighbors",
                             "knn:16", "--threads", "2", "--memory", "1K", NULL),
                     1);
    /* one line, the file and the figures in it, nothing written */
    char want[600];
    snprintf(want, sizeof want, "jetfit: %s: --memory 1K is too small for 20000 points: the least "
                                "that works is --memory ", cli_path("in.ply"));
    ck_assert_msg(!strncmp(cli_err, want, strlen(want)), "%s", cli_err);
    ck_assert_msg(strchr(cli_err, '\n') == cli_err + strlen(cli_err) - 1, "one line: %s", cli_err);
    ck_assert_int_eq(cli_exists(cli_path("p.ply")), 0);
    ck_assert_int_eq(cli_count_files(), 2);
    const unsigned long long least = least_named();
    ck_assert_msg(least >= (20000ULL * 24), "the coordinates alone: %s", cli_err);
    /* exact to the K: 1K less is refused, the least runs (in parts: the
     * least is below the whole cloud's need) with the same bytes */
    ck_assert_int_eq(run_budget("p.ply", "knn:16", least - 1024), 1);
    ck_assert_uint_eq(least_named(), least);
    ck_assert_int_eq(run_budget("p.ply", "knn:16", least), 0);
    ck_assert_msg(strstr(cli_err, "  parts: "), "in parts: %s", cli_err);
    jf_test_assert_same_files("the least, in parts", cli_path("w.ply"), cli_path("p.ply"));
}
END_TEST

/* Budgets between the least and the whole cloud's: a few to many parts,
 * every k-d tree neighbourhood, binary PLY and CSV (through the spool). */
START_TEST(small_budgets_same_bytes)
{
    /* 60,000 points: the parts' least (their halo rings, the plan's) is
     * more than 256K below the whole cloud's need */
    ck_assert_int_eq(cli_run("generate", "exp", "--n", "60000", "--seed", "4", "-o",
                             cli_path("in.ply"), NULL),
                     0);
    static const struct {
        const char *nb, *ext;
    } runs[] = {{"knn:16", "ply"}, {"radius:0.02", "csv"}, {"knn:12,radius:0.015", "ply"}};
    for (size_t k = 0; k < sizeof runs / sizeof *runs; k++) {
        char w[32], p[32];
        snprintf(w, sizeof w, "w.%s", runs[k].ext);
        snprintf(p, sizeof p, "p.%s", runs[k].ext);
        ck_assert_int_eq(cli_run("estimate", cli_path("in.ply"), "-o", cli_path(w), "--neighbors",
                                 runs[k].nb, "--threads", "2", "--quiet", NULL),
                         0);
        ck_assert_int_eq(run_budget(p, runs[k].nb, 1024), 1);
        const unsigned long long least = least_named();
        ck_assert_msg(least > 0, "%s", cli_err);
        for (unsigned long long extra = 0; extra <= (256ULL << 10); extra += 256ULL << 10) {
            ck_assert_int_eq(run_budget(p, runs[k].nb, least + extra), 0);
            ck_assert_msg(strstr(cli_err, "  parts: "), "in parts: %s", cli_err);
            jf_test_assert_same_files(runs[k].nb, cli_path(w), cli_path(p));
        }
    }
}
END_TEST

/* A binary PLY written here, so the test knows every byte: n points of a
 * wavy sheet (x y z doubles), a per-point uchar and float the estimate
 * keeps, and every 997th point NaN (a nonfinite row). */
static void write_sheet(const char *path, size_t n, uint64_t seed)
{
    FILE *f = fopen(path, "wb");
    ck_assert_msg(f != NULL, "%s", path);
    fprintf(f, "ply\nformat binary_little_endian 1.0\nelement vertex %zu\nproperty double x\n"
               "property double y\nproperty double z\nproperty uchar label\n"
               "property float intensity\nend_header\n", n);
    for (size_t i = 0; i < n; i++) {
        double x = jf_unit(jf_splitmix64(&seed)), y = jf_unit(jf_splitmix64(&seed));
        double p[3] = {x, y, 0.1 * sin(6 * x) * cos(5 * y) + 1e-4 * jf_unit(jf_splitmix64(&seed))};
        if (i % 997 == 13) p[1] = NAN;
        unsigned char label = (unsigned char)(i % 7);
        float in = (float)(i % 1000) / 3.0f;
        ck_assert_uint_eq(fwrite(p, sizeof p, 1, f), 1); /* the test machine is little endian */
        ck_assert_uint_eq(fwrite(&label, 1, 1, f), 1);
        ck_assert_uint_eq(fwrite(&in, sizeof in, 1, f), 1);
    }
    fclose(f);
}

/* --memory below what the coordinates need in memory: the parts read them
 * from the input file as they go (docs/scale.md), the refusal says so, and
 * the rows are the unbounded run's, byte for byte: knn, radius, knn+radius
 * and auto neighbourhoods, the input's attributes kept, non-finite points,
 * binary PLY and CSV (through the spool) outputs. */
START_TEST(coordinates_on_disk_same_bytes)
{
    write_sheet(cli_path("in.ply"), 30000, 5);
    /* auto's halo ring (r_256 + 2 r_128, jf__plan_part_points) is wider
     * than a part of 30,000 / 32 points: parts pay below ~3e5 points */
    write_sheet(cli_path("big.ply"), 300000, 5);
    static const struct {
        const char *nb, *ext, *keep, *in;
    } runs[] = {{"knn:16", "ply", "all", "in.ply"},        {"radius:0.02", "csv", "all", "in.ply"},
                {"knn:12,radius:0.015", "ply", "none", "in.ply"}, {"auto", "ply", "all", "big.ply"}};
    /* on 1,500 points the least plan holds the cloud (parts of it in
     * memory); on 30,000 it reads the coordinates from the file (the
     * whole cloud's run holds auto's rows per thread, 5 MiB each) */
    write_sheet(cli_path("tiny.ply"), 1500, 5);
    ck_assert_int_eq(cli_run("estimate", cli_path("tiny.ply"), "-o", cli_path("a.ply"), "--neighbors",
                             "auto", "--memory", "1K", NULL),
                     1);
    ck_assert_msg(strstr(cli_err, "(the cloud and the summary's values"), "%s", cli_err);
    for (size_t k = 0; k < sizeof runs / sizeof *runs; k++) {
        char w[32], p[32];
        snprintf(w, sizeof w, "w%zu.%s", k, runs[k].ext);
        snprintf(p, sizeof p, "p%zu.%s", k, runs[k].ext);
        ck_assert_int_eq(cli_run("estimate", cli_path(runs[k].in), "-o", cli_path(w), "--neighbors",
                                 runs[k].nb, "--threads", "2", "--keep", runs[k].keep, NULL),
                         0);
        ck_assert_int_eq(cli_run("estimate", cli_path(runs[k].in), "-o", cli_path(p), "--neighbors",
                                 runs[k].nb, "--threads", "2", "--keep", runs[k].keep, "--memory",
                                 "1K", NULL),
                         1);
        ck_assert_msg(strstr(cli_err, "with the coordinates read from the file as needed"), "%s",
                      cli_err);
        ck_assert_int_eq(cli_exists(cli_path(p)), 0);
        const unsigned long long least = least_named();
        ck_assert_msg(least > 0, "%s", cli_err);
        char mem[32];
        snprintf(mem, sizeof mem, "%lluK", (least >> 10) - 1);
        ck_assert_int_eq(cli_run("estimate", cli_path(runs[k].in), "-o", cli_path(p), "--neighbors",
                                 runs[k].nb, "--threads", "2", "--keep", runs[k].keep, "--memory",
                                 mem, NULL),
                         1);
        ck_assert_uint_eq(least_named(), least);
        snprintf(mem, sizeof mem, "%lluK", least >> 10);
        ck_assert_int_eq(cli_run("estimate", cli_path(runs[k].in), "-o", cli_path(p), "--neighbors",
                                 runs[k].nb, "--threads", "2", "--keep", runs[k].keep, "--memory",
                                 mem, NULL),
                         0);
        ck_assert_msg(strstr(cli_err, "  parts: "), "in parts: %s", cli_err);
        jf_test_assert_same_files(runs[k].nb, cli_path(w), cli_path(p));
    }
}
END_TEST

/* The input written to in place during a run whose parts read it again
 * and again: an error naming the file, nothing written (before: the parts
 * could fit different points, silently); untouched, the same run passes. */
static volatile int toggle_stop;
static void *toggler(void *arg)
{
    int fd = open(arg, O_RDWR);
    struct stat sb;
    unsigned char b0;
    if (fd < 0 || fstat(fd, &sb) != 0 || pread(fd, &b0, 1, sb.st_size - 13) != 1) return NULL;
    for (unsigned k = 1; !toggle_stop; k++) { /* the last z's lowest byte (rows of 29 bytes) */
        const unsigned char b = b0 ^ (unsigned char)(k & 1);
        if (pwrite(fd, &b, 1, sb.st_size - 13) != 1) break;
        usleep(200);
    }
    if (pwrite(fd, &b0, 1, sb.st_size - 13) != 1) {}
    close(fd);
    return arg;
}

START_TEST(input_modified_during_run_refused)
{
    write_sheet(cli_path("in.ply"), 30000, 7);
    ck_assert_int_eq(run_budget("p.ply", "knn:16", 1024), 1);
    const unsigned long long least = least_named();
    ck_assert_msg(least > 0 && strstr(cli_err, "read from the file as needed"), "%s", cli_err);
    pthread_t th;
    toggle_stop = 0;
    ck_assert_int_eq(pthread_create(&th, NULL, toggler, (void *)cli_path("in.ply")), 0);
    const int rc = run_budget("p.ply", "knn:16", least);
    toggle_stop = 1;
    void *ran = NULL;
    pthread_join(th, &ran);
    ck_assert_ptr_nonnull(ran);
    ck_assert_int_eq(rc, 1);
    char want[600];
    snprintf(want, sizeof want, "jetfit: %s: the file was modified while it was read",
             cli_path("in.ply"));
    ck_assert_msg(strstr(cli_err, want), "%s", cli_err);
    ck_assert_int_eq(cli_exists(cli_path("p.ply")), 0);
    ck_assert_int_eq(run_budget("p.ply", "knn:16", least), 0);
    ck_assert_msg(strstr(cli_err, "  parts: "), "in parts: %s", cli_err);
}
END_TEST

/* Nothing held beside the parts (--quiet: no summary values; --keep none;
 * no normals): the refusal does not name a size of nothing ("0K"). */
START_TEST(refusal_names_no_empty_size)
{
    ck_assert_int_eq(cli_run("generate", "exp", "--n", "300000", "--seed", "6", "-o",
                             cli_path("in.ply"), NULL),
                     0);
    ck_assert_int_eq(cli_run("estimate", cli_path("in.ply"), "-o", cli_path("p.ply"), "--threads",
                             "1", "--quiet", "--keep", "none", "--memory", "1K", NULL),
                     1);
    const char *tail = "(with the coordinates read from the file as needed)\n";
    size_t le = strlen(cli_err), lt = strlen(tail);
    ck_assert_msg(le > lt && !strcmp(cli_err + le - lt, tail), "%s", cli_err);
    ck_assert_msg(!strstr(cli_err, " 0K"), "%s", cli_err);
    ck_assert_uint_gt(least_named(), 0);
    ck_assert_int_eq(cli_exists(cli_path("p.ply")), 0);
    /* with the summary's values (8 bytes a point), their size is named */
    ck_assert_int_eq(cli_run("estimate", cli_path("in.ply"), "-o", cli_path("p.ply"), "--threads",
                             "1", "--keep", "none", "--memory", "1K", NULL),
                     1);
    char want[128];
    snprintf(want, sizeof want, "; the summary's values, normals and attributes: %dK)\n",
             (300000 * 8 + 1023) / 1024);
    ck_assert_msg(strstr(cli_err, want), "%s", cli_err);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("cli_memory");
    TCase *tc = tcase_create("memory budget");
    tcase_add_checked_fixture(tc, cli_setup, cli_teardown);
    tcase_set_timeout(tc, 900);
    tcase_add_test(tc, too_small_is_refused_with_the_least);
    tcase_add_test(tc, small_budgets_same_bytes);
    tcase_add_test(tc, coordinates_on_disk_same_bytes);
    tcase_add_test(tc, refusal_names_no_empty_size);
    tcase_add_test(tc, input_modified_during_run_refused);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}

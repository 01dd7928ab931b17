/* jetfit_mpi.c -- `mpirun -np N jetfit-mpi estimate INPUT -o OUTPUT [options]`:
 * the estimate of `jetfit estimate`, over MPI, byte for byte the same file.
 *
 * design: the options are parsed by the command's own code (src/cmdline/opts.c)
 * and the rows made by it (jf_result_row); mpi_dist.c gives each rank its
 * part of the cloud and the part's exact halo; the fit is the pipeline's
 * (jf__estimate_masked: the halo points are neighbours, not fitted); each
 * rank writes its rows with MPI-IO at their input-order offsets into the
 * temporary of rank 0's table writer (header written by it), which rank 0
 * renames onto OUTPUT once every rank has succeeded.  Text outputs (.csv,
 * .xyz, .txt, --ascii) go through a binary temporary that rank 0 converts
 * in one sequential pass with the same writer.  Refused with one line:
 * natural and rings neighbourhoods, --orient mst and scanner (they need
 * the whole cloud at once), inputs other than binary PLY and LAS (LAZ
 * included), LAS output. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <omp.h>

#include "auto_cloud.h"
#include "auto_k.h"
#include "io_internal.h"
#include "mpi_internal.h"
#include "opts.h"
#include "progress.h"

static void usage(FILE *f)
{
    fprintf(f,
        "usage: mpirun -np N jetfit-mpi estimate INPUT -o OUTPUT [options]\n"
        "\n"
        "The estimate of `jetfit estimate` over N MPI ranks: the same options and\n"
        "the same output file, byte for byte.  Each rank reads 1/N of INPUT, owns\n"
        "one spatial part of the cloud and fetches the exact halo it needs; no rank\n"
        "holds the whole cloud.  Options: jetfit estimate --help.\n"
        "INPUT: binary PLY, LAS or LAZ.   OUTPUT: .ply (binary or --ascii), .csv, .xyz, .txt.\n"
        "Not in distributed runs: --neighbors natural|rings, --orient mst|scanner\n"
        "(they need the whole cloud at once), LAS output; the input's\n"
        "other properties are not carried (the output is that of --keep none).\n"
        "No standard input or output ('-'): each rank reads its share of a named file.\n"
        "docs/scale.md \"Distributed runs\" says how to run on a cluster.\n"
        "\n  -h, --help      this text\n  --version       jetfit's and the MPI library's versions\n");
}

static void on_fatal_signal(int sig)
{
    jf_tmpfiles_remove_all(); /* rank 0's temporary: no partial output */
    signal(sig, SIG_DFL);
    raise(sig);
}

static void catch_signals(void)
{
    const int sigs[] = {SIGINT, SIGTERM, SIGHUP};
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_fatal_signal;
    sigemptyset(&sa.sa_mask);
    for (size_t i = 0; i < sizeof sigs / sizeof sigs[0]; i++) sigaction(sigs[i], &sa, NULL);
}

/* Rank 0's writers: `bin` the binary PLY the ranks write into (OUTPUT
 * itself, or for text outputs a side file never committed), `txt` the
 * text OUTPUT. */
typedef struct {
    jf_writer *bin, *txt;
    uint64_t header;
    char tmp[4096];
} outputs;

static void open_outputs(jf_mpi *m, const char *out, int ascii, const jf_column *cols,
                         size_t ncols, uint64_t nrows, outputs *o)
{
    jf_error err = {{0}};
    const char *tmp = NULL;
    jf_format fmt = jf_format_from_path(out);
    int text = ascii || fmt != JF_FMT_PLY;
    char *side = NULL;
    if (text) {
        if (jf_writer_open(out, cols, ncols, (size_t)nrows, ascii, &o->txt, &err) != JF_OK) {
            jf_mpi_fail(m, "%s", err.msg);
            return;
        }
        side = malloc(strlen(out) + 16);
        if (!side) {
            jf_mpi_fail(m, "out of memory");
            return;
        }
        sprintf(side, "%s.mpi-rows.ply", out);
    }
    if (jf_writer_open(side ? side : out, cols, ncols, (size_t)nrows, 0, &o->bin, &err) != JF_OK)
        jf_mpi_fail(m, "%s", err.msg);
    else if (jf__writer_begin(o->bin, &o->header, &tmp) != JF_OK)
        jf_mpi_fail(m, "%s: cannot write the header", side ? side : out);
    else if (strlen(tmp) >= sizeof o->tmp)
        jf_mpi_fail(m, "%s: path too long", out);
    else
        strcpy(o->tmp, tmp);
    free(side);
}

static void abort_outputs(outputs *o)
{
    jf_writer_abort(o->bin);
    jf_writer_abort(o->txt);
    o->bin = o->txt = NULL;
}

/* An MPI-IO failure of this rank, in MPI's words. */
static void io_fail(jf_mpi *m, const char *out, const char *what, int rc)
{
    char s[MPI_MAX_ERROR_STRING];
    int len = 0;
    if (MPI_Error_string(rc, s, &len) != MPI_SUCCESS) snprintf(s, sizeof s, "error %d", rc);
    jf_mpi_fail(m, "%s: MPI-IO %s failed: %s", out, what, s);
}

/* Rank 0: the temporary gets its full length before any rank writes, so a
 * disk without room fails here, before the fit (a filesystem that cannot
 * preallocate is left to the checked writes and the final length). */
static void reserve(jf_mpi *m, const outputs *o, const char *out, uint64_t bytes)
{
    if (getenv("JETFIT_MPI_TEST_NO_RESERVE")) return; /* tests reach the write checks */
    int fd = open(o->tmp, O_WRONLY);
    int e = fd < 0 ? errno : posix_fallocate(fd, 0, (off_t)bytes);
    if (fd >= 0) close(fd);
    if (e && e != EOPNOTSUPP && e != EINVAL)
        jf_mpi_fail(m, "%s: cannot reserve %llu bytes for the output: %s", out,
                    (unsigned long long)bytes, strerror(e));
}

/* Rank 0, before the rename: the temporary is as long as its header says. */
static int commit_length(jf_mpi *m, const outputs *o, const char *out, uint64_t bytes)
{
    struct stat sb;
    if (stat(o->tmp, &sb) != 0)
        return jf_mpi_fail(m, "%s: %s", out, strerror(errno));
    if ((uint64_t)sb.st_size != bytes)
        return jf_mpi_fail(m, "%s: the rows written are %llu bytes, %llu expected (disk full?)",
                           out, (unsigned long long)sb.st_size, (unsigned long long)bytes);
    return 0;
}

/* Each rank writes its own rows at header + index * row size (collective
 * writes in rounds of BLOCK rows, so MPI-IO can gather them). */
static void write_rows(jf_mpi *m, const outputs *o, const char *out, const jf_mpi_cloud *c,
                       const jf_result *res, const jf_column *cols, size_t ncols, int monge,
                       int threads)
{
    enum { BLOCK = 16384 };
    jf_col_type types[JF_RESULT_MAX_COLS];
    size_t rowb = 0;
    int sigma = 0; /* neighbors auto: the sigma column is there */
    for (size_t j = 0; j < ncols; j++) {
        if (!strcmp(cols[j].name, "sigma")) sigma = 1;
        types[j] = cols[j].type;
        rowb += cols[j].type == JF_COL_F64 ? 8 : 4;
    }
    MPI_File fh;
    char path[4096];
    memcpy(path, o->tmp, sizeof path);
    MPI_Bcast(path, (int)sizeof path, MPI_CHAR, 0, m->comm);
    int rc = MPI_File_open(m->comm, path, MPI_MODE_WRONLY, MPI_INFO_NULL, &fh);
    if (rc != MPI_SUCCESS) jf_mpi_fail(m, "%s: cannot open the output with MPI-IO", path);
    if (jf_mpi_check(m)) {
        if (rc == MPI_SUCCESS) MPI_File_close(&fh);
        return;
    }
    size_t *pos = malloc(BLOCK * sizeof *pos);
    double *vals = malloc((size_t)BLOCK * ncols * sizeof *vals);
    char *buf = malloc((size_t)BLOCK * rowb);
    MPI_Aint *disp = malloc(BLOCK * sizeof *disp);
    if (!pos || !vals || !buf || !disp) jf_mpi_fail(m, "out of memory (output rows)");
    uint64_t mine = (c->nown + BLOCK - 1) / BLOCK, rounds = 0;
    MPI_Allreduce(&mine, &rounds, 1, MPI_UINT64_T, MPI_MAX, m->comm);
    size_t j = 0; /* next local point */
    for (uint64_t r = 0; r < rounds; r++) {
        int k = 0;
        while (!m->failed && k < BLOCK && j < c->n) {
            if (c->own[j]) pos[k++] = j;
            j++;
        }
#pragma omp parallel for num_threads(threads > 0 ? threads : jf_default_threads(NULL))
        for (int t = 0; t < k; t++) {
            const size_t p = pos[t];
            double *v = vals + (size_t)t * ncols;
            jf_result_row(c->xyz + 3 * p, &res[p], monge, sigma, v);
            jf__ply_row_le(types, ncols, v, buf + (size_t)t * rowb);
        }
        for (int t = 0; t < k; t++) disp[t] = (MPI_Aint)(o->header + (uint64_t)c->gid[pos[t]] * rowb);
        MPI_Datatype ft = MPI_BYTE;
        if (k) {
            MPI_Type_create_hindexed_block(k, (int)rowb, disp, MPI_BYTE, &ft);
            MPI_Type_commit(&ft);
        }
        rc = MPI_File_set_view(fh, 0, MPI_BYTE, ft, "native", MPI_INFO_NULL);
        MPI_Status st;
        /* every write_all is collective: a rank that failed still joins
         * the later rounds with its rows (the check comes after) */
        const int want = (int)((size_t)k * rowb);
        if (rc == MPI_SUCCESS) rc = MPI_File_write_all(fh, buf, want, MPI_BYTE, &st);
        int got = 0;
        if (rc == MPI_SUCCESS && MPI_Get_count(&st, MPI_BYTE, &got) == MPI_SUCCESS && got != want)
            jf_mpi_fail(m, "%s: wrote %d of %d bytes of rows (disk full?)", out, got, want);
        else if (rc != MPI_SUCCESS) io_fail(m, out, "write", rc);
        if (k) MPI_Type_free(&ft);
    }
    /* Open MPI's ompio reports a failed pwritev only on stderr (issue 32):
     * the sync and close results are checked too, and rank 0 checks the
     * file's length before the rename (commit_length) */
    rc = MPI_File_sync(fh);
    if (rc != MPI_SUCCESS) io_fail(m, out, "sync", rc);
    rc = MPI_File_close(&fh);
    if (rc != MPI_SUCCESS) io_fail(m, out, "close", rc);
    free(pos);
    free(vals);
    free(buf);
    free(disp);
}

/* Rank 0: the binary rows read back in order into the text writer. */
static void convert_text(jf_mpi *m, outputs *o, const jf_column *cols, size_t ncols,
                         uint64_t nrows, int threads)
{
    enum { BLOCK = 16384 };
    size_t rowb = 0;
    for (size_t j = 0; j < ncols; j++) rowb += cols[j].type == JF_COL_F64 ? 8 : 4;
    int fd = open(o->tmp, O_RDONLY);
    char *buf = malloc(BLOCK * rowb);
    double *vals = malloc((size_t)BLOCK * ncols * sizeof *vals);
    if (fd < 0 || !buf || !vals) jf_mpi_fail(m, "%s: cannot read the rows back", o->tmp);
    for (uint64_t r0 = 0; !m->failed && r0 < nrows; r0 += BLOCK) {
        size_t k = nrows - r0 < BLOCK ? (size_t)(nrows - r0) : BLOCK, got = 0;
        while (got < k * rowb) {
            ssize_t n = pread(fd, buf + got, k * rowb - got,
                              (off_t)(o->header + r0 * rowb + got));
            if (n <= 0) break;
            got += (size_t)n;
        }
        if (got < k * rowb) {
            jf_mpi_fail(m, "%s: rows missing in the binary temporary", o->tmp);
            break;
        }
        for (size_t t = 0; t < k; t++) {
            const char *p = buf + t * rowb;
            for (size_t j = 0; j < ncols; j++) {
                if (cols[j].type == JF_COL_F64) {
                    memcpy(&vals[t * ncols + j], p, 8);
                    p += 8;
                } else {
                    int32_t x;
                    memcpy(&x, p, 4);
                    vals[t * ncols + j] = x;
                    p += 4;
                }
            }
        }
        if (jf_writer_rows(o->txt, vals, k, threads) != JF_OK) break; /* commit says why */
    }
    if (fd >= 0) close(fd);
    free(buf);
    free(vals);
}

/* No point fitted: an error, nothing written; most points unfitted: a
 * warning -- jetfit estimate's rule and words (cmd_estimate.c, issues 31,
 * 33.12), over every rank's own points.  1 if the run must stop. */
static int nothing_fitted(jf_mpi *m, const char *in, const jf_mpi_cloud *c, const jf_result *res,
                          uint64_t count)
{
    uint64_t mine[3] = {0, 0, 0}, all[3] = {0, 0, 0}; /* unfit, nonfinite, own */
    double big = 0, bigall = 0;
    for (size_t j = 0; j < c->n; j++) {
        if (!c->own[j]) continue;
        mine[2]++;
        if (res[j].status & (JF_PT_FAILED | JF_PT_NONFINITE)) mine[0]++;
        if (res[j].status & JF_PT_NONFINITE) mine[1]++;
        for (int d = 0; d < 3; d++)
            if (isfinite(c->xyz[3 * j + d]) && fabs(c->xyz[3 * j + d]) > big)
                big = fabs(c->xyz[3 * j + d]);
    }
    MPI_Allreduce(mine, all, 3, MPI_UINT64_T, MPI_SUM, m->comm);
    MPI_Allreduce(&big, &bigall, 1, MPI_DOUBLE, MPI_MAX, m->comm);
    const uint64_t unfit = all[0], nonfin = all[1];
    if (count && unfit == count) {
        if (m->rank == 0)
            jf_mpi_fail(m, "%s: no point could be fitted (%llu non-finite, %llu failed)%s; "
                           "nothing written", in, (unsigned long long)nonfin,
                        (unsigned long long)(count - nonfin),
                        bigall > 1e150 ? ": coordinates near 1e150 or beyond overflow the fit "
                                         "(rescale the cloud)"
                        : nonfin < count ? ": too few or collinear neighbours (K must be at "
                                           "least 3)"
                                         : ": every point is NaN or infinite (a scale or "
                                           "transform that overflows?)");
        return 1;
    }
    if (unfit > count / 2 && m->rank == 0)
        fprintf(stderr, "jetfit-mpi: %s: warning: %llu of %llu points could not be fitted "
                        "(status failed or nonfinite)\n", in, (unsigned long long)unfit,
                (unsigned long long)count);
    return 0;
}

/* neighbors auto's step 0 (auto_cloud.c): each rank fits the sample
 * points it owns, every rank gets every record and decides the same cap
 * (the records sorted by input index: the whole cloud's sums).  0, or 1
 * on a failure every rank knows of. */
static int auto_cap(jf_mpi *m, const char *in, const jf_mpi_cloud *c, jf_estimate_opts *o,
                    uint64_t total)
{
    jf_estimate_opts r = *o;
    jf__nb_auto_opts(&r);
    jf__cvrec *mine = NULL, *all = NULL;
    size_t nm = 0;
    int nt = o->threads > 0 ? o->threads : jf_default_threads(NULL);
    jf_status st = jf__auto_cv_sample(c->xyz, c->n, c->own, c->gid, (size_t)total, NULL, &r.params,
                                      nt, &mine, &nm);
    if (st != JF_OK) jf_mpi_fail(m, "%s: neighbors auto's sample: %s", in, jf_strerror(st));
    if (nm > (size_t)INT_MAX / sizeof *mine) jf_mpi_fail(m, "%s: neighbors auto's sample too large", in);
    int bad = jf_mpi_check(m);
    int *cnt = bad ? NULL : malloc((size_t)m->size * 2 * sizeof *cnt);
    if (!bad && !cnt) jf_mpi_fail(m, "out of memory");
    if (bad || jf_mpi_check(m)) {
        free(mine);
        free(cnt);
        return 1;
    }
    int *dsp = cnt + m->size, mb = (int)(nm * sizeof *mine);
    MPI_Allgather(&mb, 1, MPI_INT, cnt, 1, MPI_INT, m->comm);
    size_t tot = 0;
    for (int k = 0; k < m->size; k++) {
        dsp[k] = (int)tot;
        tot += (size_t)cnt[k];
    }
    if (tot > (size_t)INT_MAX || !(all = malloc(tot ? tot : 1))) jf_mpi_fail(m, "out of memory");
    if (jf_mpi_check(m)) {
        free(mine);
        free(all);
        free(cnt);
        return 1;
    }
    MPI_Allgatherv(mine, mb, MPI_BYTE, all, cnt, dsp, MPI_BYTE, m->comm);
    o->params.auto_select = jf__auto_cv_select(&o->params, all, tot / sizeof *all);
    free(mine);
    free(all);
    free(cnt);
    return 0;
}

static int refuse(jf_mpi *m, const char *fmt, const char *what)
{
    if (m->rank == 0) {
        fprintf(stderr, "jetfit-mpi: ");
        fprintf(stderr, fmt, what);
        fputc('\n', stderr);
    }
    return 1;
}

static int estimate(jf_mpi *m, int argc, char **argv)
{
    jf_cli_estimate_cmd cmd;
    jf_cli_bad bad;
    if (jf_cli_estimate_parse(argc, argv, &cmd, &bad)) {
        if (m->rank == 0 && !bad.opt)
            fprintf(stderr, "jetfit-mpi estimate: %s (jetfit-mpi --help)\n", bad.why);
        else if (m->rank == 0)
            fprintf(stderr, "jetfit-mpi estimate: %s '%s': %s (jetfit estimate --help)\n",
                    bad.opt, bad.val ? bad.val : "", bad.why);
        return 2;
    }
    if (cmd.help) {
        if (m->rank == 0) usage(stdout);
        return 0;
    }
    jf_estimate_opts o = cmd.e.o;
    const char *in = cmd.in, *out = cmd.out;
    if (!strcmp(in, "-") || !strcmp(out, "-") || cmd.in_fmt || cmd.out_fmt)
        return refuse(m, "%s: distributed runs read and write named files (each rank reads its "
                         "share): no standard input or output, no --input-format or "
                         "--output-format; use jetfit estimate for pipes", "-");
    if (cmd.las_columns)
        return refuse(m, "%s: --las-columns: jetfit-mpi writes doubles; use jetfit estimate for "
                         "float columns", out);
    char nbs[64];
    jf_nb_format(&o.nb, nbs, sizeof nbs);
    if (o.nb.kind == JF_NB_NATURAL || o.nb.kind == JF_NB_RINGS)
        return refuse(m, "--neighbors %s: not supported in distributed runs (it needs the whole "
                         "triangulation or mesh); use knn, radius or knn,radius, or jetfit "
                         "estimate", nbs);
    if (o.orient == JF_ORIENT_MST || o.orient == JF_ORIENT_SCANNER)
        return refuse(m, "--orient %s: not supported in distributed runs (it needs the whole "
                         "cloud at once); use none, input or viewpoint:X,Y,Z, or jetfit estimate",
                      o.orient == JF_ORIENT_MST ? "mst" : "scanner");
    jf_format fin = jf_format_from_path(in), fout = jf_format_from_path(out);
    if (fin != JF_FMT_PLY && fin != JF_FMT_LAS)
        return refuse(m, "%s: distributed runs read binary PLY and LAS only (jetfit estimate "
                         "reads the other formats; a PLY tool or jetfit can convert)", in);
    if (fout == JF_FMT_LAS)
        return refuse(m, "%s: LAS output is not supported in distributed runs (write .ply, "
                         ".csv or .xyz)", out);
    if (m->rank == 0 && jf_same_file(in, out)) {
        fprintf(stderr, "jetfit-mpi: %s: is the input file (%s); write the result to another "
                        "file\n", out, in);
        return 1;
    }
    if (jf_same_file(in, out)) return 1;

    double t0 = MPI_Wtime();
    jf_row_layout lay;
    jf_mpi_probe(m, in, &lay);
    if (jf_mpi_check(m)) return 1;
    o.orient = jf_orient_resolve(o.orient, lay.has_normals, 0); /* the library's rule */
    if (o.orient == JF_ORIENT_INPUT && !lay.has_normals)
        return refuse(m, "%s: orient input: the cloud has no normals", in);
    jf_part_query q;
    if (jf__part_query_init(&o, &q) != JF_OK)
        return refuse(m, "%s: invalid parameters", in);

    jf_column cols[JF_RESULT_MAX_COLS];
    size_t ncols = jf_result_columns(cmd.e.o.params.monge_degree, o.nb.kind == JF_NB_AUTO, cols);
    outputs w;
    memset(&w, 0, sizeof w);
    /* open the output first: a missing folder fails before the work */
    if (m->rank == 0) open_outputs(m, out, cmd.ascii, cols, ncols, lay.count, &w);
    if (jf_mpi_check(m)) {
        abort_outputs(&w);
        return 1;
    }
    MPI_Bcast(&w.header, 1, MPI_UINT64_T, 0, m->comm);
    size_t rowb = 0;
    for (size_t j = 0; j < ncols; j++) rowb += cols[j].type == JF_COL_F64 ? 8 : 4;
    const uint64_t bytes = w.header + lay.count * (uint64_t)rowb;
    if (m->rank == 0) reserve(m, &w, out, bytes);
    if (jf_mpi_check(m)) {
        abort_outputs(&w);
        return 1;
    }

    jf_mpi_cloud c;
    int normals = o.orient == JF_ORIENT_INPUT;
    jf_mpi_load(m, in, &lay, &q, normals, o.threads, &c);
    int failed = m->failed;
    double t1 = MPI_Wtime();
    /* rank 0's progress line: its own points (the ranks fit at one pace) */
    jf_cli_progress pg;
    jf_cli_progress_init(&pg, "jetfit-mpi", m->rank == 0 && !cmd.quiet && isatty(2));
    if (m->rank == 0) {
        o.phase = jf_cli_progress_phase;
        o.phase_user = &pg;
    }
    jf_result *res = NULL;
    uint64_t kall[JF_CLI_NKBIN] = {0}; /* rank 0: auto's chosen K, every rank's rows */
    if (!failed && o.nb.kind == JF_NB_AUTO) failed = auto_cap(m, in, &c, &o, lay.count);
    if (!failed) {
        res = malloc((c.n ? c.n : 1) * sizeof *res);
        jf_cloud lc = {0};
        lc.n = c.n;
        lc.xyz = c.xyz;
        lc.nrm = c.nrm;
        jf_error err = {{0}};
        jf_status st = res ? jf__estimate_masked(&lc, &o, c.own, res, &err) : JF_ERR_NOMEM;
        jf_cli_progress_end(&pg);
        if (st != JF_OK) jf_mpi_fail(m, "%s: %s", in, err.msg[0] ? err.msg : jf_strerror(st));
        /* fault injection for tests/mpi/test_mpi.sh: this rank fails here */
        const char *inj = getenv("JETFIT_MPI_TEST_FAIL");
        if (inj && *inj && atoi(inj) == m->rank)
            jf_mpi_fail(m, "rank %d: injected failure (JETFIT_MPI_TEST_FAIL)", m->rank);
        failed = jf_mpi_check(m);
        if (!failed) {
            nothing_fitted(m, in, &c, res, lay.count);
            failed = jf_mpi_check(m);
        }
        /* auto's chosen K over every rank's own rows, for the summary */
        if (!failed && o.nb.kind == JF_NB_AUTO) {
            uint64_t mine[JF_CLI_NKBIN] = {0};
            for (size_t j = 0; j < c.n; j++)
                if (c.own[j] && (res[j].status & JF_PT_AUTO)) mine[jf_cli_kbin(res[j].n_used)]++;
            MPI_Reduce(mine, kall, JF_CLI_NKBIN, MPI_UINT64_T, MPI_SUM, 0, m->comm);
        }
    }
    double t2 = MPI_Wtime();
    if (!failed) {
        write_rows(m, &w, out, &c, res, cols, ncols, cmd.e.o.params.monge_degree, o.threads);
        failed = jf_mpi_check(m);
    }
    free(res);
    double t3 = MPI_Wtime();
    if (!failed && m->rank == 0 && !commit_length(m, &w, out, bytes)) {
        jf_error err = {{0}};
        if (w.txt) {
            jf_writer_progress(w.txt, jf_cli_progress_phase, &pg);
            jf_cli_progress_phase(&pg, JF_PHASE_WRITE, 0, (size_t)lay.count);
            convert_text(m, &w, cols, ncols, lay.count, o.threads);
            jf_cli_progress_end(&pg);
            jf_writer_abort(w.bin); /* the side file's temporary goes */
            w.bin = NULL;
            jf_writer *t = w.txt;
            w.txt = NULL;
            if (jf_writer_commit(t, &err) != JF_OK) jf_mpi_fail(m, "%s", err.msg);
        } else {
            jf_writer *b = w.bin;
            w.bin = NULL;
            if (jf__writer_placed(b, (size_t)lay.count) != JF_OK) {
                jf_writer_abort(b);
                jf_mpi_fail(m, "%s: rows missing", out);
            } else if (jf_writer_commit(b, &err) != JF_OK)
                jf_mpi_fail(m, "%s", err.msg);
        }
    }
    if (failed || m->failed) abort_outputs(&w);
    if (!failed) failed = jf_mpi_check(m); /* rank 0's commit */
    /* figures: the slowest rank's time in each step, the halo's total */
    double mine[3] = {m->t_exchange, t2 - t1, t3 - t2}, worst[3];
    uint64_t hl[2] = {c.nhalo, c.fetched}, hall[2];
    MPI_Reduce(mine, worst, 3, MPI_DOUBLE, MPI_MAX, 0, m->comm);
    MPI_Reduce(hl, hall, 2, MPI_UINT64_T, MPI_SUM, 0, m->comm);
    if (!failed && !cmd.quiet && m->rank == 0) {
        double secs = MPI_Wtime() - t0;
        fprintf(stderr, "jetfit-mpi: %llu points on %d ranks in %.2f s (%.0f points/s)\n",
                (unsigned long long)lay.count, m->size, secs,
                secs > 0 ? (double)lay.count / secs : 0.0);
        fprintf(stderr, "  exchange %.2f s, fit %.2f s, write %.2f s (slowest rank)\n",
                worst[0], worst[1], worst[2]);
        fprintf(stderr, "  halo: %llu points kept, %llu fetched (%.4f, %.4f of the points)\n",
                (unsigned long long)hall[0], (unsigned long long)hall[1],
                lay.count ? (double)hall[0] / (double)lay.count : 0.0,
                lay.count ? (double)hall[1] / (double)lay.count : 0.0);
        if (o.nb.kind == JF_NB_AUTO) { /* the chosen K and step 0's decision, as jetfit estimate's */
            size_t kc[JF_CLI_NKBIN];
            for (int b = 0; b < JF_CLI_NKBIN; b++) kc[b] = (size_t)kall[b];
            jf_cli_auto_summary(stderr, kc, o.params.auto_select);
        }
        fprintf(stderr, "  output: %s\n", out);
    }
    jf_mpi_cloud_free(&c);
    return failed ? 1 : 0;
}

int main(int argc, char **argv)
{
    int provided = 0;
    MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
    jf_mpi m;
    memset(&m, 0, sizeof m);
    m.comm = MPI_COMM_WORLD;
    MPI_Comm_rank(m.comm, &m.rank);
    MPI_Comm_size(m.comm, &m.size);
    MPI_Comm_set_errhandler(m.comm, MPI_ERRORS_ARE_FATAL);
    int rc, asked, nt = jf_default_threads(&asked);
    if (nt != asked && m.rank == 0)
        fprintf(stderr, "jetfit-mpi: OMP_NUM_THREADS asks for %d threads: %d by default here "
                        "(the processors available; --threads N overrides)\n", asked, nt);
    if (argc >= 2 && (!strcmp(argv[1], "-h") || !strcmp(argv[1], "--help"))) {
        if (m.rank == 0) usage(stdout);
        rc = 0;
    } else if (argc >= 2 && !strcmp(argv[1], "--version")) {
        if (m.rank == 0) {
            int major = 0, minor = 0, len = 0;
            char lib[MPI_MAX_LIBRARY_VERSION_STRING];
            MPI_Get_version(&major, &minor);
            MPI_Get_library_version(lib, &len);
            lib[strcspn(lib, "\n")] = '\0';
            printf("jetfit-mpi %s\nMPI %d.%d (%s)\n", jf_version(), major, minor, lib);
        }
        rc = 0;
    } else if (argc < 2 || strcmp(argv[1], "estimate")) {
        if (m.rank == 0) {
            fprintf(stderr, "jetfit-mpi: expected the command 'estimate'\n");
            usage(stderr);
        }
        rc = 2;
    } else {
        if (m.rank == 0) catch_signals();
        rc = estimate(&m, argc - 1, argv + 1);
    }
    MPI_Finalize();
    return rc;
}

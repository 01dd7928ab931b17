/* cmd_estimate.c -- `jetfit estimate INPUT -o OUTPUT [options]`: read,
 * estimate (jf_estimate), write one row per input point, summarise.
 * Uses only the public header. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <omp.h>

#include "auto_k.h"
#include "cmd.h"
#include "core/order_stat.h" /* the percentiles without sorting 10^8 conds */
#include "estimate/parts.h"  /* --memory: the plan (jf__parts_plan) */
#include "io/io_internal.h"   /* --memory: a PLY or LAS header's point count */
#include "jetfit.h"
#include "opts.h"
#include "pipes.h"
#include "progress.h"

#define DEFAULT_NEIGHBORS JF_CLI_DEFAULT_NEIGHBORS

static void usage(FILE *f)
{
    jf_params p;
    jf_params_init(&p);
    fprintf(f,
        "usage: jetfit estimate [options] INPUT -o OUTPUT\n"
        "\n"
        "Fits an osculating jet (Cazals & Pouget 2003) at every point of INPUT\n"
        "and writes one row per input point, in input order.\n"
        "INPUT: .ply .xyz .pts .txt .csv .off .las .ptx .e57   OUTPUT: .ply .csv .xyz .txt .las .laz\n"
        "\n"
        "  -o, --output FILE     output file (written to a temporary, renamed at the end);\n"
        "                        '-' is standard output (with --output-format)\n"
        "  --input-format FMT    read INPUT as FMT (ply xyz txt pts csv off las laz ptx e57)\n"
        "                        whatever its extension; needed when INPUT is '-'\n"
        "                        (standard input, e.g. a pipe from PDAL or awk)\n"
        "  --output-format FMT   write FMT (ply csv xyz txt las laz) whatever the name\n"
        "  --neighbors SPEC      knn:K | radius:R | knn:K,radius:R | rings[:N] (mesh input)\n"
        "                        | natural[:N] | auto (default " DEFAULT_NEIGHBORS "; K and N count\n"
        "                        the point; radius:R keeps at most the 256 nearest; auto:\n"
        "                        per point, K <= 256 and degree 2 or 3 chosen from the\n"
        "                        data, status flag auto, column sigma = the noise seen;\n"
        "                        K capped by the cloud's cross-validation where the\n"
        "                        noise is thin: flag auto_capped; the neighbours' fits\n"
        "                        weighted where the noise bounds them: auto_weighted)\n"
        "  --degree N            jet degree 1..%d (default %d)\n"
        "  --monge-degree N      2..4, <= degree: 3 adds b0..b3, 4 adds c0..c4\n"
        "                        (default min(degree, 4))\n"
        "  --fit MODE            approx | interp (default approx)\n"
        "  --frame MODE          pca | axis (default pca)\n"
        "  --max-cond X          lower the degree while cond > X (default %g)\n"
        "  --orient MODE         none | input | viewpoint:X,Y,Z | scanner | mst[:K]\n"
        "                        (default: scanner for a PTX or E57 INPUT (its scanner\n"
        "                        positions), else input if INPUT has normals,\n"
        "                        else none;\n"
        "                        mst uses K nearest neighbours, default 8)\n"
        "  --normal MODE         natural only: tangent plane from auto | poles |\n"
        "                        mincirc (both: 3D Delaunay) | pca (PCA of knn:16)\n"
        "                        | jet (jet of knn:N; rings on, and the fit of,\n"
        "                        the jet-projected points) | input (default auto:\n"
        "                        jet on a noisy cloud, else pca)\n"
        "  --robust MODE         none | huber | tukey (default none)\n"
        "  --scales K1,K2,...    per-point scale selection among these K (default off)\n"
        "  --degree-select DMIN  per-point degree choice in DMIN..degree: the lowest\n"
        "                        degree whose normal agrees with every higher one\n"
        "                        within their uncertainty (noisy data, small K;\n"
        "                        default off)\n"
        "  --dist-weight C       Gaussian weights on the distance to the point,\n"
        "                        sigma = C x the farthest neighbour (clean data:\n"
        "                        0.3-0.4; default off)\n"
        "  --robust-normals      preset for normals on data of unknown noise:\n"
        "                        --degree-select 1 --dist-weight 0.55 (later flags\n"
        "                        override; measured on PCPNet: docs/robustness.md)\n"
        "  --columns X,Y,Z[,NX,NY,NZ]\n"
        "                        .xyz/.txt/.pts/.csv: 0-based columns of x y z [nx ny nz]\n"
        "                        (default: x y z first, normals in 3..5 if 6 columns)\n"
        "  --bad-rows MODE       text input: error (default) stops at the first\n"
        "                        unparsable row; skip keeps it as a NaN row (status\n"
        "                        nonfinite, so rows stay aligned with the input)\n"
        "  --threads N           OpenMP threads (default: all cores, here %d)\n"
        "  --ascii               ascii PLY output (default binary little endian)\n"
        "  --memory SIZE         memory budget of the whole run, e.g. 8G, 256M (K, M,\n"
        "                        G, T: powers of 1024; default: the available memory,\n"
        "                        MemAvailable); when the whole cloud's k-d tree would\n"
        "                        not fit, the cloud is fitted in parts with exact\n"
        "                        halos, one at a time (same output), a binary PLY\n"
        "                        input's coordinates read from the file when they do\n"
        "                        not fit; a SIZE too small is refused, naming the least\n"
        "                        that works\n"
        "  --keep MODE           all (default): the input's other per-point values\n"
        "                        (PLY properties, named CSV columns, LAS dimensions;\n"
        "                        a LAS output keeps the LAS records) go to the output\n"
        "                        after x y z, a name that clashes renamed in_NAME;\n"
        "                        none: jetfit's columns only\n"
        "  --las-scale X,Y,Z     a LAS output's scale per axis (or one value), and\n"
        "  --las-offset X,Y,Z    its offset (default: the minimum); without them\n"
        "                        the scale is the smallest power of ten >= 1e-7\n"
        "                        keeping counts in int32, with a warning when an\n"
        "                        outlier makes it coarse (docs/formats.md)\n"
        "  --las-columns TYPE    double | float | compact: the Extra Bytes type of\n"
        "                        jetfit's real-valued columns in a .las or .laz output\n"
        "                        (default double for .las, compact for .laz: floats,\n"
        "                        nx ny nz d1x..d2z rounded to multiples of 2^-16;\n"
        "                        float: 7 digits; docs/formats.md)\n"
        "  -q, --quiet           no progress line, no summary\n"
        "  -h, --help            this text\n"
        "Options follow GNU conventions: --degree=3 or --degree 3, -oFILE, unique\n"
        "abbreviations (--neighb knn:16), '--' ends the options.\n"
        "\n"
        "Columns: x y z nx ny nz k1 k2 d1x d1y d1z d2x d2y d2z [b0..b3] [c0..c4]\n"
        "         degree neighbors cond residual [sigma] status\n"
        "k1 >= k2, signed w.r.t. the normal (z = (k1 x^2 + k2 y^2)/2 + ... along it).\n",
        JF_MAX_DEGREE, p.degree, p.max_cond, jf_default_threads(NULL));
}

/* MemAvailable of /proc/meminfo in bytes, or 0 when unknown. */
static unsigned long long mem_available(void)
{
    FILE *f = fopen("/proc/meminfo", "r");
    char line[256];
    unsigned long long kb = 0;
    while (f && fgets(line, sizeof line, f))
        if (sscanf(line, "MemAvailable: %llu kB", &kb) == 1) break;
    if (f) fclose(f);
    return kb * 1024ULL;
}

/* A byte count as --memory takes it, rounded up: K below 64M, else M
 * (G, M when exact). */
static const char *size_str(unsigned long long b, char out[32])
{
    if (b % (1ULL << 30) == 0 && b) snprintf(out, 32, "%lluG", b >> 30);
    else if (b % (1ULL << 20) == 0 && b) snprintf(out, 32, "%lluM", b >> 20);
    else if (b < (64ULL << 20)) snprintf(out, 32, "%lluK", (b + 1023) >> 10);
    else snprintf(out, 32, "%lluM", (b + (1ULL << 20) - 1) >> 20);
    return out;
}

static int bad_option(const char *opt, const char *val, const char *why)
{
    if (!opt) { /* the scanner's whole message (args.h) */
        fprintf(stderr, "jetfit estimate: %s (jetfit estimate --help)\n", why);
        return 2;
    }
    fprintf(stderr, "jetfit estimate: %s '%s': %s (jetfit estimate --help)\n", opt,
            val ? val : "", why);
    return 2;
}

/* ---- progress line and summary ---------------------------------------- */

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* What the summary counts, per thread (the sink runs on the fit's
 * threads), padded so that threads do not share a cache line. */
typedef struct {
    size_t flags[32], ok, deg[JF_MAX_DEGREE + 1], k[JF_CLI_NKBIN]; /* k: auto's chosen K (auto_k.h) */
    size_t unfit; /* failed or nonfinite: no fit at all */
    double big;   /* coordinates on disk: the largest finite |x|, |y|, |z| */
    char pad[64];
} tally;

static void tally_add(tally *t, const jf_result *r)
{
    if (r->status & JF_PT_AUTO) t->k[jf_cli_kbin(r->n_used)]++;
    if (!(r->status & ~JF_CLI_HOW_FLAGS)) t->ok++; /* under auto every row has a flag */
    if (r->status & (JF_PT_FAILED | JF_PT_NONFINITE)) t->unfit++;
    for (int b = 0; b < 32; b++)
        if (r->status & (1u << b)) t->flags[b]++;
    if (r->degree >= 0 && r->degree <= JF_MAX_DEGREE) t->deg[r->degree]++;
}

/* cond[i] of every point (NaN skipped); nt tallies summed. */
static void summary(const tally *tl, int nt, double *cond, size_t n, size_t nbad, double secs,
                    const char *out, int chosen)
{
    tally t = {{0}, 0, {0}, {0}, 0, 0, {0}};
    for (int k = 0; k < nt; k++) {
        for (int b = 0; b < JF_CLI_NKBIN; b++) t.k[b] += tl[k].k[b];
        t.ok += tl[k].ok;
        for (int b = 0; b < 32; b++) t.flags[b] += tl[k].flags[b];
        for (int d = 0; d <= JF_MAX_DEGREE; d++) t.deg[d] += tl[k].deg[d];
    }
    fprintf(stderr, "jetfit: %zu points in %.2f s (%.0f points/s)\n", n, secs,
            secs > 0 ? (double)n / secs : 0.0);
    fprintf(stderr, "  status: ok %zu", t.ok);
    for (int b = 0; b < 32; b++) {
        char name[64];
        if (t.flags[b])
            fprintf(stderr, ", %s %zu", jf_point_status_str(1u << b, name, sizeof name),
                    t.flags[b]);
    }
    fprintf(stderr, "\n  degree:");
    for (int d = 0; d <= JF_MAX_DEGREE; d++)
        if (t.deg[d]) fprintf(stderr, " %d: %zu", d, t.deg[d]);
    fputc('\n', stderr);
    jf_cli_auto_summary(stderr, t.k, chosen); /* neighbors auto: what it chose */
    size_t m = 0;
    if (cond)
        for (size_t i = 0; i < n; i++)
            if (isfinite(cond[i])) cond[m++] = cond[i];
    if (m) {
        /* each selection leaves the larger values above its rank */
        size_t r[4] = {(m - 1) / 2, (size_t)(0.9 * (double)(m - 1)), (size_t)(0.99 * (double)(m - 1)),
                       m - 1};
        for (int q = 0; q < 4; q++) {
            size_t from = q ? r[q - 1] : 0;
            jf__select_kth(cond + from, m - from, r[q] - from);
        }
        fprintf(stderr, "  cond: p50 %.3g, p90 %.3g, p99 %.3g, max %.3g\n", cond[r[0]], cond[r[1]],
                cond[r[2]], cond[r[3]]);
    }
    if (nbad)
        fprintf(stderr, "  bad rows: %zu (kept as NaN rows, status nonfinite)\n", nbad);
    fprintf(stderr, "  output: %s\n", out);
}

/* ---- output ------------------------------------------------------------ */

/* ---- rows straight to the output ------------------------------------- */

/* design (docs/scale.md): results are never held for the whole cloud.
 * jf_estimate_blocks hands over blocks of <= JF_BLOCK_MAX results from the fit's
 * threads; each block becomes rows written at their input index
 * (jf_writer_put: in place for binary PLY and LAS, through a binary spool
 * for text).  What stays per point: the coordinates, the index, and the
 * condition numbers for the summary's quantiles. */
typedef struct {
    jf_writer *w;
    const double *xyz;
    int monge, nt, sigma;
    size_t ncols;
    double *rows;    /* nt x JF_BLOCK_MAX x ncols: a block per thread    */
    tally *tl;       /* nt                                              */
    double *cond;    /* n, or NULL (--quiet)                            */
    int wfail;       /* a jf_writer_put failed (atomic)                 */
    jf_cli_progress *pg; /* counts the points fitted (parts too)        */
} sinkctx;

/* The rows of one fitted block into the writer: point j's coordinates at
 * xyz + 3 idx[j] (by_index: the cloud's, in input order) or xyz + 3 j
 * (handed over in the block's order); track_big: the largest finite
 * coordinate kept for the "nothing fitted" message (the cloud not held). */
static inline __attribute__((always_inline)) jf_status
put_rows(sinkctx *s, const uint32_t *idx, const double *xyz, int by_index, int track_big,
         jf_result *res, size_t m)
{
    int t = omp_get_thread_num();
    if (t >= s->nt) return JF_ERR_INVALID; /* more threads than planned */
    double *v = s->rows + (size_t)t * JF_BLOCK_MAX * s->ncols;
    for (size_t j = 0; j < m; j++) {
        if (j + 8 < m) { /* input order: a cache miss each, asked for early */
            if (by_index) __builtin_prefetch(xyz + 3 * (size_t)idx[j + 8]);
            if (s->cond) __builtin_prefetch(s->cond + idx[j + 8], 1);
        }
        const double *p = xyz + 3 * (by_index ? (size_t)idx[j] : j);
        jf_result_row(p, &res[j], s->monge, s->sigma, v + j * s->ncols);
        tally_add(&s->tl[t], &res[j]);
        if (s->cond) s->cond[idx[j]] = res[j].cond;
        for (int k = 0; track_big && k < 3; k++)
            if (isfinite(p[k]) && fabs(p[k]) > s->tl[t].big) s->tl[t].big = fabs(p[k]);
    }
    jf_status st = jf_writer_put(s->w, idx, v, m);
    if (st != JF_OK) __atomic_store_n(&s->wfail, 1, __ATOMIC_RELAXED);
    if (s->pg) jf_cli_progress_fitted(s->pg, m);
    return st;
}

static jf_status sink_block(void *user, const uint32_t *idx, jf_result *res, size_t m)
{
    sinkctx *s = user;
    return put_rows(s, idx, s->xyz, 1, 0, res, m);
}

/* The same with the block's coordinates handed over by the fit (its
 * walk's, in tree order): the rows read no point by input index (in a
 * shuffled input a cache and TLB miss each, ~5% of a knn:16 run). */
static jf_status sink_block_walk(void *user, const uint32_t *idx, const double *xyz,
                                 jf_result *res, size_t m)
{
    return put_rows(user, idx, xyz, 0, 0, res, m);
}

/* The same with the coordinates handed over (--memory with the
 * coordinates on disk: jf__estimate_parts_src reads them as it goes). */
static jf_status sink_block_xyz(void *user, const uint32_t *idx, const double *xyz, jf_result *res,
                                size_t m)
{
    return put_rows(user, idx, xyz, 0, 1, res, m);
}

/* ---- the command ---------------------------------------------------------- */

/* The refusal of a --memory too small (jf__memory_precheck's figures),
 * in one line; r->ooc: the least with the coordinates read from the file
 * as needed.  What else the run holds is named when it is not nothing. */
static void memory_refused(const char *in, unsigned long long memory, const jf_memchk *r)
{
    char given[32], least[32], held[32], what[160];
    if (!r->ooc)
        snprintf(what, sizeof what, "the cloud and the summary's values: %s",
                 size_str(r->held, held));
    else if (r->held)
        snprintf(what, sizeof what, "with the coordinates read from the file as needed; the "
                 "summary's values, normals and attributes: %s", size_str(r->held, held));
    else
        snprintf(what, sizeof what, "with the coordinates read from the file as needed");
    fprintf(stderr, "jetfit: %s: --memory %s is too small for %zu points: the least that works is "
                    "--memory %s (%s)\n", in, size_str(memory, given), r->n,
            size_str(r->need_min, least), what);
}

/* --las-columns: checked here, applied by the library's rule
 * (jf__las_columns, the Python binding's too: .laz compact unless told). */
static jf_status las_columns(const jf_cli_estimate_cmd *cmd, const char *path, jf_column *cols,
                             size_t ncols, jf_error *err)
{
    size_t l = strlen(path);
    int laz = l >= 4 && !strcasecmp(path + l - 4, ".laz");
    if (cmd->las_columns && !laz && !(l >= 4 && !strcasecmp(path + l - 4, ".las"))) {
        snprintf(err->msg, sizeof err->msg, "%s: --las-columns applies to a .las or .laz output",
                 cmd->out);
        return JF_ERR_INVALID;
    }
    jf__las_columns(path, cmd->las_columns, cols, ncols);
    return JF_OK;
}

/* fd's file as it was (sb): same size and modification time. */
static int same_file_state(int fd, const struct stat *sb)
{
    struct stat now;
    return fstat(fd, &now) == 0 && now.st_size == sb->st_size &&
           now.st_mtim.tv_sec == sb->st_mtim.tv_sec && now.st_mtim.tv_nsec == sb->st_mtim.tv_nsec;
}

static int estimate(int argc, char **argv, int *fd);

int jf_cmd_estimate(int argc, char **argv)
{
    int fd = -1; /* --memory: the input, read as the parts need it */
    int rc = estimate(argc, argv, &fd);
    if (fd >= 0) close(fd);
    return rc;
}

static int estimate(int argc, char **argv, int *fd)
{
    jf_cli_estimate_cmd cmd;
    jf_cli_bad bad;
    if (jf_cli_estimate_parse(argc, argv, &cmd, &bad)) return bad_option(bad.opt, bad.val, bad.why);
    if (cmd.help) {
        usage(stdout);
        return 0;
    }
    jf_cli_est e = cmd.e;
    const char *in = cmd.in, *out = cmd.out;
    int quiet = cmd.quiet, ascii = cmd.ascii, keep = cmd.keep;
    unsigned long long memory = cmd.memory; /* --memory; 0: MemAvailable */
    jf_estimate_opts o = e.o;
    int monge = e.o.params.monge_degree;
    jf_error err = {{0}};

    double t0 = now_s();
    jf_cloud c = {0};
    int ooc = 0; /* --memory: coordinates read from the input file as needed */
    jf_row_layout lay;
    memset(&lay, 0, sizeof lay);
    struct stat isb; /* the input when opened: a change by the end spoils the parts' reads */
    memset(&isb, 0, sizeof isb);
    /* writing over the input would lose its other columns (and, renamed
     * over it, the input itself) */
    if (jf_same_file(in, out)) {
        fprintf(stderr, "jetfit: %s: is the input file (%s); write the result to another file\n",
                out, in);
        return 1;
    }
    {
        jf_column pc[JF_RESULT_MAX_COLS];
        const int kd = o.nb.kind != JF_NB_RINGS && o.nb.kind != JF_NB_NATURAL &&
                       o.orient != JF_ORIENT_MST;
        jf_memchk mc;
        jf_plan_nb pnb; /* the halo's ring and auto's records */
        jf__plan_nb(&o, &pnb);
        ooc = jf__memory_precheck(in, cmd.in_fmt, memory, !quiet,
                                  jf_result_columns(monge, o.nb.kind == JF_NB_AUTO, pc),
                                  o.threads > 0 ? o.threads : jf_default_threads(NULL), kd, &pnb, keep,
                                  out, cmd.out_fmt, &lay, &mc);
        if (ooc == JF_MEMCHK_REFUSED) {
            memory_refused(in, memory, &mc);
            return 1;
        }
        ooc = ooc == JF_MEMCHK_OOC;
    }
    e.ro.no_attrs = !keep; /* --keep none: not even read */
    e.ro.threads = o.threads; /* text input parsed in blocks on them */
    /* the progress line: reading, indexing (or ordering), fitting,
     * writing; the phases' times go to the summary */
    jf_cli_progress pg;
    jf_cli_progress_init(&pg, "jetfit", !quiet && isatty(2));
    e.ro.progress = jf_cli_progress_phase;
    e.ro.progress_user = &pg;
    if (o.threads > 0)
        omp_set_num_threads(o.threads); /* the LAZ reader decodes chunks on them */
    jf_status st = JF_ERR_UNSUPPORTED;
    if (ooc) { /* everything but the coordinates; a PLY that does not qualify: read whole */
        *fd = open(in, O_RDONLY);
        if (*fd >= 0 && fstat(*fd, &isb) == 0 && S_ISREG(isb.st_mode))
            st = jf__read_ply_chunked_noxyz(*fd, (size_t)isb.st_size, in, &e.ro, &c, &err);
        if (st != JF_OK && *fd >= 0) close(*fd), *fd = -1;
        if (st == JF_OK && c.n != lay.count) {
            jf_cloud_free(&c);
            st = JF_ERR_UNSUPPORTED; /* the file changed since its header was read */
        }
        ooc = st == JF_OK;
    }
    if (ooc) {
        /* the attributes known: the cloud read whole when it fits (no
         * reads per part), else parts with the coordinates on disk */
        const int pt = o.threads > 0 ? o.threads : jf_default_threads(NULL);
        jf_column pc[JF_RESULT_MAX_COLS];
        const size_t nc = jf_result_columns(monge, o.nb.kind == JF_NB_AUTO, pc);
        size_t held = c.n * ((c.nrm ? 24 : 0) + (quiet ? 0 : 8)) +
                      (c.attrs.rec ? c.n * c.attrs.stride : 0);
        jf_plan_nb pnb;
        jf__plan_nb(&o, &pnb);
        if (jf__parts_plan(c.n, held + 24 * c.n, nc, pt, &pnb, memory, NULL, NULL)) {
            jf_cloud_free(&c);
            close(*fd);
            *fd = -1;
            ooc = 0;
        }
    }
    if (!ooc) st = jf_cli_cloud_read(in, cmd.in_fmt, &e.ro, &c, &err);
    if (st != JF_OK) {
        jf_cli_progress_end(&pg);
        fprintf(stderr, "jetfit: %s\n", err.msg[0] ? err.msg : jf_strerror(st));
        return 1;
    }
    jf_cli_progress_end(&pg); /* the line ends before any message */
    if (c.nbad) {
        /* --bad-rows skip: say which rows, so the user can look at them */
        char lines[160] = "";
        size_t shown = c.nbad < 10 ? c.nbad : 10, len = 0;
        for (size_t k = 0; k < shown && len < sizeof lines; k++)
            len += (size_t)snprintf(lines + len, sizeof lines - len, "%s%zu", k ? ", " : "",
                                    c.bad_line[k]);
        fprintf(stderr, "jetfit: %s: %zu unparsable rows kept as NaN rows (status nonfinite), "
                        "lines %s%s\n", in, c.nbad, lines, c.nbad > shown ? ", ..." : "");
    }
    if (o.orient == JF_ORIENT_SCANNER && !c.scanner) {
        fprintf(stderr, "jetfit: %s: --orient scanner needs the scanner positions of a PTX "
                        "or E57 file; this input has none\n", in);
        jf_cloud_free(&c);
        return 1;
    }

    /* open the output first: a missing folder fails before the work */
    jf_column cols[JF_RESULT_MAX_COLS];
    const int with_sigma = o.nb.kind == JF_NB_AUTO; /* auto: its noise estimate */
    size_t ncols = jf_result_columns(monge, with_sigma, cols);
    /* --memory SIZE bounds the whole process (docs/scale.md): the cloud,
     * the summary's values, the output's spool and buffers, then the
     * whole cloud's tree or one part at a time; too small: said now */
    int plan = 1;
    {
        const int pt = o.threads > 0 ? o.threads : jf_default_threads(NULL);
        size_t held = c.n * ((c.xyz ? 24 : 0) + (c.nrm ? 24 : 0) + (c.scan ? 4 : 0) + (quiet ? 0 : 8)) +
                      (c.attrs.rec ? c.n * c.attrs.stride : 0) + c.nfaces * 20;
        size_t need_whole = 0, need_min = 0;
        const int kd = o.nb.kind != JF_NB_RINGS && o.nb.kind != JF_NB_NATURAL &&
                       o.orient != JF_ORIENT_MST;
        jf_plan_nb pnb;
        jf__plan_nb(&o, &pnb);
        plan = jf__parts_plan(c.n, held, ncols, pt, &pnb, memory ? memory : mem_available(), &need_whole,
                              &need_min);
        if (ooc) { /* no coordinates held: parts only */
            size_t need_ooc = 0;
            plan = jf__parts_plan_ooc(c.n, held, ncols, pt, &pnb, lay.row, memory, &need_ooc);
            if (!plan) { /* the smaller of the two leasts */
                need_min = jf__parts_plan(c.n, held + 24 * c.n, ncols, pt, &pnb, memory, NULL, &need_min)
                               ? 0 : need_min;
                const int o1 = need_ooc < need_min;
                memory_refused(in, memory, &(jf_memchk){c.n, o1 ? need_ooc : need_min,
                                                        o1 ? held : held + 24 * c.n, o1});
                jf_cloud_free(&c);
                return 1;
            }
        } else if (plan != 1 && !kd) {
            if (!quiet)
                fprintf(stderr, "jetfit: note: %zu points exceed --memory %lluM, but rings, "
                                "natural and mst need the whole cloud: fitting it whole\n",
                        c.n, (memory ? memory : mem_available()) >> 20);
            plan = 1;
        } else if (plan == 0 && memory) {
            char given[32], least[32], cloud[32];
            fprintf(stderr, "jetfit: %s: --memory %s is too small for %zu points: the least that "
                            "works is --memory %s (the cloud and the summary's values: %s)\n", in,
                    size_str(memory, given), c.n, size_str(need_min, least), size_str(held, cloud));
            jf_cloud_free(&c);
            return 1;
        } else if (plan == 0)
            plan = 1; /* MemAvailable too small: try the whole cloud */
    }
    jf_writer *w = NULL;
    jf_cli_out po; /* "-o -" and --output-format: through a private file */
    st = jf_cli_out_begin(&po, out, cmd.out_fmt, &err);
    if (st == JF_OK) st = las_columns(&cmd, po.path, cols, ncols, &err);
    if (st == JF_OK) st = jf_writer_open(po.path, cols, ncols, c.n, ascii, &w, &err);
    if (st != JF_OK) {
        jf_cli_out_msg(&po, &err);
        fprintf(stderr, "jetfit: %s\n", err.msg[0] ? err.msg : jf_strerror(st));
        jf_cli_out_finish(&po, 0, NULL);
        jf_cloud_free(&c);
        return 1;
    }
    /* a mesh keeps its faces in a PLY output (MeshLab shows the fields on
     * the surface); never dropped silently (issue 33.3) */
    if (c.nfaces && (st = jf_writer_faces(w, c.nfaces, c.face_off, c.face_idx)) != JF_OK) {
        fprintf(stderr, "jetfit: %s: cannot write its %zu faces to %s: %s\n", in, c.nfaces, out,
                jf_strerror(st));
        jf_writer_abort(w);
        jf_cli_out_finish(&po, 0, NULL);
        jf_cloud_free(&c);
        return 1;
    }
    /* .las: the scale and offset (--las-scale, --las-offset, else the
     * rule); a cloud LAS cannot hold is refused here, before the work and
     * with no file made.  Kept LAS records keep their own. */
    size_t olen = strlen(out);
    int las_out = olen >= 4 && !strcasecmp(out + olen - 4, ".las");
    if ((cmd.las_scale_set || cmd.las_offset_set) && (!las_out || (keep && c.attrs.las_head))) {
        fprintf(stderr, "jetfit: %s: --las-scale and --las-offset %s\n", out,
                !las_out ? "apply to a .las output"
                         : "do not apply: the LAS input's records are kept with their own scale "
                           "and offset (add --keep none for new ones)");
        jf_writer_abort(w);
        jf_cli_out_finish(&po, 0, NULL);
        jf_cloud_free(&c);
        return 1;
    }
    if (!(keep && c.attrs.las_head) && !ooc && /* ooc: never a LAS output */
        jf_writer_las_frame_given(w, c.xyz, c.n, cmd.las_scale_set ? cmd.las_scale : NULL,
                                  cmd.las_offset_set ? cmd.las_offset : NULL) != JF_OK) {
        st = jf_writer_commit(w, &err); /* removes the temporary, says why */
        fprintf(stderr, "jetfit: %s\n", err.msg[0] ? err.msg : jf_strerror(st));
        jf_cli_out_finish(&po, 0, NULL);
        jf_cloud_free(&c);
        return 1;
    }
    /* the input's attributes after x y z (a LAS output from a LAS input
     * keeps its records) */
    st = jf_writer_attrs(w, &c.attrs);
    if (st != JF_OK) {
        fprintf(stderr, "jetfit: %s: cannot carry the input's attributes to %s: %s (use "
                        "--keep none)\n", in, out,
                st == JF_ERR_TOO_LARGE ? "a LAS record would exceed 65535 bytes or 341 "
                                         "Extra Bytes"
                                       : jf_strerror(st));
        jf_writer_abort(w);
        jf_cli_out_finish(&po, 0, NULL);
        jf_cloud_free(&c);
        return 1;
    }
    /* the writer's warnings (a name shortened, coordinates rounded): also
     * under --quiet, since they say the output differs from the input */
    for (const char *wl = jf_writer_warnings(w), *nl; *wl; wl = nl + 1) {
        if (!(nl = strchr(wl, '\n'))) break;
        fprintf(stderr, "jetfit: %.*s\n", (int)(nl - wl), wl);
    }
    const int nt = o.threads > 0 ? o.threads : jf_default_threads(NULL);
    sinkctx sk = {w, c.xyz, monge, nt, with_sigma, ncols, malloc((size_t)nt * JF_BLOCK_MAX * ncols * sizeof(double)),
                  calloc((size_t)nt, sizeof(tally)), quiet ? NULL : malloc((c.n ? c.n : 1) * sizeof(double)), 0, NULL};
    if (!sk.rows || !sk.tl || (!quiet && !sk.cond) || jf_writer_begin_put(w, o.threads) != JF_OK) {
        /* a failed begin is reported by commit's message below */
        if (!sk.rows || !sk.tl || (!quiet && !sk.cond))
            fprintf(stderr, "jetfit: out of memory (%zu points)\n", c.n);
        st = jf_writer_commit(w, &err);
        jf_cli_out_msg(&po, &err);
        if (st != JF_OK && sk.rows && sk.tl && (quiet || sk.cond))
            fprintf(stderr, "jetfit: %s\n", err.msg[0] ? err.msg : jf_strerror(st));
        free(sk.rows);
        free(sk.tl);
        free(sk.cond);
        jf_cli_out_finish(&po, 0, NULL);
        jf_cloud_free(&c);
        return 1;
    }
    sk.pg = &pg;
    pg.counted = 1; /* the sink counts: parts restart the library's counts */
    pg.fit_total = c.n;
    o.phase = jf_cli_progress_phase;
    o.phase_user = &pg;
    int chosen = 0; /* neighbors auto: step 0's decision, for the summary */
    o.auto_chosen = &chosen;
    jf_writer_progress(w, jf_cli_progress_phase, &pg);
    int nparts = plan > 1 ? plan : 1;
    pg.parts = nparts > 1;
    const jf_xyz_src src = {NULL, *fd, &lay};
    st = ooc          ? jf__estimate_parts_src(&c, &src, &o, nparts, sink_block_xyz, &sk, &err)
         : nparts > 1 ? jf_estimate_parts(&c, &o, nparts, sink_block, &sk, &err)
                      : jf__estimate_blocks_xyz(&c, &o, sink_block_walk, &sk, &err);
    if (st == JF_OK && ooc && !same_file_state(*fd, &isb)) {
        /* each part re-read the coordinates: written to in place during
         * the run, the parts may have seen different points */
        st = JF_ERR_IO;
        snprintf(err.msg, sizeof err.msg, "the file was modified while it was read (--memory "
                                          "reads it again for every part); nothing written");
    }
    free(sk.rows);
    jf_cli_progress_end(&pg); /* the fit's line ends before any message */
    if (st != JF_OK) {
        /* a failed write: the writer's own message says which file and
         * why (commit fails on it, and removes the temporary) */
        jf_error werr = {{0}};
        if (sk.wfail && jf_writer_commit(w, &werr) != JF_OK && werr.msg[0]) {
            jf_cli_out_msg(&po, &werr);
            fprintf(stderr, "jetfit: %s\n", werr.msg);
        } else {
            if (!sk.wfail) jf_writer_abort(w);
            fprintf(stderr, "jetfit: %s: %s\n", in, err.msg[0] ? err.msg : jf_strerror(st));
        }
        free(sk.tl);
        free(sk.cond);
        jf_cli_out_finish(&po, 0, NULL);
        jf_cloud_free(&c);
        return 1;
    }
    /* no point fitted (coordinates near 1e160 overflow every fit, K below
     * 3, a PTX transform or LAS scale of 1e300): an error, nothing written
     * (issues 31, 33.12); most points unfitted: a warning */
    size_t unfit = 0, nonfin = 0;
    for (int k = 0; k < nt; k++) {
        unfit += sk.tl[k].unfit;
        nonfin += sk.tl[k].flags[5]; /* JF_PT_NONFINITE */
    }
    if (c.n && unfit == c.n) {
        jf_writer_abort(w);
        double big = 0;
        for (size_t i = 0; c.xyz && i < 3 * c.n; i++)
            if (isfinite(c.xyz[i]) && fabs(c.xyz[i]) > big) big = fabs(c.xyz[i]);
        for (int k = 0; k < nt; k++) big = sk.tl[k].big > big ? sk.tl[k].big : big;
        fprintf(stderr, "jetfit: %s: no point could be fitted (%zu non-finite, %zu failed)%s; "
                        "nothing written\n", in, nonfin, c.n - nonfin,
                big > 1e150 ? ": coordinates near 1e150 or beyond overflow the fit (rescale "
                              "the cloud)"
                : nonfin < c.n ? ": too few or collinear neighbours (K must be at least 3)"
                               : ": every point is NaN or infinite (a scale or transform that "
                                 "overflows?)");
        jf_cli_out_finish(&po, 0, NULL);
        free(sk.tl);
        free(sk.cond);
        jf_cloud_free(&c);
        return 1;
    }
    if (unfit > c.n / 2)
        fprintf(stderr, "jetfit: %s: warning: %zu of %zu points could not be fitted (status "
                        "failed or nonfinite)\n", in, unfit, c.n);
    /* commit reports a failed row too, and removes the temporary; the
     * rows are formatted and written there */
    jf_cli_progress_phase(&pg, JF_PHASE_WRITE, 0, c.n);
    st = jf_writer_commit(w, &err);
    jf_cli_progress_end(&pg);
    if (st == JF_OK) st = jf_cli_out_finish(&po, 1, &err); /* to standard output, or renamed */
    else jf_cli_out_msg(&po, &err), jf_cli_out_finish(&po, 0, NULL);
    if (st != JF_OK) {
        fprintf(stderr, "jetfit: %s\n", err.msg[0] ? err.msg : jf_strerror(st));
        free(sk.tl);
        free(sk.cond);
        jf_cloud_free(&c);
        return 1;
    }
    if (!quiet) {
        char ph[160];
        summary(sk.tl, nt, sk.cond, c.n, c.nbad, now_s() - t0, out, chosen);
        if (nparts > 1) /* --memory: the cloud was fitted in parts */
            fprintf(stderr, "  parts: %d, one at a time, within --memory\n", nparts);
        jf_cli_progress_times(&pg, ph, sizeof ph);
        fprintf(stderr, "  phases: %s\n", ph);
    }
    free(sk.tl);
    free(sk.cond);
    jf_cloud_free(&c);
    return 0;
}

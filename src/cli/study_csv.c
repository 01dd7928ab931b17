/* study_csv.c -- `jetfit study`'s tables: DIR/study.csv (one row per cell,
 * RFC 4180 quoting since flag sets hold commas and spaces; numbers in the
 * shortest text that reads back to the same double, so a resumed study
 * rewrites the rows it kept byte for byte), reading it back for --resume,
 * means over repeats, and DIR/best.csv. */
#define _POSIX_C_SOURCE 200809L /* getline, dup, fdopen */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "study.h"

const char *const jf_study_metric[JF_M_COUNT] = {
    "normal_rms", "normal_median", "normal_p95", "k1_median", "k1_p95", "k2_median", "k2_p95"};

static const char *const head_key[] = {"strategy", "degree", "flags", "noise", "noise_uniform",
                                       "outliers", "repeat", "seed", "points", "normal_n"};
static const char *const head_tail[] = {"ok", "lowered", "failed", "flagged", "status",
                                        "seconds", "points_per_s"};
#define NKEY (sizeof head_key / sizeof head_key[0])
#define NTAIL (sizeof head_tail / sizeof head_tail[0])
#define NCOL (NKEY + JF_M_COUNT + NTAIL)

void jf_study_path(const char *dir, const char *name, char *buf, size_t len)
{
    snprintf(buf, len, "%s/%s", dir, name);
}

int jf_study_out_open(jf_study_out *o, const char *dir, const char *name, char *msg, size_t len)
{
    jf_error e = {{0}};
    jf_study_path(dir, name, o->final, sizeof o->final);
    if (jf_tmpfile_open(o->final, &o->t, &e) != JF_OK) {
        snprintf(msg, len, "%s", e.msg[0] ? e.msg : o->final);
        return -1;
    }
    /* a stream on a copy of the descriptor: commit closes the original */
    int fd = dup(o->t.fd);
    o->f = fd >= 0 ? fdopen(fd, "wb") : NULL;
    if (!o->f) {
        snprintf(msg, len, "%s: %s", o->final, strerror(errno));
        if (fd >= 0) close(fd);
        jf_tmpfile_discard(&o->t);
        return -1;
    }
    return 0;
}

int jf_study_out_commit(jf_study_out *o, char *msg, size_t len)
{
    jf_error e = {{0}};
    int bad = ferror(o->f);
    if (fclose(o->f)) bad = 1;
    o->f = NULL;
    if (bad) {
        snprintf(msg, len, "%s: %s", o->final, strerror(errno ? errno : EIO));
        jf_tmpfile_discard(&o->t);
        return -1;
    }
    if (jf_tmpfile_commit(&o->t, o->final, &e) != JF_OK) {
        snprintf(msg, len, "%s", e.msg[0] ? e.msg : o->final);
        return -1;
    }
    return 0;
}

/* The shortest of %.15g..%.17g that reads back exactly; "nan", "inf". */
static void put_num(FILE *f, double v)
{
    char b[40];
    if (isnan(v)) {
        fputs("nan", f);
        return;
    }
    for (int p = 15; p <= 17; p++) {
        snprintf(b, sizeof b, "%.*g", p, v);
        if (strtod(b, NULL) == v) break;
    }
    fputs(b, f);
}

static void put_str(FILE *f, const char *s)
{
    if (!strpbrk(s, ",\"\r\n")) {
        fputs(s, f);
        return;
    }
    fputc('"', f);
    for (; *s; s++) {
        if (*s == '"') fputc('"', f);
        fputc(*s, f);
    }
    fputc('"', f);
}

void jf_study_label(const jf_study *s, const jf_study_key *k, char *buf, size_t len)
{
    const char *fl = s->flags[k->flags];
    snprintf(buf, len, "%s d%d%s%s", s->strategy[k->strategy], s->degree[k->degree],
             fl[0] ? " " : "", fl);
}

static void put_row(FILE *f, const jf_study *s, const jf_study_cell *c)
{
    const jf_study_key *k = &c->key;
    put_str(f, s->strategy[k->strategy]);
    fprintf(f, ",%d,", s->degree[k->degree]);
    put_str(f, s->flags[k->flags]);
    fputc(',', f);
    put_num(f, s->noise[k->noise]);
    fputc(',', f);
    put_num(f, s->noise_u[k->noise_u]);
    fputc(',', f);
    put_num(f, s->outliers[k->outliers]);
    fprintf(f, ",%d,%llu,%zu,%zu", k->repeat, c->seed, c->points, c->normal_n);
    for (int m = 0; m < JF_M_COUNT; m++) {
        fputc(',', f);
        put_num(f, c->m[m]);
    }
    fprintf(f, ",%zu,%zu,%zu,%zu,", c->ok, c->lowered, c->failed, c->flagged);
    put_str(f, c->status);
    fputc(',', f);
    put_num(f, c->seconds);
    fputc(',', f);
    put_num(f, c->points_per_s);
    fputc('\n', f);
}

int jf_study_write_csv(const jf_study *s, const char *dir, char *msg, size_t len)
{
    jf_study_out o;
    if (jf_study_out_open(&o, dir, "study.csv", msg, len)) return -1;
    FILE *f = o.f;
    for (size_t j = 0; j < NKEY; j++) fprintf(f, "%s%s", j ? "," : "", head_key[j]);
    for (int m = 0; m < JF_M_COUNT; m++) fprintf(f, ",%s", jf_study_metric[m]);
    for (size_t j = 0; j < NTAIL; j++) fprintf(f, ",%s", head_tail[j]);
    fputc('\n', f);
    for (size_t i = 0; i < s->ncells; i++)
        if (s->cell[i].done) put_row(f, s, &s->cell[i]);
    return jf_study_out_commit(&o, msg, len);
}

/* ---- reading study.csv back (--resume) ---- */

/* Splits one CSV record of line (quotes undone in place) into at most
 * max fields; returns the count, or -1 on a stray quote. */
static int split_csv(char *line, char **fld, int max)
{
    int n = 0;
    char *p = line;
    for (;;) {
        if (n == max) return -1;
        char *w = p;
        fld[n++] = w;
        if (*p == '"') {
            p++;
            for (;;) {
                if (!*p) return -1;
                if (*p == '"') {
                    if (p[1] != '"') break;
                    p++;
                }
                *w++ = *p++;
            }
            p++;
            if (*p && *p != ',') return -1;
        } else {
            while (*p && *p != ',') *w++ = *p++;
        }
        int more = *p == ',';
        *w = '\0';
        if (!more) return n;
        p++;
    }
}

static int find_str(char **list, int n, const char *v)
{
    for (int i = 0; i < n; i++)
        if (!strcmp(list[i], v)) return i;
    return -1;
}

static int find_num(const double *list, int n, double v)
{
    for (int i = 0; i < n; i++)
        if (list[i] == v) return i;
    return -1;
}

static int num(const char *t, double *v)
{
    char *end;
    *v = strtod(t, &end);
    return end == t || *end ? -1 : 0;
}

int jf_study_read_csv(jf_study *s, const char *dir, char *msg, size_t len)
{
    char path[4096];
    jf_study_path(dir, "study.csv", path, sizeof path);
    FILE *f = fopen(path, "rb");
    if (!f) {
        if (errno == ENOENT) return 0;
        snprintf(msg, len, "%s: %s", path, strerror(errno));
        return -1;
    }
    /* a record never spans lines: the writer keeps fields on one line */
    char *line = NULL;
    size_t cap = 0, lineno = 0;
    int found = 0;
    ssize_t got;
    while ((got = getline(&line, &cap, f)) > 0) {
        lineno++;
        while (got && (line[got - 1] == '\n' || line[got - 1] == '\r')) line[--got] = '\0';
        char *fld[NCOL + 1];
        int n = split_csv(line, fld, NCOL + 1);
        if (lineno == 1) {
            int same = n == (int)NCOL;
            for (size_t j = 0; same && j < NKEY; j++) same = !strcmp(fld[j], head_key[j]);
            if (!same) {
                snprintf(msg, len, "%s:1: not a study table (header differs); move it away", path);
                found = -1;
                break;
            }
            continue;
        }
        double v[NCOL];
        if (n != (int)NCOL) {
            snprintf(msg, len, "%s:%zu: malformed row (%d fields, expected %zu)", path, lineno,
                     n, NCOL);
            found = -1;
            break;
        }
        /* every value as jetfit writes it: numbers, counts whole and not
         * negative, an ok cell's normal errors finite (a NaN there was not
         * written by jetfit: refused, naming the field and its column) */
        const size_t ST = NKEY + JF_M_COUNT + 4;
        const int ok_cell = !strcmp(fld[ST], "ok");
        int badcol = -1;
        const char *why = "";
        for (size_t j = 0; badcol < 0 && j < NCOL; j++) {
            if (j == 0 || j == 2 || j == ST) continue;
            const int whole = (j == 1 || (j >= 6 && j < NKEY) || (j >= NKEY + JF_M_COUNT && j < ST));
            if (num(fld[j], &v[j])) badcol = (int)j, why = "not a number";
            else if (whole && !(v[j] >= 0 && v[j] == floor(v[j]) && v[j] < 0x1p63))
                badcol = (int)j, why = "not a count";
            else if (ok_cell && j >= NKEY && j < NKEY + 3 && v[9] > 0 && !isfinite(v[j]))
                badcol = (int)j, why = "not finite in a finished cell";
        }
        if (badcol >= 0) {
            const char *name = (size_t)badcol < NKEY ? head_key[badcol]
                             : (size_t)badcol < NKEY + JF_M_COUNT ? jf_study_metric[badcol - (int)NKEY]
                             : head_tail[badcol - (int)(NKEY + JF_M_COUNT)];
            snprintf(msg, len, "%s:%zu: column %d (%s): '%s' is %s; move study.csv away or "
                     "run without --resume", path, lineno, badcol + 1, name, fld[badcol], why);
            found = -1;
            break;
        }
        unsigned long long seed = strtoull(fld[7], NULL, 10); /* > 2^53 too */
        jf_study_key k;
        k.strategy = find_str(s->strategy, s->nstrategy, fld[0]);
        k.degree = -1;
        for (int i = 0; i < s->ndegree; i++)
            if (s->degree[i] == v[1]) k.degree = i;
        k.flags = find_str(s->flags, s->nflags, fld[2]);
        k.noise = find_num(s->noise, s->nnoise, v[3]);
        k.noise_u = find_num(s->noise_u, s->nnoise_u, v[4]);
        k.outliers = find_num(s->outliers, s->noutliers, v[5]);
        k.repeat = (int)v[6];
        /* a row of another plan (other lists, seed or size) is dropped */
        for (size_t i = 0; i < s->ncells; i++) {
            jf_study_cell *c = &s->cell[i];
            if (memcmp(&c->key, &k, sizeof k) || c->done || c->seed != seed ||
                (double)c->points != v[8])
                continue;
            c->normal_n = (size_t)v[9];
            for (int m = 0; m < JF_M_COUNT; m++) c->m[m] = v[NKEY + (size_t)m];
            const double *t = v + NKEY + JF_M_COUNT;
            c->ok = (size_t)t[0];
            c->lowered = (size_t)t[1];
            c->failed = (size_t)t[2];
            c->flagged = (size_t)t[3];
            snprintf(c->status, sizeof c->status, "%s", fld[NKEY + JF_M_COUNT + 4]);
            c->seconds = t[5];
            c->points_per_s = t[6];
            c->done = 1;
            found++;
            break;
        }
    }
    free(line);
    fclose(f);
    return found;
}

/* ---- means over repeats, best.csv ---- */

int jf_study_setting(const jf_study *s, const jf_study_key *k)
{
    return (k->strategy * s->ndegree + k->degree) * s->nflags + k->flags;
}

size_t jf_study_cell_index(const jf_study *s, const jf_study_key *k)
{
    size_t lvl = ((size_t)k->noise * (size_t)s->nnoise_u + (size_t)k->noise_u) *
                     (size_t)s->noutliers + (size_t)k->outliers;
    size_t nset = (size_t)s->nstrategy * (size_t)s->ndegree * (size_t)s->nflags;
    return (lvl * (size_t)s->repeat + (size_t)k->repeat) * nset + (size_t)jf_study_setting(s, k);
}

void jf_study_mean(const jf_study *s, const jf_study_key *k, int metric, jf_study_stat *out)
{
    double sum = 0, sum2 = 0;
    int n = 0;
    jf_study_key q = *k;
    for (q.repeat = 0; q.repeat < s->repeat; q.repeat++) {
        const jf_study_cell *c = &s->cell[jf_study_cell_index(s, &q)];
        if (!c->done || !isfinite(c->m[metric])) continue;
        sum += c->m[metric];
        n++;
    }
    out->n = n;
    out->mean = n ? sum / n : NAN;
    for (q.repeat = 0; n > 1 && q.repeat < s->repeat; q.repeat++) {
        const jf_study_cell *c = &s->cell[jf_study_cell_index(s, &q)];
        if (!c->done || !isfinite(c->m[metric])) continue;
        sum2 += (c->m[metric] - out->mean) * (c->m[metric] - out->mean);
    }
    out->sd = n > 1 ? sqrt(sum2 / (n - 1)) : n ? 0.0 : NAN;
}

int jf_study_best(const jf_study *s, const jf_study_key *lvl, int metric, jf_study_key *best,
                  jf_study_stat *bs)
{
    int any = 0;
    jf_study_key k = *lvl;
    k.repeat = 0;
    for (k.strategy = 0; k.strategy < s->nstrategy; k.strategy++)
        for (k.degree = 0; k.degree < s->ndegree; k.degree++)
            for (k.flags = 0; k.flags < s->nflags; k.flags++) {
                jf_study_stat st;
                jf_study_mean(s, &k, metric, &st);
                if (st.n && (!any || st.mean < bs->mean)) {
                    *best = k;
                    *bs = st;
                    any = 1;
                }
            }
    return any;
}

int jf_study_write_best(const jf_study *s, const char *dir, char *msg, size_t len)
{
    jf_study_out o;
    if (jf_study_out_open(&o, dir, "best.csv", msg, len)) return -1;
    FILE *f = o.f;
    fputs("noise,noise_uniform,outliers,metric,strategy,degree,flags,mean,sd,repeats\n", f);
    jf_study_key lvl = {0};
    for (lvl.noise = 0; lvl.noise < s->nnoise; lvl.noise++)
        for (lvl.noise_u = 0; lvl.noise_u < s->nnoise_u; lvl.noise_u++)
            for (lvl.outliers = 0; lvl.outliers < s->noutliers; lvl.outliers++)
                for (int m = 0; m < JF_M_COUNT; m++) {
                    jf_study_key b;
                    jf_study_stat st;
                    if (!s->best[m] || !jf_study_best(s, &lvl, m, &b, &st)) continue;
                    put_num(f, s->noise[lvl.noise]);
                    fputc(',', f);
                    put_num(f, s->noise_u[lvl.noise_u]);
                    fputc(',', f);
                    put_num(f, s->outliers[lvl.outliers]);
                    fprintf(f, ",%s,", jf_study_metric[m]);
                    put_str(f, s->strategy[b.strategy]);
                    fprintf(f, ",%d,", s->degree[b.degree]);
                    put_str(f, s->flags[b.flags]);
                    fputc(',', f);
                    put_num(f, st.mean);
                    fputc(',', f);
                    put_num(f, st.sd);
                    fprintf(f, ",%d\n", st.n);
                }
    return jf_study_out_commit(&o, msg, len);
}

int jf_study_noise_axis(const jf_study *s)
{
    if (s->nnoise > 1) return 0;
    if (s->nnoise_u > 1) return 1;
    if (s->noutliers > 1) return 2;
    return 0;
}

/* study_def.c -- DIR/study.def: what defines a study, so that --resume
 * keeps only cells of the study the command line describes (issue 32.3).
 * One "key: value" line each: the input (a SURFACE with --n and --mesh, or
 * INPUT's size and FNV-1a 64 content hash), the truth and the subset
 * (likewise), and every estimate option outside the lists (--threads left
 * out: results do not depend on it).  The lists themselves (--neighbors,
 * --degree, --flags, noise levels, --repeat, --seed) are the cells' own
 * keys in study.csv: a changed list keeps the cells it shares. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "study_args.h"

int jf_study_def_identity(const char *path, char *out, size_t len, char *msg, size_t mlen)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(msg, mlen, "%s: %s", path, strerror(errno));
        return -1;
    }
    uint64_t h = 1469598103934665603ull, size = 0; /* FNV-1a 64 offset basis */
    unsigned char buf[65536];
    size_t k;
    while ((k = fread(buf, 1, sizeof buf, f)) > 0) {
        for (size_t i = 0; i < k; i++) h = (h ^ buf[i]) * 1099511628211ull;
        size += k;
    }
    int bad = ferror(f);
    fclose(f);
    if (bad) {
        snprintf(msg, mlen, "%s: read error", path);
        return -1;
    }
    snprintf(out, len, "%llu bytes, fnv1a64 %016llx", (unsigned long long)size,
             (unsigned long long)h);
    return 0;
}

int jf_study_def_make(const jf_study_args *c, char *def, size_t len, char *msg, size_t mlen)
{
    const jf_study *s = &c->s;
    char id[128];
    size_t u = 0;
    if (c->is_surface) {
        u += (size_t)snprintf(def + u, len - u, "surface: %s\nn: %zu\nmesh: %s\n", s->input,
                              c->npoints, c->mesh ? "yes" : "no");
    } else {
        /* taken by cmd_study.c while INPUT was read (standard input is
         * read once): the content, so a file and the same bytes piped in
         * are one study */
        u += (size_t)snprintf(def + u, len - u, "input: %s\n", c->input_id);
        if (s->truth) {
            if (jf_study_def_identity(s->truth, id, sizeof id, msg, mlen)) return -1;
            u += (size_t)snprintf(def + u, len - u, "truth: %s\n", id);
        }
    }
    if (s->subset) {
        if (u >= len || jf_study_def_identity(s->subset, id, sizeof id, msg, mlen)) return -1;
        u += (size_t)snprintf(def + u, len - u, "subset: %s\n", id);
    }
    if (u >= len) return -1;
    snprintf(def + u, len - u, "options: %s\n", c->base_text[0] ? c->base_text : "(none)");
    return 0;
}

int jf_study_def_write(const char *dir, const char *def, char *msg, size_t len)
{
    jf_study_out o;
    if (jf_study_out_open(&o, dir, "study.def", msg, len)) return -1;
    fputs(def, o.f);
    return jf_study_out_commit(&o, msg, len);
}

/* The value of `key` in a study.def text ("" if absent), into out. */
static void value_of(const char *def, const char *key, char *out, size_t len)
{
    size_t kl = strlen(key);
    out[0] = '\0';
    for (const char *p = def; p && *p; p = strchr(p, '\n') ? strchr(p, '\n') + 1 : NULL)
        if (!strncmp(p, key, kl) && p[kl] == ':' && p[kl + 1] == ' ') {
            const char *v = p + kl + 2, *e = strchr(v, '\n');
            size_t n = e ? (size_t)(e - v) : strlen(v);
            if (n >= len) n = len - 1;
            memcpy(out, v, n);
            out[n] = '\0';
            return;
        }
}

int jf_study_def_check(const char *dir, const char *def, char *msg, size_t len)
{
    char path[4096], old[8192];
    jf_study_path(dir, "study.def", path, sizeof path);
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(msg, len, "%s: %s: --resume cannot tell which study %s/study.csv belongs "
                 "to; run without --resume (or another -o folder)", path, strerror(errno), dir);
        return -1;
    }
    size_t n = fread(old, 1, sizeof old - 1, f);
    fclose(f);
    old[n] = '\0';
    static const char *const keys[] = {"surface", "n", "mesh", "input", "truth", "subset",
                                       "options"};
    for (size_t k = 0; k < sizeof keys / sizeof keys[0]; k++) {
        char a[2048], b[2048];
        value_of(old, keys[k], a, sizeof a);
        value_of(def, keys[k], b, sizeof b);
        if (strcmp(a, b)) {
            snprintf(msg, len, "%s/study.csv is another study: %s was '%s', is now '%s'; "
                     "run without --resume (or another -o folder)", dir, keys[k],
                     a[0] ? a : "(none)", b[0] ? b : "(none)");
            return -1;
        }
    }
    return 0;
}

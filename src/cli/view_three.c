/* view_three.c -- the three.js the page inlines: read at run time from
 * Debian's libjs-three (the project ships no copy), so the build tree and
 * an install use the same files and `jetfit --version` names its release. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "view.h"

#ifndef JF_THREE_DIR
#define JF_THREE_DIR "/usr/share/javascript/three"
#endif

/* The whole file, NUL-terminated; NULL when it cannot be read. */
static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    size_t cap = 1 << 20, n = 0;
    char *b = malloc(cap + 1);
    while (b) {
        n += fread(b + n, 1, cap - n, f);
        if (n < cap) break;
        char *nb = realloc(b, 2 * cap + 1);
        if (!nb) { free(b); b = NULL; break; }
        b = nb;
        cap *= 2;
    }
    int err = ferror(f);
    fclose(f);
    if (!b || err) { free(b); return NULL; }
    b[n] = 0;
    return b;
}

static const char *three_dir(void)
{
    const char *d = getenv("JETFIT_THREE_DIR");
    return d && *d ? d : JF_THREE_DIR;
}

/* three.js r111's minified build sets REVISION="111". */
static void revision(const char *lib, char *out, size_t len)
{
    const char *p = strstr(lib, "REVISION=\"");
    size_t k = 0;
    if (p)
        for (p += 10; *p && *p != '"' && k + 1 < len && k < 12; p++)
            if ((*p >= '0' && *p <= '9') || (*p >= 'a' && *p <= 'z')) out[k++] = *p;
    out[k] = 0;
    if (!k) snprintf(out, len, "?");
}

int jf_view_three_load(jf_view_three *t, char *why, size_t len)
{
    memset(t, 0, sizeof *t);
    snprintf(t->dir, sizeof t->dir, "%s", three_dir());
    char path[4200];
    snprintf(path, sizeof path, "%s/three.min.js", t->dir);
    t->lib = slurp(path);
    if (!t->lib) {
        snprintf(why, len, "%s: cannot read three.js (Debian: apt-get install libjs-three; "
                 "or set JETFIT_THREE_DIR)", path);
        return -1;
    }
    snprintf(path, sizeof path, "%s/examples/js/controls/OrbitControls.js", t->dir);
    t->controls = slurp(path);
    if (!t->controls) {
        snprintf(why, len, "%s: cannot read three.js's OrbitControls (libjs-three)", path);
        jf_view_three_free(t);
        return -1;
    }
    revision(t->lib, t->revision, sizeof t->revision);
    return 0;
}

void jf_view_three_free(jf_view_three *t)
{
    free(t->lib);
    free(t->controls);
    t->lib = t->controls = NULL;
}

void jf_view_three_describe(char *buf, size_t len)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/three.min.js", three_dir());
    char *lib = slurp(path);
    if (!lib) {
        snprintf(buf, len, "three.js not found in %s (jetfit view needs libjs-three)",
                 three_dir());
        return;
    }
    char rev[16];
    revision(lib, rev, sizeof rev);
    free(lib);
    snprintf(buf, len, "three.js r%s (%s)", rev, three_dir());
}

/* status.c -- version, status names, per-point flag names. */
#include <stdio.h>
#include <string.h>

#include "jetfit.h"

const char *jf_version(void) { return JF_VERSION_STRING; }

const char *jf_strerror(jf_status s)
{
    switch (s) {
    case JF_OK: return "success";
    case JF_ERR_INVALID: return "invalid argument";
    case JF_ERR_NOMEM: return "out of memory";
    case JF_ERR_IO: return "input/output error";
    case JF_ERR_FORMAT: return "malformed or unsupported file";
    case JF_ERR_TOO_LARGE: return "too large";
    case JF_ERR_NUMERIC: return "numerical failure";
    case JF_ERR_UNSUPPORTED: return "not supported by this build";
    case JF_ERR_INTERNAL: return "internal error";
    case JF_ERR_CANCELLED: return "cancelled";
    }
    return "unknown status";
}

static const char *const flag_names[] = {
    "lowered_cond", "lowered_rank", "lowered_few", "umbilic",
    "failed", "nonfinite", "few_neighbors", "normal_poles",
    "normal_mincirc", "normal_fallback", "robust_noconv", "orient_unknown",
    "normal_input", "scale_selected", "mesh_nonmanifold", "normal_jet",
    "normal_pca", "auto", "auto_capped", "auto_weighted",
    "auto_spread",
};

char *jf_point_status_str(unsigned status, char *buf, size_t len)
{
    size_t used = 0;
    if (!buf || !len) return buf;
    buf[0] = '\0';
    if (status == 0) {
        snprintf(buf, len, "ok");
        return buf;
    }
    for (unsigned b = 0; b < sizeof flag_names / sizeof flag_names[0]; b++) {
        if (!(status & (1u << b))) continue;
        int w = snprintf(buf + used, len - used, "%s%s", used ? "|" : "", flag_names[b]);
        if (w < 0 || (size_t)w >= len - used) break;
        used += (size_t)w;
    }
    return buf;
}

char *jf_auto_step0_str(int chosen, char *buf, size_t len)
{
    static const struct {
        int flag;
        const char *what;
    } fl[] = {{JF_AUTO_CUBIC_MIN48, "no cubic below K = 48"},
              {JF_AUTO_WEIGHTED_MEAN, "step 6: every row's weighted mean"},
              {JF_AUTO_SPREAD_CARRY, "step 6: the spread carry"},
              {JF_AUTO_CAPPED_WEIGHTED, "capped rows: the weighted mean, K at least 32"}};
    if (!buf || !len) return buf;
    const int cap = chosen & ~JF_AUTO_FLAGS;
    /* a cap at the largest K caps nothing (auto.c: no candidate above it) */
    int w = cap > 1 && cap < JF_NB_AUTO_KMAX ? snprintf(buf, len, "K capped at %d", cap)
                                             : snprintf(buf, len, "no cap on K");
    size_t at = 0;
    for (size_t i = 0; i < sizeof fl / sizeof *fl; i++) {
        if (w < 0 || (size_t)w >= len - at) break; /* full: cut */
        at += (size_t)w;
        w = chosen & fl[i].flag ? snprintf(buf + at, len - at, "; %s", fl[i].what) : 0;
    }
    return buf;
}

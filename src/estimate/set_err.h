/* set_err.h -- the estimate's one way to fill a jf_error (not part of
 * the public API). */
#ifndef JF_SET_ERR_H
#define JF_SET_ERR_H

#include <stdio.h>

#include "jetfit.h"

/* msg into err (NULL: no message wanted) */
static inline void jf__set_err(jf_error *err, const char *msg)
{
    if (err) snprintf(err->msg, sizeof err->msg, "%s", msg);
}

#endif /* JF_SET_ERR_H */

/* none.c -- the bridge of a build without CGAL (-DJF_CGAL=OFF): the same C
 * ABI (cgal_bridge.h), where what needs a 3D Delaunay triangulation (the
 * Voronoi poles and the minimum-circumradius normal of natural
 * neighbourhoods, docs/design.md "What CGAL is used for") reports that it
 * is not built in.  Everything else of libjetfit works without it. */
#include <string.h>

#include "cgal_bridge.h"

const char *jfb_cgal_version(void) { return NULL; }

int jfb_delaunay_build(const double *xyz, size_t n, int threads, jfb_delaunay *out)
{
    (void)xyz, (void)n, (void)threads;
    if (out) memset(out, 0, sizeof *out);
    return 7; /* JF_ERR_UNSUPPORTED */
}

void jfb_delaunay_release(jfb_delaunay *d)
{
    if (d) memset(d, 0, sizeof *d);
}

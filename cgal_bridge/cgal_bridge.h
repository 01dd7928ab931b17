/* cgal_bridge.h -- the C ABI of the CGAL bridge (C++17 inside).  Opaque
 * handles, plain arrays, integer status codes (jf_status values); every
 * entry point catches every exception.  No C++ type crosses. */
#ifndef JF_CGAL_BRIDGE_H
#define JF_CGAL_BRIDGE_H
#ifdef __cplusplus
extern "C" {
#endif

/* CGAL version the bridge was built with, e.g. "5.5.1". */
const char *jfb_cgal_version(void);

#ifdef __cplusplus
}
#endif
#endif

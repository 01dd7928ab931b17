// version.cpp -- which CGAL the bridge was built with.
#include <CGAL/version.h>

#include "cgal_bridge.h"

extern "C" const char *jfb_cgal_version(void) { return CGAL_VERSION_STR; }

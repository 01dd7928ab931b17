/* bigalloc.h -- jf__big_alloc (bigalloc.c): malloc of a large buffer about
 * to be written whole, asked (on Linux) to be backed by huge pages; free()
 * frees it.  In core: the readers (io/) and the k-d tree (spatial/) use it. */
#ifndef JF_BIGALLOC_H
#define JF_BIGALLOC_H
#include <stddef.h>

void *jf__big_alloc(size_t bytes);
#endif

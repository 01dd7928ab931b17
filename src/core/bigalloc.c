/*
 * bigalloc.c -- the large buffers filled whole (a read's records and
 * coordinates, the k-d tree's copy of the points), asked for huge pages.
 *
 * design: a fresh malloc'ed buffer of many MiB comes from mmap and takes a
 * page fault every 4 KiB on first write; on a virtual machine such a fault
 * costs about as much as decoding a LAZ point (a third of a LAZ read's CPU
 * time on the 2-core test machine, docs/benchmarks.md).  Linux's
 * madvise(MADV_HUGEPAGE) lets transparent huge pages (in "madvise" mode,
 * Debian's default) back it with 2 MiB pages: one fault per 512.  A hint:
 * where it is refused or missing, the buffer is an ordinary one.
 */
#define _DEFAULT_SOURCE /* MADV_HUGEPAGE */
#include <stdint.h>
#include <stdlib.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "bigalloc.h"

void *jf__big_alloc(size_t bytes)
{
    void *p = malloc(bytes);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    uintptr_t a = ((uintptr_t)p + 4095) & ~(uintptr_t)4095; /* whole pages inside */
    uintptr_t e = ((uintptr_t)p + bytes) & ~(uintptr_t)4095;
    if (p && bytes >= ((size_t)4 << 20) && e > a)
        (void)madvise((void *)a, e - a, MADV_HUGEPAGE);
#endif
    return p;
}

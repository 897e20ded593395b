/* Allocation whose result is always checked: out of memory, the simulator
 * says what failed and exits, rather than write through a null pointer
 * later, somewhere else.  Zero bytes are asked for as one, so that a
 * lab with no robots or boxes gets a real pointer. */
#ifndef ALLOC_H
#define ALLOC_H
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static inline void *alloc_checked(void *p)
{
    if (!p) {
        fputs("b14: ERROR: out of memory\n", stderr);
        exit(1);
    }
    return p;
}

static inline void *xmalloc(size_t n) { return alloc_checked(malloc(n ? n : 1)); }
static inline void *xcalloc(size_t n, size_t size)
{
    return alloc_checked(calloc(n ? n : 1, size ? size : 1));
}
static inline void *xrealloc(void *p, size_t n) { return alloc_checked(realloc(p, n ? n : 1)); }
static inline char *xstrdup(const char *s) { return alloc_checked(strdup(s)); }
static inline char *xstrndup(const char *s, size_t n) { return alloc_checked(strndup(s, n)); }
#endif

/* A minimal test harness: each CHECK is one test case; main ends with
 * check_summary(), which prints "N passed, N failed" for the Makefile to add
 * up and returns the exit status. */
#ifndef CHECK_H
#define CHECK_H
#include <stdio.h>

static int check_passed, check_failed;

#define CHECK(name, cond) do { \
        if (cond) { check_passed++; } \
        else { check_failed++; \
               fprintf(stderr, "FAIL %s (%s:%d): %s\n", \
                       name, __FILE__, __LINE__, #cond); } \
    } while (0)

static int check_summary(void)
{
    printf("%d passed, %d failed\n", check_passed, check_failed);
    return check_failed != 0;
}
#endif

/* test_main.c: runs the unit tests (TEST and TEST_SLOW in tests/unit/test.h).
 *   unit_tests [--tier fast|slow|all] [--list] [PATTERN...]
 * runs the tests of the tier (default all: fast and slow) whose "suite.name" contains any
 * PATTERN (all without one; a PATTERN starting with ^ must match at the start: ^path. is the
 * path suite). --list prints the names it would run, with their tier, and runs nothing.
 * Each test's time is measured; one over the budget (TEST_BUDGET_S) prints a note with its
 * time. Prints "unit: N passed, N failed, N skipped (T s)" at the end; exit 1 on any failure. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "test.h"

/* A test of the fast tier (make test) should take at most this long: tests/README.md. */
#define TEST_BUDGET_S 10.0

int test_failures;
int test_checks;
static int skipped_flag;

void test_skip(const char *why)
{
    if (!skipped_flag)
        printf("    skipped: %s\n", why);
    skipped_flag = 1;
}

const char *test_assets_dir(void)
{
    static char path[4096];
    struct stat st;
    const char *env = getenv("GONIO_ASSETS");
    snprintf(path, sizeof path, "%s", env && *env ? env : "../shared/assets");
    if (stat(path, &st) != 0 || !S_ISDIR(st.st_mode))
        return NULL;
    return path;
}

#define MAX_TESTS 512

typedef struct test_case {
    char name[96]; /* "suite.name" */
    test_fn fn;
    const char *file;
    int line;
    bool slow;
} test_case;

static test_case tests[MAX_TESTS];
static int num_tests;

void test_register(const char *suite, const char *name, test_fn fn, const char *file, int line, bool slow)
{
    if (num_tests == MAX_TESTS) {
        fprintf(stderr, "test_main.c: more than %d tests: raise MAX_TESTS\n", MAX_TESTS);
        exit(1);
    }
    test_case *t = &tests[num_tests++];
    snprintf(t->name, sizeof t->name, "%s.%s", suite, name);
    t->fn = fn;
    t->file = file;
    t->line = line;
    t->slow = slow;
}

/* By file, then line: the order does not depend on the linker's. */
static int by_place(const void *pa, const void *pb)
{
    const test_case *a = pa, *b = pb;
    int c = strcmp(a->file, b->file);
    return c ? c : a->line - b->line;
}

static double seconds(clockid_t clock)
{
    struct timespec ts;
    clock_gettime(clock, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
static double now(void) { return seconds(CLOCK_MONOTONIC); }
/* CPU time of the process, lavapipe's threads included */
static double cpu_now(void) { return seconds(CLOCK_PROCESS_CPUTIME_ID); }

static bool matches(const char *name, const char *pattern)
{
    if (pattern[0] == '^')
        return strncmp(name, pattern + 1, strlen(pattern + 1)) == 0;
    return strstr(name, pattern) != NULL;
}

static int usage(void)
{
    fprintf(stderr, "usage: unit_tests [--tier fast|slow|all] [--list] [PATTERN...]\n");
    return 2;
}

int main(int argc, char **argv)
{
    int passed = 0, failed = 0, skipped = 0, npat = 0;
    bool want_fast = true, want_slow = true, list = false;
    const char **patterns = calloc((size_t)argc, sizeof *patterns);
    double start = now();
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--list")) {
            list = true;
        } else if (!strcmp(argv[i], "--tier") && i + 1 < argc) {
            const char *t = argv[++i];
            if (!strcmp(t, "fast") || !strcmp(t, "slow") || !strcmp(t, "all")) {
                want_fast = strcmp(t, "slow") != 0;
                want_slow = strcmp(t, "fast") != 0;
            } else {
                return usage();
            }
        } else if (argv[i][0] == '-') {
            return usage();
        } else {
            patterns[npat++] = argv[i];
        }
    }
    qsort(tests, (size_t)num_tests, sizeof *tests, by_place);
    for (int i = 0; i < num_tests; i++) {
        int before, k;
        double t0, dt, c0;
        if (!(tests[i].slow ? want_slow : want_fast))
            continue;
        for (k = 0; k < npat && !matches(tests[i].name, patterns[k]); k++)
            ;
        if (npat && k == npat)
            continue;
        if (list) {
            printf("%s %s\n", tests[i].name, tests[i].slow ? "slow" : "fast");
            continue;
        }
        before = test_failures;
        skipped_flag = 0;
        printf("  %s\n", tests[i].name);
        fflush(stdout);
        t0 = now();
        c0 = cpu_now();
        tests[i].fn();
        dt = now() - t0;
        if (dt > TEST_BUDGET_S)
            printf("    note: %s took %.1f s (CPU %.1f s), over the %.0f s budget of a test (tests/README.md)%s\n",
                   tests[i].name, dt, cpu_now() - c0, TEST_BUDGET_S, tests[i].slow ? "; it is in the slow tier" : "");
        if (test_failures != before) {
            failed++;
            printf("    FAILED\n");
        } else if (skipped_flag) {
            skipped++;
        } else {
            passed++;
        }
        fflush(stdout);
    }
    free(patterns);
    if (!list)
        printf("unit: %d passed, %d failed, %d skipped (%.1f s)\n", passed, failed, skipped, now() - start);
    return failed ? 1 : 0;
}

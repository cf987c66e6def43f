/* test_main.c: runs every unit test (TEST in tests/unit/test.h), or those whose
 * "suite.name" contains argv[1]. Prints "N passed, N failed, N skipped" at the end; exit 1 on any failure. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "test.h"

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
} test_case;

static test_case tests[MAX_TESTS];
static int num_tests;

void test_register(const char *suite, const char *name, test_fn fn, const char *file, int line)
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
}

/* By file, then line: the order does not depend on the linker's. */
static int by_place(const void *pa, const void *pb)
{
    const test_case *a = pa, *b = pb;
    int c = strcmp(a->file, b->file);
    return c ? c : a->line - b->line;
}

int main(int argc, char **argv)
{
    int passed = 0, failed = 0, skipped = 0;
    qsort(tests, (size_t)num_tests, sizeof *tests, by_place);
    for (int i = 0; i < num_tests; i++) {
        int before;
        if (argc > 1 && !strstr(tests[i].name, argv[1]))
            continue;
        before = test_failures;
        skipped_flag = 0;
        printf("  %s\n", tests[i].name);
        fflush(stdout);
        tests[i].fn();
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
    printf("unit: %d passed, %d failed, %d skipped\n", passed, failed, skipped);
    return failed ? 1 : 0;
}

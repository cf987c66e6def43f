/* test_main.c: runs every unit test listed in suites.h, or those whose "suite.name" contains
 * argv[1]. Prints "N passed, N failed, N skipped" at the end; exit 1 on any failure. */
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

/* SUITES_FILE lets a module be built and tested alone: -DSUITES_FILE='"suite_bvh.h"' */
#ifndef SUITES_FILE
#define SUITES_FILE "suites.h"
#endif

#define TEST(suite, name) void test_##suite##_##name(void);
#include SUITES_FILE
#undef TEST

static const struct {
    const char *name;
    test_fn fn;
} tests[] = {
#define TEST(suite, name) {#suite "." #name, test_##suite##_##name},
#include SUITES_FILE
#undef TEST
    {NULL, NULL}};

int main(int argc, char **argv)
{
    int passed = 0, failed = 0, skipped = 0;
    for (int i = 0; tests[i].name; i++) {
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

/* test.h: the unit-test harness. Tests are plain functions; CHECK never compiles out. */
#ifndef GONIO_TEST_H
#define GONIO_TEST_H

#include <stdbool.h>
#include <stdio.h>

extern int test_failures;
extern int test_checks;

#define CHECK(cond)                                                                   \
    do {                                                                              \
        test_checks++;                                                                \
        if (!(cond)) {                                                                \
            test_failures++;                                                          \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond);  \
        }                                                                             \
    } while (0)

#define CHECKF(cond, ...)                                                             \
    do {                                                                              \
        test_checks++;                                                                \
        if (!(cond)) {                                                                \
            test_failures++;                                                          \
            fprintf(stderr, "%s:%d: CHECK failed: %s: ", __FILE__, __LINE__, #cond);  \
            fprintf(stderr, __VA_ARGS__);                                             \
            fputc('\n', stderr);                                                      \
        }                                                                             \
    } while (0)

/* Marks the running test skipped (with a reason printed once). */
void test_skip(const char *why);

/* Directory of the third-party test assets ($GONIO_ASSETS, which tests/run.sh sets; the
 * fallback is test_main.c's); NULL when absent, in which case tests that need it call test_skip. */
const char *test_assets_dir(void);

/* The Vulkan device for GPU tests (validation on when GONIO_VALIDATE=1); a failed CHECK
 * and false when there is none. Defined in test_gpu.c. */
struct gpu;
bool test_open_gpu(struct gpu *g);

/* TEST(suite, name) { ... } defines a test and registers it (a constructor runs before
 * main), so a test is written in one place: tests/unit/test_SUITE.c. They run in the order
 * of their files' names, and in a file in the order they are written. TEST_SLOW is the
 * same for a test of the slow tier (make test-full; tests/README.md): one that cannot be
 * made to fit the fast tier's budget of 10 s. */
typedef void (*test_fn)(void);
void test_register(const char *suite, const char *name, test_fn fn, const char *file, int line, bool slow);
#define TEST_TIER(suite, name, slow)                                                       \
    static void test_##suite##_##name(void);                                               \
    __attribute__((constructor)) static void test_register_##suite##_##name(void)          \
    {                                                                                      \
        test_register(#suite, #name, test_##suite##_##name, __FILE__, __LINE__, slow);     \
    }                                                                                      \
    static void test_##suite##_##name(void)
#define TEST(suite, name) TEST_TIER(suite, name, false)
#define TEST_SLOW(suite, name) TEST_TIER(suite, name, true)

#endif

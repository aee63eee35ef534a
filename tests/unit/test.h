/* test.h: a tiny unit-test harness (in the spirit of Box2D's test macros).
 *
 *   TEST(name) { CHECK(cond); CHECK_NEAR(a, b, tol); REQUIRE(cond); }
 *
 * A test is a function test_<name>(void); main.c lists every test in one table
 * (TEST_LIST) and runs them in order. Output is TAP-like:
 *   ok N - name / not ok N - name, with "#   file:line: ..." diagnostics for each
 * failed check, and as the very last line exactly "N passed, N failed". The exit
 * status is 1 when any test failed. */
#ifndef WB_TEST_H
#define WB_TEST_H

#include <math.h>
#include <stdio.h>
#include <string.h>

typedef struct test_case {
    const char *name;
    void (*fn)(void);
} test_case;

/* failed checks in the running test (main.c owns it) */
extern int test_failures;
void test_fail(const char *file, int line, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

#define TEST(name) void test_##name(void)

/* record a failure and go on */
#define CHECK(cond)                                                                 \
    do {                                                                            \
        if (!(cond)) test_fail(__FILE__, __LINE__, "CHECK(%s) failed", #cond);      \
    } while (0)

/* |a - b| <= tol; values printed with %.17g so the failure is reproducible */
#define CHECK_NEAR(a, b, tol)                                                       \
    do {                                                                            \
        const double a_ = (double)(a), b_ = (double)(b), t_ = (double)(tol);        \
        if (!(fabs(a_ - b_) <= t_))                                                 \
            test_fail(__FILE__, __LINE__,                                           \
                      "CHECK_NEAR(%s, %s, %s) failed: %.17g vs %.17g, |diff| %.17g > %.17g", \
                      #a, #b, #tol, a_, b_, fabs(a_ - b_), t_);                     \
    } while (0)

/* integers compared exactly, both printed */
#define CHECK_EQ(a, b)                                                              \
    do {                                                                            \
        const long long a_ = (long long)(a), b_ = (long long)(b);                   \
        if (a_ != b_)                                                               \
            test_fail(__FILE__, __LINE__, "CHECK_EQ(%s, %s) failed: %lld vs %lld",  \
                      #a, #b, a_, b_);                                              \
    } while (0)

/* a vector path's switch (wb__*_simd(1)) turned it on wherever the build and the CPU
 * have AVX2: the bit-identity tests then really compare it with the scalar loop */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(WB_FLOAT)
#define CHECK_SIMD_RUNS(on)                                                         \
    do {                                                                            \
        __builtin_cpu_init();                                                       \
        CHECK_EQ((on), __builtin_cpu_supports("avx2") ? 1 : 0);                     \
    } while (0)
#else
#define CHECK_SIMD_RUNS(on) CHECK_EQ((on), 0)
#endif

/* the string s (may be NULL) contains sub */
#define CHECK_HAS(s, sub)                                                           \
    do {                                                                            \
        const char *s_ = (s);                                                       \
        if (!s_ || !strstr(s_, (sub)))                                              \
            test_fail(__FILE__, __LINE__, "CHECK_HAS(%s, \"%s\") failed: got \"%s\"", \
                      #s, (sub), s_ ? s_ : "(null)");                               \
    } while (0)

/* record a failure and leave the test (the rest would crash or mean nothing) */
#define REQUIRE(cond)                                                               \
    do {                                                                            \
        if (!(cond)) {                                                              \
            test_fail(__FILE__, __LINE__, "REQUIRE(%s) failed", #cond);             \
            return;                                                                 \
        }                                                                           \
    } while (0)

#endif

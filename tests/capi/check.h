/* Checks for the C API's C11 test programs (no test framework: these are what a C host compiles). */
#ifndef SPLATFX_TESTS_CAPI_CHECK_H
#define SPLATFX_TESTS_CAPI_CHECK_H

#include <stdio.h>
#include <string.h>

#include <splatfx/splatfx_c.h>

/* The ABI the header promises: its enums are 32-bit. */
_Static_assert(sizeof(splatfx_status) == sizeof(int32_t), "splatfx_status is 32-bit");
_Static_assert(sizeof(splatfx_easing) == sizeof(int32_t), "splatfx_easing is 32-bit");

/* Failed checks so far; main returns nonzero when any failed. */
static int g_failures = 0; /* test-program state, not SDK state */

#define CHECK(cond, ...)                                                                                                                             \
    do {                                                                                                                                             \
        if (!(cond)) {                                                                                                                               \
            ++g_failures;                                                                                                                            \
            fprintf(stderr, "%s:%d: CHECK(%s) failed: ", __FILE__, __LINE__, #cond);                                                                 \
            fprintf(stderr, __VA_ARGS__);                                                                                                            \
            fprintf(stderr, "\n");                                                                                                                   \
        }                                                                                                                                            \
    } while (0)

/* A call must succeed; on failure prints the error object's message. */
#define CHECK_OK(call, err)                                                                                                                          \
    do {                                                                                                                                             \
        splatfx_status s_ = (call);                                                                                                                  \
        CHECK(s_ == SPLATFX_OK, "%s returned %s: %s", #call, splatfx_status_name(s_), splatfx_error_message(err));                                   \
        CHECK(splatfx_error_status(err) == s_, "the error object's status is not the returned one");                                                 \
    } while (0)

/* A call must fail with `want`, the error object must say so, and its message must contain `needle`. */
#define CHECK_FAILS(call, err, want, needle)                                                                                                         \
    do {                                                                                                                                             \
        splatfx_status s_ = (call);                                                                                                                  \
        CHECK(s_ == (want), "%s returned %s, expected %s (message: %s)", #call, splatfx_status_name(s_), splatfx_status_name(want),                  \
              splatfx_error_message(err));                                                                                                           \
        CHECK(splatfx_error_status(err) == s_, "the error object's status is not the returned one");                                                 \
        CHECK(strstr(splatfx_error_message(err), (needle)) != NULL, "%s: message \"%s\" lacks \"%s\"", #call, splatfx_error_message(err), (needle)); \
    } while (0)

#endif

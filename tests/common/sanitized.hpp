// Counts for the sanitized suite. tools/sanitize.sh runs every test again under ASan + UBSan,
// where numeric code runs 10 to 25 times slower than in the Release build. A test whose cost is
// a count of repeats of the same code (mutated inputs, animation frames, probes) asks for a
// smaller count there: the sanitizers need each code path once, the Release run keeps the full
// count, and the assertions are the same in both.
#pragma once

namespace splatfx::test {

#if defined(SPLATFX_TEST_SANITIZED)
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif

// `full` in the Release build, `sanitized` in the instrumented one.
constexpr int count(int full, int sanitized) { return kSanitized ? sanitized : full; }

} // namespace splatfx::test

// tools/common/cli.hpp: the command-line boundary shared by every tool.
//
// What it is: strict number parsing (the whole string, range-checked, no
// silent wrap-around), a "WxH" size parser, an "A-B[:STEP]" frame-range
// parser (render-farm tasks), and a guard for main() that turns any escaping
// std::exception (std::bad_alloc included) into a message and a non-zero
// exit instead of std::terminate's abort.
// What it does not do: option tables, usage text or argv walking (CLI11 does,
// through tools/common/options.hpp, whose options call these parsers),
// locale handling (numbers are C-locale: '.' is the decimal point).
//
//   long n = 0;
//   if (auto s = cli::parseInt("--frames", text, 1, 100000, n); !s) return fail(s.error());
//   int main(int argc, char** argv) { return cli::guardedMain("splatfx-bench", [&] { return run(argc, argv); }); }
//
// Threading: pure functions; no shared state.
#pragma once

#include <cerrno>
#include <charconv>
#include <cmath>
#include <concepts>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <limits>
#include <new>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>

#include "splatfx/result.hpp"

namespace cli {

namespace detail {
// Built by appends: GCC 12's -Wrestrict misfires on "'" + std::string(...).
inline std::string quoted(std::string_view text) {
    std::string q;
    q.reserve(text.size() + 2);
    q.push_back('\'');
    q.append(text);
    q.push_back('\'');
    return q;
}

template <class T>
std::string show(T v) {
    if constexpr (std::is_floating_point_v<T>) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%g", double(v));
        return buf;
    } else {
        return std::to_string(v);
    }
}
} // namespace detail

// An integer: optional sign and decimal digits filling the whole text, within
// [lo, hi]. "12abc", "", " 12", "0x10", "1e3" and anything that would not fit
// in T are errors naming the option, the range and the text.
template <std::integral T>
splatfx::Status parseInt(std::string_view option, std::string_view text, std::type_identity_t<T> lo, std::type_identity_t<T> hi, T& out) {
    auto bad = [&](const char* why) {
        return splatfx::makeError(std::string(option) + " expects a whole number in [" + detail::show(lo) + ", " + detail::show(hi) + "], got " +
                                  detail::quoted(text) + why);
    };
    std::string_view digits = text;
    if (!digits.empty() && digits.front() == '+') digits.remove_prefix(1); // from_chars accepts '-' only
    if (digits.empty() || digits.front() == '+' || digits.front() == ' ') return bad("");
    // Parse as the widest type of the same signedness so that "out of T's
    // range" and "out of [lo, hi]" give the same message, and a value past
    // even that is reported as too large rather than wrapped.
    using Wide = std::conditional_t<std::is_signed_v<T>, long long, unsigned long long>;
    Wide v{};
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), v, 10);
    if (ec == std::errc::result_out_of_range) return bad(" (far out of range)");
    if (ec != std::errc() || end != digits.data() + digits.size()) return bad("");
    if (v < Wide(lo) || v > Wide(hi)) return bad("");
    out = T(v);
    return {};
}

// A finite floating-point number filling the whole text, within [lo, hi].
// "nan", "inf", "1e999" and "0.5x" are errors.
template <std::floating_point T>
splatfx::Status parseReal(std::string_view option, std::string_view text, std::type_identity_t<T> lo, std::type_identity_t<T> hi, T& out) {
    auto bad = [&]() {
        return splatfx::makeError(std::string(option) + " expects a number in [" + detail::show(lo) + ", " + detail::show(hi) + "], got " +
                                  detail::quoted(text));
    };
    std::string_view digits = text;
    if (!digits.empty() && digits.front() == '+') digits.remove_prefix(1);
    if (digits.empty() || digits.front() == '+' || digits.front() == ' ') return bad();
    double v = 0.0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), v, std::chars_format::general);
    if (ec != std::errc() || end != digits.data() + digits.size() || !std::isfinite(v)) return bad();
    if (!(v >= double(lo) && v <= double(hi))) return bad();
    out = T(v);
    return {};
}

// "WxH" with both sides whole numbers in [lo, hi] (e.g. "640x480").
inline splatfx::Status parseSize(std::string_view option, std::string_view text, int lo, int hi, int& width, int& height) {
    const size_t x = text.find('x');
    int w = 0, h = 0;
    if (x == std::string_view::npos || !parseInt(option, text.substr(0, x), lo, hi, w) || !parseInt(option, text.substr(x + 1), lo, hi, h))
        return splatfx::makeError(std::string(option) + " expects WxH with each side a whole number in [" + std::to_string(lo) + ", " +
                                  std::to_string(hi) + "], got " + detail::quoted(text));
    width = w;
    height = h;
    return {};
}

// A range of frame indices for one render-farm task: "A-B" (every frame
// from A to B, both included) or "A-B:STEP" (A, A+STEP, ... up to B).
struct FrameRange {
    int first = 0; // default 0
    int last = 0;  // >= first; default 0
    int step = 1;  // >= 1; default 1
    bool contains(int i) const { return i >= first && i <= last && (i - first) % step == 0; }
    int count() const { return (last - first) / step + 1; }
};

// "A-B" or "A-B:STEP" with A, B whole numbers in [0, maxIndex], B >= A and
// STEP a whole number in [1, maxIndex + 1]. Whether B lies inside a given
// sequence is the caller's check (checkFrameRange), since the sequence's
// length is often known only later. Errors name the option and the text.
inline splatfx::Status parseFrameRange(std::string_view option, std::string_view text, int maxIndex, FrameRange& out) {
    const std::string opt(option);
    auto bad = [&](const std::string& why) {
        return splatfx::makeError(opt + " expects A-B or A-B:STEP (frame indices from 0, e.g. 0-23 or 0-95:4), got " + detail::quoted(text) + why);
    };
    const size_t dash = text.find('-');
    if (dash == std::string_view::npos) return bad("");
    const std::string_view a = text.substr(0, dash);
    std::string_view rest = text.substr(dash + 1);
    std::string_view b = rest, st;
    if (const size_t colon = rest.find(':'); colon != std::string_view::npos) {
        b = rest.substr(0, colon);
        st = rest.substr(colon + 1);
    }
    // Each part digits only: no signs ("--range -3-5" or "3-+5" is garbage, not a negative frame).
    auto digitsOnly = [](std::string_view v) { return !v.empty() && v.find_first_not_of("0123456789") == std::string_view::npos; };
    if (!digitsOnly(a) || !digitsOnly(b) || (rest.find(':') != std::string_view::npos && !digitsOnly(st))) return bad("");
    FrameRange r;
    if (!parseInt(option, a, 0, maxIndex, r.first) || !parseInt(option, b, 0, maxIndex, r.last))
        return bad(" (frame indices go from 0 to " + std::to_string(maxIndex) + ")");
    if (r.last < r.first) return bad(" (the last frame " + std::to_string(r.last) + " comes before the first " + std::to_string(r.first) + ")");
    if (!st.empty()) {
        long long step = 0;
        if (!parseInt(option, st, 0ll, (long long)maxIndex + 1, step)) return bad(" (STEP must be a whole number from 1)");
        if (step == 0) return bad(" (STEP must be at least 1)");
        r.step = int(step);
    }
    out = r;
    return {};
}

// The range inside a sequence of `frames` frames (indices 0 .. frames - 1).
inline splatfx::Status checkFrameRange(std::string_view option, const FrameRange& r, int frames) {
    if (r.last < frames) return {};
    return splatfx::makeError(std::string(option) + " " + std::to_string(r.first) + "-" + std::to_string(r.last) +
                              (r.step > 1 ? ":" + std::to_string(r.step) : std::string()) + " goes beyond the sequence: it has " +
                              std::to_string(frames) + " frame(s), indices 0-" + std::to_string(frames - 1) +
                              " (set the sequence's length with --frames, the same for every task)");
}

// Runs body() (returning the exit code) and turns an escaping exception into
// "<tool>: <why>" on stderr and exit code 1. std::bad_alloc gets its own
// message: the run asked for more memory than this machine could give.
template <class Body>
int guardedMain(const char* tool, Body&& body) noexcept {
    try {
        return body();
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr,
                     "%s: out of memory: this run needs more memory than the machine could allocate; "
                     "lower the sizes or counts asked for\n",
                     tool);
    } catch (const std::exception& e) { std::fprintf(stderr, "%s: internal error: %s\n", tool, e.what()); } catch (...) {
        std::fprintf(stderr, "%s: internal error (unknown exception)\n", tool);
    }
    return 1;
}

} // namespace cli

// splatfx/result.hpp: how splatfx reports runtime failure.
//
// Runtime failures (a bad file, bad data, no EGL display) come back as a
// Result carrying a message a person can act on. No exception crosses the
// public API, so engines built with -fno-exceptions can use the SDK.
// Misuse of the API (a broken precondition) is an assertion, not a Result.
//
//   splatfx::Result<splatfx::TextureSet> set = splatfx::loadTextureSet("textures/fire8");
//   if (!set) { std::fprintf(stderr, "%s\n", set.error().c_str()); return 1; }
//   use(*set);
//
// Threading: plain values; no shared state.
#pragma once

#include <cassert>
#include <optional>
#include <string>
#include <utility>

namespace splatfx {

// The error half of a Result: a message written for the person reading it.
struct Error {
    std::string message;
};

inline Error makeError(std::string message) { return Error{std::move(message)}; }

// Either a value or an error message.
template <class T>
class [[nodiscard]] Result {
public:
    Result(T value) : mValue(std::move(value)) {}             // NOLINT: implicit by design
    Result(Error error) : mError(std::move(error.message)) {} // NOLINT: implicit by design

    bool ok() const { return mValue.has_value(); }
    explicit operator bool() const { return ok(); }

    // Expects ok().
    T& value() & {
        assert(ok() && "Result::value() called on an error");
        return *mValue;
    }
    const T& value() const& {
        assert(ok() && "Result::value() called on an error");
        return *mValue;
    }
    T&& value() && {
        assert(ok() && "Result::value() called on an error");
        return std::move(*mValue);
    }
    T& operator*() & { return value(); }
    const T& operator*() const& { return value(); }
    T&& operator*() && { return std::move(*this).value(); }
    T* operator->() { return &value(); }
    const T* operator->() const { return &value(); }

    // Empty when ok().
    const std::string& error() const { return mError; }

private:
    std::optional<T> mValue;
    std::string mError;
};

// A Result with no value: success, or an error message.
class [[nodiscard]] Status {
public:
    Status() = default;
    Status(Error error) : mError(std::move(error.message)), mFailed(true) {} // NOLINT: implicit by design

    bool ok() const { return !mFailed; }
    explicit operator bool() const { return ok(); }
    const std::string& error() const { return mError; }

private:
    std::string mError;
    bool mFailed = false;
};

} // namespace splatfx

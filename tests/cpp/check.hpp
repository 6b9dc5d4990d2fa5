// Minimal test macros (no framework): CHECK(cond), CHECK_NEAR(a, b, tol).
// A failed check prints file:line and the values and is counted; a test's
// main returns sh_test::report("name"), nonzero when anything failed.
#pragma once

#include <cmath>
#include <cstdio>

namespace sh_test {

inline int& failures() {
  static int n = 0;
  return n;
}
inline long& checks() {
  static long n = 0;
  return n;
}

inline bool check(bool ok, const char* expr, const char* file, int line) {
  ++checks();
  if (!ok) {
    ++failures();
    std::fprintf(stderr, "%s:%d: CHECK failed: %s\n", file, line, expr);
  }
  return ok;
}

//! |a - b| <= tol (NaN fails).
inline bool check_near(double a, double b, double tol, const char* ea, const char* eb, const char* file, int line) {
  ++checks();
  const bool ok = std::fabs(a - b) <= tol;
  if (!ok) {
    ++failures();
    std::fprintf(stderr, "%s:%d: CHECK_NEAR failed: %s = %.17g, %s = %.17g, |diff| = %.3g > tol = %.3g\n", file, line,
                 ea, a, eb, b, std::fabs(a - b), tol);
  }
  return ok;
}

//! Prints a one-line summary; the return value is main's exit code.
inline int report(const char* name) {
  std::printf("%s: %ld checks, %d failed\n", name, checks(), failures());
  return failures() == 0 ? 0 : 1;
}

}  // namespace sh_test

#define CHECK(cond) ::sh_test::check(static_cast<bool>(cond), #cond, __FILE__, __LINE__)
#define CHECK_NEAR(a, b, tol) ::sh_test::check_near((a), (b), (tol), #a, #b, __FILE__, __LINE__)

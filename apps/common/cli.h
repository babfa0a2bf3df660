// What the command-line apps share: number arguments and the error convention of main()
// (one line naming the app, the error kind and the problem; exit 2 for usage errors, else 1).
#pragma once

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <optional>
#include <string>

#include "gi/errors.h"

namespace gi::cli {

// `text` as a number in [lo, hi]; nullopt when it is not one (trailing characters included).
inline std::optional<double> numberIn(const char* text, double lo, double hi) {
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || !(v >= lo && v <= hi)) return std::nullopt;
  return v;
}

// "expects a number in [lo, hi], got 'text'"
inline std::string rangeMessage(const char* text, double lo, double hi) {
  return "expects a number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got '" +
         text + "'";
}

// Runs the app's body and turns exceptions into its one-line error and exit code.
template <class Body>
int runMain(const char* app, Body&& body) {
  try {
    return body();
  } catch (const Error& e) {
    std::fprintf(stderr, "%s: error (%s): %s\n", app, errorKindName(e.kind()), e.what());
    return e.kind() == ErrorKind::Usage ? 2 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", app, e.what());
    return 1;
  }
}

}  // namespace gi::cli

// A one-line progress bar on stderr (a terminal: redrawn in place; otherwise a line per step).
#pragma once

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>

namespace gi_bench {

class ProgressBar {
 public:
  ProgressBar(bool enabled, std::string what, size_t total)
      : enabled_(enabled && total > 0),
        tty_(isatty(STDERR_FILENO) != 0),
        what_(std::move(what)),
        total_(total),
        start_(std::chrono::steady_clock::now()) {}
  void step(const std::string& label) {
    ++done_;
    if (!enabled_) return;
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double eta = elapsed / double(done_) * double(total_ - done_);
    const int width = 30, filled = int(double(width) * double(done_) / double(total_));
    if (tty_) {
      std::fprintf(stderr, "\r%s [%s%s] %zu/%zu  %.0fs elapsed, ETA %.0fs  %-40.40s", what_.c_str(),
                   std::string(size_t(filled), '#').c_str(),
                   std::string(size_t(width - filled), '.').c_str(), done_, total_, elapsed, eta,
                   label.c_str());
      if (done_ == total_) std::fputc('\n', stderr);
    } else {
      std::fprintf(stderr, "gi-bench: %s %zu/%zu (%s) %.1fs elapsed, ETA %.0fs\n", what_.c_str(),
                   done_, total_, label.c_str(), elapsed, eta);
    }
    std::fflush(stderr);
  }

 private:
  bool enabled_, tty_;
  std::string what_;
  size_t total_, done_ = 0;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace gi_bench

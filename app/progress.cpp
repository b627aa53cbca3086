#include "app/progress.h"

#include <cstdio>

#include <unistd.h>

namespace strata::app {

Progress::Progress(std::string what, size_t total)
    : what_(std::move(what)), total_(total), terminal_(isatty(STDERR_FILENO) != 0) {}

void Progress::step_done(size_t done) {
  const Clock::time_point now = Clock::now();
  const bool last = done == total_;
  if (!terminal_ && !last && now - last_line_ < std::chrono::seconds(10)) return;
  last_line_ = now;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double rate = elapsed > 0.0 ? double(done) / elapsed : 0.0;
  const double left = rate > 0.0 ? double(total_ - done) / rate : 0.0;
  std::fprintf(stderr, "%s%s %zu/%zu, %.2f a second, %.0f s %s   %s", terminal_ ? "\r" : "",
               what_.c_str(), done, total_, rate, last ? elapsed : left, last ? "in all" : "left",
               terminal_ && !last ? "" : "\n");
}

double Progress::seconds() const {
  return std::chrono::duration<double>(Clock::now() - start_).count();
}

}  // namespace strata::app

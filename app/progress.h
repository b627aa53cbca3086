// Progress of a long operation on stderr: on a terminal one line rewritten in place ("frame
// 12/60, 8.3 a second, 6 s left"), elsewhere (logs, CI) a line at most every 10 seconds and one at
// the end, so a long run is never silent.
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

namespace strata::app {

class Progress {
 public:
  // `what` names the steps: "frame", "order".
  Progress(std::string what, size_t total);
  void step_done(size_t done);
  // Seconds since the progress began.
  double seconds() const;

 private:
  using Clock = std::chrono::steady_clock;
  std::string what_;
  size_t total_;
  bool terminal_;
  Clock::time_point start_ = Clock::now();
  Clock::time_point last_line_ = Clock::now();
};

}  // namespace strata::app

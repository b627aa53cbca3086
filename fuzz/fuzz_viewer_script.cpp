// The viewer's input scripts (`strata view --script`, app/viewer/script.cpp) through
// parse_viewer_script: every command it returns must carry numbers that are finite and within the
// script limits, or the parse gives an Error.
#include <cmath>
#include <string>

#include "app/viewer/script.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  strata::fuzz::expect_only_errors([&] {
    for (const strata::app::ScriptCommand& c : strata::app::parse_viewer_script(text, "script")) {
      for (const double n : c.numbers) {
        if (!std::isfinite(n) || std::abs(n) > strata::app::kScriptMaxLabelId) {
          std::fprintf(stderr, "fuzz: line %zu: a number %g past the limits\n", c.line, n);
          std::abort();
        }
      }
      if (c.name == "frames" && c.numbers[0] > strata::app::kScriptMaxFrames) {
        std::fprintf(stderr, "fuzz: line %zu: frames %g\n", c.line, c.numbers[0]);
        std::abort();
      }
      if (c.name == "sleep" && !(c.numbers[0] <= strata::app::kScriptMaxSleep)) {
        std::fprintf(stderr, "fuzz: line %zu: sleep %g\n", c.line, c.numbers[0]);
        std::abort();
      }
    }
  });
  return 0;
}

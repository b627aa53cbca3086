// Names tables (names_table.cpp) on fuzzed text: every form is told by content, so one target
// reaches them all. The extension decides only where content cannot (.json, .csv, .ctbl), so each
// input is parsed under the three names.
#include <string_view>

#include "engine/scene/segmentation.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  for (const char* name : {"input.txt", "input.csv", "input.json"})
    strata::fuzz::expect_only_errors([&] { strata::parse_names_table(text, name); });
  return 0;
}

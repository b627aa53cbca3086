// Slicer's fiducial lists through load_label_file (label_file_loader.cpp), which picks the reader
// by extension.
#include "engine/scene/io/label_file_loader.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = strata::fuzz::write_input(data, size, "input.fcsv");
  strata::fuzz::expect_only_errors([&] { strata::load_label_file(path); });
  return 0;
}

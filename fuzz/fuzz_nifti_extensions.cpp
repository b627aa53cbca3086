// The label table in NIfTI header extensions (nifti_extensions.cpp) on fuzzed bytes: the walk
// over the bytes in memory, then the same bytes as input.nii read from the file (only the header
// and extensions; gzip when the input starts as gzip does).
#include <string_view>

#include "engine/scene/segmentation.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  strata::fuzz::expect_only_errors(
      [&] { strata::nifti_label_table_from_bytes(bytes, "input.nii"); });
  const auto path = strata::fuzz::write_input(data, size, "input.nii");
  strata::fuzz::expect_only_errors([&] { strata::nifti_label_table(path); });
  return 0;
}

// The DICOM structure walker (dicom_structure.cpp) that guards GDCM: the file's kind, then, as
// dicom.cpp does, the walk over every element of a Part 10 file or bare data set.
#include "engine/scene/io/dicom_structure.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = strata::fuzz::write_input(data, size, "input.dcm");
  strata::fuzz::expect_only_errors([&] {
    const auto kind = strata::dicom::file_kind(path);
    if (kind != strata::dicom::Kind::other) strata::dicom::check_structure(path, kind);
  });
  return 0;
}

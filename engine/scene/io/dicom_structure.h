// The byte structure of a DICOM file, checked before GDCM parses it (see dicom_structure.cpp).
#pragma once

#include <filesystem>

namespace strata::dicom {

// Files with the Part 10 preamble are DICOM; a bare data set (no preamble) usually starts with a
// group 0008 tag. Anything else is not handed to the parser at all.
enum class Kind { part10, bare, other };

Kind file_kind(const std::filesystem::path& file);

// Throws strata::Error naming the file when an element header or value does not fit in the file,
// or the transfer syntax is one strata cannot read.
void check_structure(const std::filesystem::path& file, Kind kind);

}  // namespace strata::dicom

// Reading a DICOM data set's elements with GDCM, shared by the image reader (dicom.cpp) and the
// Segmentation reader (dicom_seg.cpp): values as checked numbers and text, the functional groups
// of multi-frame files, and the plane attributes of one slice.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <gdcmDataSet.h>
#include <gdcmFile.h>
#include <gdcmReader.h>
#include <gdcmSequenceOfItems.h>
#include <gdcmStringFilter.h>

#include "engine/scene/io/dicom_slice.h"
#include "engine/scene/io/volume_io.h"

namespace strata::dicom {

// Element values of one data set (the file's, or a functional group's item) as text: GDCM's
// StringFilter renders binary VRs such as US too. Parsed by hand so that malformed values become
// errors instead of zeros; errors name `context` ("frame 3: ") before the element.
class Elements {
 public:
  Elements(const gdcm::File& file, const gdcm::DataSet& data_set, std::filesystem::path path,
           std::string context = "")
      : data_set_(data_set), path_(std::move(path)), context_(std::move(context)) {
    filter_.SetFile(file);
  }
  bool has(uint16_t group, uint16_t element) const {
    const gdcm::Tag tag(group, element);
    return data_set_.FindDataElement(tag) && !data_set_.GetDataElement(tag).IsEmpty();
  }
  std::string text(uint16_t group, uint16_t element) const {
    if (!has(group, element)) return {};
    return std::string(
        volume_io::trim(filter_.ToString(data_set_.GetDataElement(gdcm::Tag(group, element)))));
  }
  // The backslash-separated numbers of a required element (or of an optional one, if present).
  std::vector<double> numbers(uint16_t group, uint16_t element, const char* name, size_t count,
                              std::optional<double> fallback = std::nullopt) const {
    if (!has(group, element)) {
      if (!fallback) volume_io::fail(path_, volume_io::concat(context_, name, " is missing"));
      return std::vector<double>(count, *fallback);
    }
    std::string value = text(group, element);
    std::replace(value.begin(), value.end(), '\\', ' ');
    const std::vector<double> result =
        volume_io::parse_numbers<double>(path_, context_ + name, value);
    if (result.size() != count)
      volume_io::fail(path_, volume_io::concat(context_, name, " = '", volume_io::printable(value),
                                               "': expected ", count, " numbers"));
    return result;
  }
  int integer(uint16_t group, uint16_t element, const char* name,
              std::optional<double> fallback = std::nullopt) const {
    const double v = numbers(group, element, name, 1, fallback)[0];
    if (v != std::floor(v) || std::fabs(v) > 65535.0)
      volume_io::fail(path_,
                      volume_io::concat(context_, name, " = ", v, ": expected a whole number"));
    return static_cast<int>(v);
  }
  const gdcm::DataSet& data_set() const { return data_set_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  const gdcm::DataSet& data_set_;
  std::filesystem::path path_;
  std::string context_;
  gdcm::StringFilter filter_;
};

// Calls read(item) with the first item of a sequence element; false when there is none. The
// callback keeps GDCM's item alive while it is read (GetValueAsSQ may build it on the fly).
template <class Read>
bool with_first_item(const gdcm::DataSet& data_set, uint16_t group, uint16_t element, Read&& read) {
  const gdcm::Tag tag(group, element);
  if (!data_set.FindDataElement(tag)) return false;
  const gdcm::SmartPointer<gdcm::SequenceOfItems> items =
      data_set.GetDataElement(tag).GetValueAsSQ();
  if (!items || items->GetNumberOfItems() == 0) return false;
  read(items->GetItem(1).GetNestedDataSet());
  return true;
}

// Per-frame and Shared Functional Groups Sequences: each item holds macros (PlanePosition,
// PixelMeasures, ...), each macro a sequence of one item that holds the attributes.
class FunctionalGroups {
 public:
  explicit FunctionalGroups(const gdcm::DataSet& data_set)
      : per_frame_(sequence(data_set, 0x9230)), shared_(sequence(data_set, 0x9229)) {}
  bool present() const { return per_frame_ || shared_; }
  size_t per_frame_items() const { return per_frame_ ? per_frame_->GetNumberOfItems() : 0; }

  // Calls read(attributes) with frame f's macro (group, element), from the frame's own item or
  // else the shared one; false when neither has it.
  template <class Read>
  bool with_macro(size_t f, uint16_t group, uint16_t element, Read&& read) const {
    if (f < per_frame_items() &&
        with_first_item(per_frame_->GetItem(f + 1).GetNestedDataSet(), group, element, read))
      return true;
    return shared_ && shared_->GetNumberOfItems() > 0 &&
           with_first_item(shared_->GetItem(1).GetNestedDataSet(), group, element, read);
  }

 private:
  static gdcm::SmartPointer<gdcm::SequenceOfItems> sequence(const gdcm::DataSet& data_set,
                                                            uint16_t element) {
    const gdcm::Tag tag(0x5200, element);
    if (!data_set.FindDataElement(tag)) return nullptr;
    return data_set.GetDataElement(tag).GetValueAsSQ();
  }
  gdcm::SmartPointer<gdcm::SequenceOfItems> per_frame_, shared_;
};

// ImagePositionPatient (with the last digit each coordinate is printed to), ImageOrientationPatient
// and PixelSpacing with SliceThickness, from a data set that holds them (the file's or a
// functional group's item).
void read_position(const Elements& e, Slice& s);
void read_orientation(const Elements& e, Slice& s);
void read_pixel_measures(const Elements& e, Slice& s);

// Files that are not DICOM are skipped on purpose; GDCM must not print about them.
void quiet_gdcm();

// The Error for a file GDCM could not parse: its transfer syntax where GDCM does not know it,
// else "truncated or malformed".
[[noreturn]] void fail_to_parse(const std::filesystem::path& file, const gdcm::Reader& reader);

}  // namespace strata::dicom

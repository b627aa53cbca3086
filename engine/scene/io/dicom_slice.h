// One slice of a DICOM series as its header describes it: what dicom.cpp reads from each file and
// dicom_stack.cpp puts in order as one volume.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>

#include <glm/glm.hpp>

#include "engine/scene/io/volume_io.h"

namespace strata::dicom {

// Elements that may tell apart two slices at one position: the first three are time (one of them
// splits a series into time points that --frame chooses), the others only name what differs.
struct KeyTag {
  uint16_t group, element;
  const char* name;
};
inline constexpr std::array<KeyTag, 7> kKeyTags = {{
    {0x0020, 0x0100, "TemporalPositionIdentifier"},
    {0x0020, 0x0012, "AcquisitionNumber"},
    {0x0018, 0x1060, "TriggerTime"},
    {0x0018, 0x0086, "EchoNumbers"},
    {0x0018, 0x0081, "EchoTime"},
    {0x0018, 0x9087, "DiffusionBValue"},
    {0x0008, 0x0008, "ImageType"},
}};
inline constexpr size_t kTimeKeys = 3;

// One slice: a single-frame file, or one frame of a multi-frame file.
struct Slice {
  std::filesystem::path file;
  size_t frame = 0;  // in its file, from 0
  size_t frames_in_file = 1;
  uint32_t rows = 0, columns = 0;
  glm::dvec3 position{0.0}, row_cosine{0.0}, column_cosine{0.0};
  // The last digit ImagePositionPatient prints of each coordinate (0.1 for "-12.3"): the values
  // may be off by half of it.
  glm::dvec3 position_digit{0.0};
  glm::dvec2 pixel_spacing{0.0};  // (along a row = between columns, between rows)
  int bits_allocated = 0, bits_stored = 0, high_bit = 0;
  bool is_signed = false;
  volume_io::Rescale rescale;
  std::string series, syntax;                        // SeriesInstanceUID, TransferSyntaxUID
  std::string series_number, description, modality;  // SeriesNumber, SeriesDescription, Modality
  std::string instance;                              // SOPInstanceUID
  std::array<std::string, kKeyTags.size()> keys;     // kKeyTags' values
  std::string stack, time;  // StackID and TemporalPositionIndex of enhanced files' frames
  double thickness = 0.0;
  double along_normal = 0.0;  // the position projected onto the slice normal
  bool placed = true;         // false: no ImagePositionPatient (a secondary capture, a 2-D image)
};

// "2062", or "frame 5" inside a multi-frame file (whose name the error already gives).
std::string name_of(const Slice& s);

inline glm::dvec3 slice_normal(const Slice& s) {
  return glm::normalize(glm::cross(s.row_cosine, s.column_cosine));
}

}  // namespace strata::dicom

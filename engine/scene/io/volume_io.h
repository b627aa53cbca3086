// Helpers shared by the volume readers (nifti.cpp, metaimage.cpp, nrrd.cpp, dicom.cpp); not part
// of the engine's API. They exist so that every reader checks sizes the same way, reads voxels
// straight into Volume::voxels (decompressing on the fly) and words its errors the same way:
// "<file>: <field>: <reason>".
#pragma once

#include <array>
#include <charconv>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "engine/core/error.h"
#include "engine/scene/io/volume_loader.h"
#include "engine/scene/scene.h"

namespace strata::volume_io {

// ---- errors

template <class... Parts>
std::string concat(const Parts&... parts) {
  std::ostringstream out;
  (out << ... << parts);
  return out.str();
}

// Throws Error("<file>: <what>").
[[noreturn]] void fail(const std::filesystem::path& file, const std::string& what);

// ---- element types and sizes

// Element types as files store them. Volume holds uint8, int16, uint16 and float32; the others
// are converted to float32 after reading.
enum class StoredType { uint8, int8, int16, uint16, int32, uint32, float32, float64 };

size_t stored_size(StoredType type);
const char* to_string(StoredType type);

// Larger volumes do not fit any GPU strata targets; refusing them early also means a corrupt
// header never makes us allocate terabytes.
inline constexpr uint64_t max_voxel_bytes = uint64_t{1} << 34;  // 16 GiB

// The byte count of dims[0] x dims[1] x dims[2] elements, after checking that every dimension is
// positive and fits Volume::dims, that the product does not overflow and stays under
// max_voxel_bytes, and that the volume fits the limits (the machine's memory, the device).
// `field` names the header field in errors ("dim[1..3]", "DimSize", "sizes").
size_t checked_voxel_bytes(const std::filesystem::path& file, std::string_view field,
                           const std::array<int64_t, 3>& dims, size_t element_size,
                           const VolumeLimits& limits);

// The machine's physical memory in bytes.
uint64_t physical_memory_bytes();

// Dimensions that passed checked_voxel_bytes, as Volume holds them.
inline glm::uvec3 to_dims(const std::array<int64_t, 3>& dims) {
  return glm::uvec3(static_cast<uint32_t>(dims[0]), static_cast<uint32_t>(dims[1]),
                    static_cast<uint32_t>(dims[2]));
}

// Spacing must be finite and positive, and within value_limits.h's range; `field` names where
// it came from, `axis_field` and `first_axis` name one axis's number ("pixdim", 1: "pixdim[1]").
void check_spacing(const std::filesystem::path& file, std::string_view field,
                   const std::array<double, 3>& spacing, std::string_view axis_field = {},
                   int first_axis = 0);

// The geometry within value_limits.h's limits: each spacing, the origin, the far corner, and
// voxels still apart in float at their position. check_geometry ends with it; load_volume runs it
// on every volume (DICOM's reader does not call check_geometry).
void check_plausible_geometry(const std::filesystem::path& file, std::string_view origin_field,
                              std::string_view direction_field, const Volume& volume);

// The volume's spacing, origin and direction as a reader set them: spacing positive, every number
// finite (in float range),
// each direction column of unit length (within 10%; then made exact) and the three columns
// spanning space, not lying in a plane. `origin_field` and `direction_field` name the header
// fields in errors ("qoffset_x/y/z", "TransformMatrix", ...).
void check_geometry(const std::filesystem::path& file, std::string_view origin_field,
                    std::string_view direction_field, Volume& volume);

// ---- reading

// A header or data file read from `offset`, either as it is or inflated (zlib or gzip streams,
// detected by their own headers; concatenated gzip members are read as one stream). Errors name
// `report_as` (the header file the user asked for) and `what` ("ElementDataFile 'a.raw'").
class InputFile {
 public:
  struct Source {
    std::filesystem::path file;
    std::filesystem::path report_as;
    std::string what;
    uint64_t offset = 0;
    bool compressed = false;
    // Compressed bytes that belong to the stream (MetaImage's CompressedDataSize); all to the end
    // of the file when unset.
    std::optional<uint64_t> compressed_size;
  };
  explicit InputFile(Source source);
  ~InputFile();
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;

  // Reads up to n bytes; fewer only where the data ends.
  size_t read(std::byte* destination, size_t n);
  // Skips n bytes of (decompressed) data; false if the data ends first.
  bool skip(uint64_t n);
  // The most bytes the rest of the data can hold: exact for raw files, for compressed ones the
  // bound deflate's maximum ratio (1032:1) allows. Checked before allocating.
  uint64_t max_remaining() const;
  bool compressed() const { return source_.compressed; }
  const Source& source() const { return source_; }

 private:
  struct Inflater;
  size_t read_compressed(std::byte* destination, size_t n);
  bool refill();

  Source source_;
  std::ifstream in_;
  uint64_t file_bytes_left_ = 0;  // raw: data bytes left; compressed: input bytes left
  uint64_t produced_ = 0;         // decompressed bytes handed out
  uint64_t compressed_total_ = 0;
  std::unique_ptr<Inflater> inflater_;
};

// True if the file starts with the gzip magic bytes (1f 8b).
bool is_gzip_file(const std::filesystem::path& file);

// Reads exactly `bytes` into volume.voxels (the one allocation of the voxels), after checking that
// the source can hold them; "<what> has N bytes, the header needs M" otherwise.
void read_voxels(InputFile& in, size_t bytes, Volume& volume);

// Up to max_bytes from the start of a file (headers of text formats).
std::string read_prefix(const std::filesystem::path& file, size_t max_bytes);

// check_input_file (engine/core/text_file.h): the size of a regular file, else one Error.
uint64_t existing_file_size(const std::filesystem::path& file);
// The size of a data file a header names (a FIFO there would block the reader): errors name the
// header and `what` ("ElementDataFile 'a.raw': no such file (<file>)").
uint64_t data_file_size(const std::filesystem::path& header, std::string_view what,
                        const std::filesystem::path& file);

// ---- 4-D images

// The frame of an image with `frames` frames (1 for a 3-D one) that options ask for, 0 when they
// do not: out of range is an error that names the range, and a 4-D image adds the warning that
// says which frame is shown.
uint64_t choose_frame(const std::filesystem::path& file, uint64_t frames,
                      const VolumeReadOptions& options, std::vector<std::string>& warnings);

// Skips the frames before `frame` (frames are stored one after the other, the fourth dimension
// slowest); "<what> ends before frame N" when the data does.
void skip_frames(InputFile& in, uint64_t frame, size_t frame_bytes);

// ---- voxel conversion

// Reverses the byte order of every element of the given size, in place.
void swap_bytes(std::span<std::byte> data, size_t element_size);

struct Rescale {
  double slope = 1.0;
  double intercept = 0.0;
  // NIfTI and DICOM both say: slope 0 (or not finite) means "no scaling".
  bool applies() const;
};

// Turns freshly read elements into what Volume holds, in place where it can: fixes the byte order,
// converts int8/int32/uint32/float64 to float32, applies the rescale and fills value_range.
// `per_slice` holds one rescale for the whole volume or one per k slice (DICOM). With
// int16_when_exact, integer rescales whose results fit int16 give int16 (DICOM CT); otherwise any
// rescale that applies gives float32. At most one extra buffer of the result's size is made.
struct Conversion {
  StoredType stored = StoredType::uint8;
  bool big_endian = false;
  std::vector<Rescale> per_slice;
  bool int16_when_exact = false;
  // Names the slope and intercept in errors (a rescale that overflows float is one).
  const char* rescale_field = "slope, intercept";
};
void finish_voxels(Volume& volume, const Conversion& conversion);

// Min and max over all voxels (NaN and infinities skipped).
glm::vec2 compute_value_range(const Volume& volume);

// The file name without the volume extensions (.nii.gz, .mha, ...).
std::string volume_name(const std::filesystem::path& path);

// ---- text headers (MetaImage, NRRD)

std::string_view trim(std::string_view text);
std::string lowercase(std::string_view text);
// At most max_length characters of text for an error message, bytes outside ASCII shown as '?'.
std::string printable(std::string_view text, size_t max_length = 40);

// Text headers are a few hundred bytes; a megabyte without the header's end is not a header.
inline constexpr size_t max_text_header_bytes = 1 << 20;

// A text header's fields in file order, names lowercased: MetaImage's "Key = Value" lines and
// NRRD's "field: value" lines.
struct TextHeader {
  std::filesystem::path path;
  std::vector<std::pair<std::string, std::string>> fields;  // lowercase name, value
  uint64_t data_offset = 0;  // where data that follows the header starts
  bool quote_names = false;  // NRRD's names hold spaces: errors quote them
  // NRRD's "key:=value" lines in file order, keys as written (3D Slicer keeps its metadata there).
  std::vector<std::pair<std::string, std::string>> key_values;

  // The value of a field, its name in any case.
  std::optional<std::string_view> get(std::string_view name) const;
  // The value of the first of the names (a format's synonyms) that is present.
  std::optional<std::string_view> first_of(std::initializer_list<std::string_view> names) const;
  // The value of a field; "no <name> field" otherwise.
  std::string_view require(std::string_view name) const;
};

// The line of `text` that starts at `pos`, without its '\n' (nor a '\r' before it); `pos` moves
// past it. `complete`: a '\n' ended it (else the text did: a header cut there?).
struct TextLine {
  std::string_view text;
  bool complete = false;
};
TextLine next_line(std::string_view text, size_t& pos);

// Whitespace-separated numbers; "<file>: <field>: '<text>' is not a list of numbers" otherwise.
template <class T>
std::vector<T> parse_numbers(const std::filesystem::path& file, std::string_view field,
                             std::string_view text) {
  std::vector<T> values;
  const char* p = text.data();
  const char* end = text.data() + text.size();
  while (true) {
    while (p < end && (*p == ' ' || *p == '\t' || *p == ',')) ++p;
    if (p == end) break;
    if (*p == '+') ++p;  // from_chars refuses a leading '+', files sometimes have one
    T value{};
    const auto [next, error] = std::from_chars(p, end, value);
    if (error != std::errc{}) {
      const char* reason =
          error == std::errc::result_out_of_range ? "is out of range" : "is not a list of numbers";
      fail(file, concat(field, ": '", printable(trim(text)), "' ", reason));
    }
    values.push_back(value);
    p = next;
  }
  return values;
}

template <class T, size_t N>
std::array<T, N> parse_exactly(const std::filesystem::path& file, std::string_view field,
                               std::string_view text) {
  const std::vector<T> values = parse_numbers<T>(file, field, text);
  if (values.size() != N)
    fail(file, concat(field, ": expected ", N, " numbers, got '", printable(trim(text)), "'"));
  std::array<T, N> result{};
  for (size_t i = 0; i < N; ++i) result[i] = values[i];
  return result;
}

// ---- NRRD (nrrd.cpp), shared with 3D Slicer's .seg.nrrd reader

// A .nrrd or .nhdr header: its fields, and its "key:=value" lines in key_values.
TextHeader read_nrrd_header(const std::filesystem::path& path);

// A NRRD's axes: three spatial ones (a 2-D image's third is one voxel) and, in a 4-D image, one
// non-spatial axis: last in an image (its frames, stored one after the other) or first in a
// segmentation (its layers, interleaved voxel by voxel).
struct NrrdAxes {
  int rank = 3;
  std::array<int64_t, 3> dims{1, 1, 1};
  int64_t count = 1;  // along the non-spatial axis
  bool list_first = false;
};
NrrdAxes nrrd_axes(const TextHeader& header, bool list_first);

// The volume's spacing, origin and direction (LPS+) from "space directions" (or "spacings") and
// "space origin", checked as check_geometry does.
void set_nrrd_geometry(Volume& volume, const TextHeader& header, const NrrdAxes& axes);

bool nrrd_big_endian(const TextHeader& header);

// The data opened at its first byte: attached or in the data file, raw or gzip, after "line skip"
// and "byte skip". `data_bytes`, the size of all of it, places data that "byte skip: -1" puts at
// the end of its file.
std::unique_ptr<InputFile> open_nrrd_data(const TextHeader& header, uint64_t data_bytes);

}  // namespace strata::volume_io

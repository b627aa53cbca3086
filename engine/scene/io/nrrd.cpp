// NRRD (teem's "nearly raw raster data"): a "NRRD000N" magic line, "field: value" lines, then
// either a blank line and the data (.nrrd, attached) or a "data file:" field (.nhdr, detached).
// strata reads scalar images with raw or gzip encoding: 3-D, 2-D (one slice) and of a 4-D image
// whose fourth axis is the non-spatial one (time) one frame. Positions in "space directions" and
// "space origin" are converted to strata's LPS+ patient space according to the "space" field.
#include <algorithm>
#include <bit>
#include <sstream>

#include "engine/scene/io/volume_io.h"
#include "engine/scene/io/volume_loader.h"

namespace strata {
namespace {

using namespace volume_io;
namespace fs = std::filesystem;

std::optional<std::string_view> data_file(const TextHeader& header) {
  return header.first_of({"data file", "datafile"});
}

void check_magic(const fs::path& path, const std::string& text) {
  const std::string_view first = std::string_view(text).substr(0, text.find('\n'));
  const bool ok =
      first.size() >= 8 && first.starts_with("NRRD000") && first[7] >= '1' && first[7] <= '5';
  if (!ok)
    fail(path, concat("not a NRRD file: wrong magic '", printable(first.substr(0, 8)),
                      "' (expected NRRD0001 to NRRD0005)"));
}

}  // namespace

TextHeader volume_io::read_nrrd_header(const fs::path& path) {
  TextHeader header{.path = path, .quote_names = true};
  const std::string text = read_prefix(path, max_text_header_bytes);
  check_magic(path, text);
  size_t pos = text.find('\n') + 1;
  bool attached = false;      // a blank line ended the header: the data follows it
  std::string bad_last_line;  // an unfinished last line that is not a field: cut off?
  for (int line_number = 2; pos < text.size(); ++line_number) {
    const auto [line, complete] = next_line(text, pos);
    if (line.empty()) {
      attached = true;
      header.data_offset = pos;
      break;
    }
    if (line.starts_with('#')) continue;
    const size_t colon = line.find(": ");
    if (const size_t key = line.find(":="); key < colon) {
      header.key_values.emplace_back(line.substr(0, key), line.substr(key + 2));
      continue;
    }
    if (colon == std::string_view::npos) {
      const std::string message =
          concat("line ", line_number, ": expected 'field: value', got '", printable(line), "'");
      if (complete) fail(path, message);
      bad_last_line = message;
      break;
    }
    header.fields.emplace_back(lowercase(trim(line.substr(0, colon))),
                               std::string(trim(line.substr(colon + 2))));
  }
  if (!attached && !data_file(header)) {
    if (text.size() == max_text_header_bytes)
      fail(path, "no blank line ends the header in its 1 MiB");
    fail(path, "header is truncated: no blank line ends it and it names no data file");
  }
  if (!bad_last_line.empty()) fail(path, bad_last_line);
  return header;
}

namespace {

StoredType element_type(const TextHeader& header) {
  const std::string type = lowercase(header.require("type"));
  for (const char* name : {"uchar", "unsigned char", "uint8", "uint8_t"})
    if (type == name) return StoredType::uint8;
  for (const char* name :
       {"short", "short int", "signed short", "signed short int", "int16", "int16_t"})
    if (type == name) return StoredType::int16;
  for (const char* name : {"ushort", "unsigned short", "unsigned short int", "uint16", "uint16_t"})
    if (type == name) return StoredType::uint16;
  if (type == "float") return StoredType::float32;
  fail(header.path,
       concat("type '", type, "' is not supported (strata reads uchar, short, ushort, float)"));
}

// "(x,y,z) (x,y,z) ..." as the texts between the parentheses; nothing for "none" (the entry of a
// non-spatial axis).
std::vector<std::optional<std::string_view>> vectors(const fs::path& path, std::string_view field,
                                                     std::string_view text) {
  std::vector<std::optional<std::string_view>> result;
  std::string_view rest = trim(text);
  while (!rest.empty()) {
    if (rest.starts_with("none")) {
      result.push_back(std::nullopt);
      rest = trim(rest.substr(4));
      continue;
    }
    const size_t close = rest.find(')');
    if (rest.front() != '(' || close == std::string_view::npos)
      fail(path, concat(field, ": '", printable(text), "' is not a list of (x,y,z) vectors"));
    result.push_back(rest.substr(1, close - 1));
    rest = trim(rest.substr(close + 1));
  }
  return result;
}

// A vector of the header's space: 3 numbers, or 2 in a 2-D space (its z is 0).
glm::dvec3 vector_in_space(const fs::path& path, std::string_view field, std::string_view inside,
                           int space_dimension) {
  if (space_dimension == 2) {
    const auto v = parse_exactly<double, 2>(path, field, inside);
    return glm::dvec3(v[0], v[1], 0.0);
  }
  const auto v = parse_exactly<double, 3>(path, field, inside);
  return glm::dvec3(v[0], v[1], v[2]);
}

// How many numbers a vector has: "space dimension", or 3 for a named space (all of NRRD's named
// spaces are 3-D). A 2-D space (ITK writes one for 2-D images) holds only a 2-D image.
int space_dimension(const TextHeader& header, int rank) {
  const fs::path& path = header.path;
  const auto text = header.get("space dimension");
  if (!text) return 3;
  if (header.get("space")) fail(path, "both 'space' and 'space dimension': give one");
  const int64_t n = parse_exactly<int64_t, 1>(path, "space dimension", *text)[0];
  if (n != 2 && n != 3)
    fail(path, concat("space dimension = ", n,
                      ": expected 2 or 3 (strata reads 2-D and 3-D "
                      "spaces)"));
  if (n == 2 && rank != 2)
    fail(path,
         concat("space dimension = 2: a 2-D space holds a 2-D image, but dimension is ", rank));
  return int(n);
}

// Signs that take coordinates of the header's "space" to LPS+.
glm::dvec3 to_lps(const TextHeader& header) {
  const auto space = header.get("space");
  if (!space) return glm::dvec3(1.0);
  const std::string name = lowercase(*space);
  if (name == "right-anterior-superior" || name == "ras") return {-1.0, -1.0, 1.0};
  if (name == "left-anterior-superior" || name == "las") return {1.0, -1.0, 1.0};
  if (name == "left-posterior-superior" || name == "lps" || name == "scanner-xyz" ||
      name == "3d-right-handed" || name == "3d-left-handed")
    return glm::dvec3(1.0);
  fail(header.path, concat("space '", *space, "' is not a 3D space strata knows"));
}

// What a 4-D file must look like, for errors.
const char* layout_rule(bool list_first) {
  return list_first ? "strata reads 4-D segmentations whose first axis is the list of layers"
                    : "strata reads 4-D images whose fourth axis is the non-spatial one (time)";
}

bool spatial_kind(const std::string& kind) {
  const std::string k = lowercase(kind);
  return k == "domain" || k == "space" || k == "???" || k == "none";
}

// The non-spatial axis ("none" in space directions, a kind other than domain or space) must be
// the last (an image's frames, read one at a time) or the first (a segmentation's layers).
void check_kinds(const TextHeader& header, bool list_first) {
  const auto kinds = header.get("kinds");
  if (!kinds) return;
  std::istringstream words{std::string(*kinds)};
  std::string kind;
  for (int axis = 0; axis < 4 && words >> kind; ++axis) {
    const bool list_axis = list_first ? axis == 0 : axis == 3;
    const std::string k = lowercase(kind);
    const bool wrong = list_axis
                           ? list_first && (k == "domain" || k == "space")  // ("none": unknown)
                           : !spatial_kind(kind);
    if (wrong)
      fail(header.path,
           concat("kinds: axis ", axis, " is '", kind, "': ", layout_rule(list_first)));
  }
}

}  // namespace

NrrdAxes volume_io::nrrd_axes(const TextHeader& header, bool list_first) {
  const fs::path& path = header.path;
  const std::string_view dimension = trim(header.require("dimension"));
  NrrdAxes e{.list_first = list_first};
  if (dimension == "2" || dimension == "3" || dimension == "4") {
    e.rank = dimension[0] - '0';
  } else {
    fail(path, concat("dimension = ", dimension, ": expected 2, 3 or 4 (a 2-D, 3-D or 4-D image)"));
  }
  const std::string_view text = header.require("sizes");
  const auto sizes = parse_numbers<int64_t>(path, "sizes", text);
  if (sizes.size() != size_t(e.rank))
    fail(path, concat("sizes: expected ", e.rank, " numbers (dimension ", e.rank, "), got '",
                      printable(trim(text)), "'"));
  const size_t first_spatial = e.rank == 4 && list_first ? 1 : 0;
  for (size_t axis = 0; axis < std::min<size_t>(3, sizes.size()); ++axis)
    e.dims[axis] = sizes[first_spatial + axis];
  if (e.rank == 4) {
    const size_t list_axis = list_first ? 0 : 3;
    e.count = sizes[list_axis];
    if (e.count < 1)
      fail(path, concat("sizes: axis ", list_axis, " has ", e.count, " ",
                        list_first ? "layers" : "frames", ": must be positive"));
    check_kinds(header, list_first);
  }
  return e;
}

namespace {

void set_direction(Volume& volume, const TextHeader& header, const NrrdAxes& layout,
                   std::string_view text) {
  const fs::path& path = header.path;
  const int rank = layout.rank;
  const glm::dvec3 signs = to_lps(header);
  const int space = space_dimension(header, rank);
  const auto axes = vectors(path, "space directions", text);
  if (axes.size() != size_t(rank))
    fail(path, concat("space directions: expected ", rank, " entries (dimension ", rank, "), got ",
                      axes.size()));
  const int first_spatial = rank == 4 && layout.list_first ? 1 : 0;
  for (int axis = 0; axis < std::min(rank, 3); ++axis) {
    const int entry = first_spatial + axis;
    if (!axes[size_t(entry)])
      fail(path, concat("space directions: axis ", entry,
                        " is 'none': ", layout_rule(layout.list_first)));
    const glm::dvec3 v =
        signs * vector_in_space(path, "space directions", *axes[size_t(entry)], space);
    const double length = glm::length(v);
    if (!(length > 0.0) || !std::isfinite(length))
      fail(path,
           concat("space directions: axis ", entry, " has zero length: spacing must be positive"));
    volume.spacing[axis] = static_cast<float>(length);
    volume.direction[axis] = glm::vec3(v / length);
  }
  const int list_axis = layout.list_first ? 0 : 3;
  if (rank == 4 && axes[size_t(list_axis)])
    fail(path, concat("space directions: axis ", list_axis, " is a vector: it must be 'none' (",
                      layout_rule(layout.list_first), ")"));
  if (rank == 2)  // one slice: k is its normal
    volume.direction[2] = glm::normalize(glm::cross(volume.direction[0], volume.direction[1]));
}

}  // namespace

void volume_io::set_nrrd_geometry(Volume& volume, const TextHeader& header, const NrrdAxes& axes) {
  const fs::path& path = header.path;
  const int rank = axes.rank;
  if (const auto text = header.get("space directions")) {
    set_direction(volume, header, axes, *text);
  } else if (const auto spacings = header.get("spacings")) {
    const auto s = parse_numbers<double>(path, "spacings", *spacings);
    if (s.size() != size_t(rank))
      fail(path, concat("spacings: expected ", rank, " numbers (dimension ", rank, "), got '",
                        printable(trim(*spacings)), "'"));
    const size_t first = rank == 4 && axes.list_first ? 1 : 0;
    const std::array<double, 3> spatial{s[first], s[first + 1], rank > 2 ? s[first + 2] : 1.0};
    check_spacing(path, "spacings", spatial, "spacings", 0);
    volume.spacing = glm::vec3(glm::dvec3(spatial[0], spatial[1], spatial[2]));
  }
  if (const auto text = header.get("space origin")) {
    const auto origin = vectors(path, "space origin", *text);
    if (origin.size() != 1 || !origin[0]) fail(path, "space origin: expected one vector");
    volume.origin = glm::vec3(to_lps(header) * vector_in_space(path, "space origin", *origin[0],
                                                               space_dimension(header, rank)));
  }
  check_geometry(path, "space origin", "space directions", volume);
}

namespace {

bool is_gzip_encoding(const TextHeader& header) {
  const std::string encoding = lowercase(header.require("encoding"));
  if (encoding == "raw") return false;
  if (encoding == "gzip" || encoding == "gz") return true;
  fail(header.path, concat("encoding '", encoding, "' is not supported (raw, gzip)"));
}

}  // namespace

bool volume_io::nrrd_big_endian(const TextHeader& header) {
  const auto endian = header.get("endian");
  if (!endian || lowercase(*endian) == "little") return false;
  if (lowercase(*endian) == "big") return true;
  fail(header.path, concat("endian '", *endian, "': expected little or big"));
}

namespace {

int64_t skip_field(const TextHeader& header, std::string_view field) {
  const auto text = header.get(field);
  return text ? parse_exactly<int64_t, 1>(header.path, field, *text)[0] : 0;
}

// Where the data starts in its file, before "byte skip" (which, for gzip, counts inflated bytes).
InputFile::Source data_source(const TextHeader& header, bool gzip) {
  const fs::path& path = header.path;
  InputFile::Source source{.file = path, .report_as = path, .compressed = gzip};
  if (const auto name = data_file(header)) {
    if (name->starts_with("LIST") || name->find_first_of("% ") != std::string_view::npos)
      fail(path, concat("data file: '", *name, "': file lists and patterns are not supported"));
    source.file = path.parent_path() / *name;
    source.what = concat("data file '", *name, "'");
    data_file_size(path, source.what, source.file);
  } else {
    source.what = "the data after the header";
    source.offset = header.data_offset;
  }
  const int64_t lines = skip_field(header, "line skip");
  if (lines < 0) fail(path, concat("line skip = ", lines, ": must not be negative"));
  if (lines > 0) {
    std::ifstream in(source.file, std::ios::binary);
    in.seekg(static_cast<std::streamoff>(source.offset));
    for (int64_t i = 0; i < lines && in; ++i)
      in.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
    source.offset = in ? static_cast<uint64_t>(in.tellg()) : fs::file_size(source.file);
  }
  return source;
}

}  // namespace

std::unique_ptr<InputFile> volume_io::open_nrrd_data(const TextHeader& header,
                                                     uint64_t data_bytes) {
  const fs::path& path = header.path;
  const bool gzip = is_gzip_encoding(header);
  InputFile::Source source = data_source(header, gzip);
  const int64_t byte_skip = skip_field(header, "byte skip");
  if (byte_skip < -1 || (byte_skip == -1 && gzip))
    fail(path, concat("byte skip = ", byte_skip, ": expected >= 0 (or -1 for raw data)"));
  if (byte_skip == -1) {  // the data (every frame) is at the end of the file
    const uint64_t size = fs::file_size(source.file);
    source.offset = size >= data_bytes ? size - data_bytes : 0;
  } else if (!gzip) {
    source.offset += static_cast<uint64_t>(byte_skip);
  }
  auto in = std::make_unique<InputFile>(std::move(source));
  if (gzip && !in->skip(static_cast<uint64_t>(byte_skip)))
    fail(path, concat("byte skip = ", byte_skip, ": past the end of the data"));
  return in;
}

Volume load_nrrd(const std::filesystem::path& path, const VolumeReadOptions& options,
                 std::vector<std::string>& warnings) {
  existing_file_size(path);
  const TextHeader header = read_nrrd_header(path);
  const NrrdAxes axes = nrrd_axes(header, false);
  const StoredType stored = element_type(header);
  const size_t bytes =
      checked_voxel_bytes(path, "sizes", axes.dims, stored_size(stored), options.limits);
  uint64_t all_frames_bytes = 0;
  if (__builtin_mul_overflow(uint64_t{bytes}, uint64_t(axes.count), &all_frames_bytes))
    fail(path, "sizes: voxel count overflows");
  const uint64_t frame = choose_frame(path, uint64_t(axes.count), options, warnings);

  Volume volume;
  volume.name = volume_name(path);
  volume.source = path;
  volume.dims = to_dims(axes.dims);
  set_nrrd_geometry(volume, header, axes);

  const auto in = open_nrrd_data(header, all_frames_bytes);
  skip_frames(*in, frame, bytes);
  read_voxels(*in, bytes, volume);
  finish_voxels(
      volume, {.stored = stored, .big_endian = nrrd_big_endian(header), .per_slice = {Rescale{}}});
  return volume;
}

}  // namespace strata

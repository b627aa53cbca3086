// MetaImage (ITK's MetaIO): a text header of "Key = Value" lines whose last line,
// ElementDataFile, names the raw data file or says LOCAL (.mha: the data follows the header).
// Geometry is taken as ITK writes it: LPS+ patient space, TransformMatrix holding the direction
// of i, then j, then k. NDims 2 is one slice; of NDims 4 (time last, as ITK writes it) one frame
// is read, the fourth entry of every per-axis field ignored.
#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>

#include <zlib.h>

#include "engine/core/atomic_file.h"
#include "engine/scene/io/volume_io.h"
#include "engine/scene/io/volume_loader.h"

namespace strata {
namespace {

using namespace volume_io;
namespace fs = std::filesystem;

TextHeader parse_header(const fs::path& path) {
  TextHeader header{.path = path};
  const std::string text = read_prefix(path, max_text_header_bytes);
  size_t pos = 0;
  for (int line_number = 1; pos < text.size(); ++line_number) {
    const auto [raw, complete] = next_line(text, pos);
    const std::string_view line = trim(raw);
    for (char c : line)
      if ((static_cast<unsigned char>(c) < 32 && c != '\t') || c == 127)
        fail(path, concat("not a MetaImage header: line ", line_number, " holds binary data"));
    if (line.empty()) continue;
    const size_t equals = line.find('=');
    if (equals == std::string_view::npos) {
      if (!complete) break;  // the header was cut inside this line
      if (header.fields.empty())
        fail(path, concat("not a MetaImage header: line ", line_number, " is not 'Key = Value'"));
      fail(path,
           concat("line ", line_number, ": expected 'Key = Value', got '", printable(line), "'"));
    }
    header.fields.emplace_back(lowercase(trim(line.substr(0, equals))),
                               std::string(trim(line.substr(equals + 1))));
    if (header.fields.back().first == "elementdatafile") {
      header.data_offset = pos;
      return header;
    }
  }
  fail(path, "header is truncated: no ElementDataFile line");
}

bool parse_bool(const fs::path& path, std::string_view field, std::string_view value) {
  const std::string v = lowercase(value);
  if (v == "true" || v == "1") return true;
  if (v == "false" || v == "0") return false;
  fail(path, concat(field, " = ", value, ": expected True or False"));
}

void check_image_kind(const TextHeader& header) {
  const fs::path& path = header.path;
  if (const auto type = header.get("ObjectType"); type && lowercase(*type) != "image")
    fail(path, concat("ObjectType = ", *type, ": only Image is supported"));
  if (const auto channels = header.get("ElementNumberOfChannels"); channels && *channels != "1")
    fail(path, concat("ElementNumberOfChannels = ", *channels, ": only 1 is supported"));
  if (const auto binary = header.get("BinaryData");
      binary && !parse_bool(path, "BinaryData", *binary))
    fail(path, "BinaryData = False: ASCII data is not supported");
}

StoredType element_type(const TextHeader& header) {
  const std::string_view name = header.require("ElementType");
  if (name == "MET_UCHAR") return StoredType::uint8;
  if (name == "MET_SHORT") return StoredType::int16;
  if (name == "MET_USHORT") return StoredType::uint16;
  if (name == "MET_FLOAT") return StoredType::float32;
  fail(header.path, concat("ElementType = ", name,
                           " is not supported (strata reads MET_UCHAR, MET_SHORT, MET_USHORT, "
                           "MET_FLOAT)"));
}

int dimensions(const TextHeader& header) {
  const std::string_view ndims = trim(header.require("NDims"));
  if (ndims != "2" && ndims != "3" && ndims != "4")
    fail(header.path, concat("NDims = ", ndims, ": expected 2, 3 or 4 (a 2-D, 3-D or 4-D image)"));
  return ndims[0] - '0';
}

// A per-axis field's n numbers (n = NDims, or NDims² for the matrix).
std::vector<float> numbers_of(const TextHeader& header, std::string_view field,
                              std::string_view text, size_t n) {
  std::vector<float> values = parse_numbers<float>(header.path, field, text);
  if (values.size() != n)
    fail(header.path,
         concat(field, ": expected ", n, " numbers, got '", printable(trim(text)), "'"));
  return values;
}

void set_geometry(Volume& volume, const TextHeader& header, int ndims) {
  const fs::path& path = header.path;
  const size_t n = size_t(ndims), spatial = std::min<size_t>(n, 3);
  if (const auto text = header.first_of({"ElementSpacing", "ElementSize"})) {
    const auto s = numbers_of(header, "ElementSpacing", *text, n);
    for (size_t axis = 0; axis < spatial; ++axis) volume.spacing[int(axis)] = s[axis];
    check_spacing(path, "ElementSpacing", {volume.spacing.x, volume.spacing.y, volume.spacing.z},
                  "ElementSpacing", 0);
  }
  if (const auto text = header.first_of({"Offset", "Position", "Origin"})) {
    const auto o = numbers_of(header, "Offset", *text, n);
    for (size_t axis = 0; axis < spatial; ++axis) volume.origin[int(axis)] = o[axis];
  }
  if (const auto text = header.first_of({"TransformMatrix", "Rotation", "Orientation"})) {
    const auto m = numbers_of(header, "TransformMatrix", *text, n * n);
    for (size_t axis = 0; axis < spatial; ++axis)
      for (size_t row = 0; row < spatial; ++row)
        volume.direction[int(axis)][int(row)] = m[n * axis + row];
  }
}

InputFile::Source data_source(const TextHeader& header, uint64_t bytes) {
  const fs::path& path = header.path;
  InputFile::Source source{.file = path, .report_as = path};
  if (const auto text = header.get("CompressedData"))
    source.compressed = parse_bool(path, "CompressedData", *text);
  if (const auto text = header.get("CompressedDataSize"); text && source.compressed)
    source.compressed_size = parse_exactly<uint64_t, 1>(path, "CompressedDataSize", *text)[0];

  const std::string name(header.require("ElementDataFile"));
  if (lowercase(name) == "local") {
    source.what = "the LOCAL data after the header";
    source.offset = header.data_offset;
    return source;
  }
  if (lowercase(name) == "list" || name.find('%') != std::string::npos)
    fail(path, concat("ElementDataFile = ", name, ": file lists and patterns are not supported"));
  source.file = path.parent_path() / name;
  source.what = concat("ElementDataFile '", name, "'");
  const uint64_t size = data_file_size(path, source.what, source.file);
  if (const auto text = header.get("HeaderSize")) {
    const int64_t skip = parse_exactly<int64_t, 1>(path, "HeaderSize", *text)[0];
    // -1 means "the data is at the end of the file, after a header of unknown size".
    if (skip == -1 && !source.compressed) source.offset = size >= bytes ? size - bytes : 0;
    if (skip > 0) source.offset = static_cast<uint64_t>(skip);
  }
  return source;
}

// ---- writing

std::string numbers(std::initializer_list<float> values) {
  std::string text;
  for (float v : values) {
    char buffer[32];
    // Shortest round-trip form: reading it back with from_chars gives the same float.
    const auto end = std::to_chars(buffer, buffer + sizeof buffer, v).ptr;
    if (!text.empty()) text += ' ';
    text.append(buffer, end);
  }
  return text;
}

const char* met_type(VoxelType type) {
  switch (type) {
    case VoxelType::uint8:
      return "MET_UCHAR";
    case VoxelType::int16:
      return "MET_SHORT";
    case VoxelType::uint16:
      return "MET_USHORT";
    case VoxelType::float32:
      return "MET_FLOAT";
  }
  return "MET_UCHAR";
}

std::string header_text(const Volume& v, bool compress, const std::string& data_file) {
  const glm::mat3& d = v.direction;
  const bool msb = std::endian::native == std::endian::big;
  return concat(
      "ObjectType = Image\nNDims = 3\nBinaryData = True\n",
      "BinaryDataByteOrderMSB = ", msb ? "True" : "False", "\n",
      "CompressedData = ", compress ? "True" : "False", "\n", "TransformMatrix = ",
      numbers({d[0][0], d[0][1], d[0][2], d[1][0], d[1][1], d[1][2], d[2][0], d[2][1], d[2][2]}),
      "\nOffset = ", numbers({v.origin.x, v.origin.y, v.origin.z}),
      "\nElementSpacing = ", numbers({v.spacing.x, v.spacing.y, v.spacing.z}),
      "\nDimSize = ", v.dims.x, " ", v.dims.y, " ", v.dims.z, "\nElementType = ", met_type(v.type),
      "\nElementDataFile = ", data_file, "\n");
}

// Streams the voxels through deflate (zlib format, as MetaIO writes) in 64 KiB pieces, so writing
// needs no second copy of the volume.
void write_deflated(AtomicFile& out, const std::vector<std::byte>& data, const fs::path& path) {
  z_stream z{};
  if (deflateInit(&z, Z_DEFAULT_COMPRESSION) != Z_OK) fail(path, "cannot start zlib");
  std::vector<unsigned char> buffer(1 << 16);
  size_t offset = 0;
  int flush = Z_NO_FLUSH;
  do {
    const size_t chunk = std::min<size_t>(data.size() - offset, size_t{1} << 30);
    z.next_in = reinterpret_cast<Bytef*>(const_cast<std::byte*>(data.data() + offset));
    z.avail_in = static_cast<uInt>(chunk);
    offset += chunk;
    flush = offset == data.size() ? Z_FINISH : Z_NO_FLUSH;
    do {
      z.next_out = buffer.data();
      z.avail_out = static_cast<uInt>(buffer.size());
      deflate(&z, flush);
      out.write(buffer.data(), buffer.size() - z.avail_out);
    } while (z.avail_out == 0);
  } while (flush != Z_FINISH);
  deflateEnd(&z);
}

void write_data(AtomicFile& out, const Volume& volume, bool compress, const fs::path& path) {
  if (compress) {
    write_deflated(out, volume.voxels, path);
  } else {
    out.write(volume.voxels.data(), volume.voxels.size());
  }
}

}  // namespace

Volume load_metaimage(const std::filesystem::path& path, const VolumeReadOptions& options,
                      std::vector<std::string>& warnings) {
  existing_file_size(path);
  const TextHeader header = parse_header(path);
  check_image_kind(header);
  const int ndims = dimensions(header);
  const StoredType stored = element_type(header);
  const std::string_view dim_text = header.require("DimSize");
  const auto sizes = parse_numbers<int64_t>(path, "DimSize", dim_text);
  if (sizes.size() != size_t(ndims))
    fail(path, concat("DimSize: expected ", ndims, " numbers (NDims = ", ndims, "), got '",
                      printable(trim(dim_text)), "'"));
  const std::array<int64_t, 3> dims{sizes[0], sizes[1], ndims > 2 ? sizes[2] : 1};
  const int64_t frames = ndims == 4 ? sizes[3] : 1;
  if (frames < 1) fail(path, concat("DimSize: the fourth size is ", frames, ": must be positive"));
  const size_t bytes =
      checked_voxel_bytes(path, "DimSize", dims, stored_size(stored), options.limits);
  uint64_t all_frames_bytes = 0;
  if (__builtin_mul_overflow(uint64_t{bytes}, uint64_t(frames), &all_frames_bytes))
    fail(path, "DimSize: voxel count overflows");
  const uint64_t frame = choose_frame(path, uint64_t(frames), options, warnings);

  Volume volume;
  volume.name = volume_name(path);
  volume.source = path;
  volume.dims = to_dims(dims);
  set_geometry(volume, header, ndims);
  if (ndims == 2)  // one slice: k is its normal
    volume.direction[2] = glm::normalize(glm::cross(volume.direction[0], volume.direction[1]));
  check_geometry(path, "Offset", "TransformMatrix", volume);
  bool big_endian = false;
  if (const auto msb = header.first_of({"BinaryDataByteOrderMSB", "ElementByteOrderMSB"}))
    big_endian = parse_bool(path, "BinaryDataByteOrderMSB", *msb);

  InputFile in(data_source(header, all_frames_bytes));
  skip_frames(in, frame, bytes);
  read_voxels(in, bytes, volume);
  finish_voxels(volume, {.stored = stored, .big_endian = big_endian, .per_slice = {Rescale{}}});
  return volume;
}

void write_metaimage(const std::filesystem::path& path, const Volume& volume, bool compress) {
  const std::string extension = lowercase(path.extension().string());
  if (extension != ".mha" && extension != ".mhd")
    fail(path, "write_metaimage: the extension must be .mha or .mhd");
  const size_t expected = volume.voxel_count() * voxel_size(volume.type);
  if (volume.voxels.size() != expected)
    fail(path, concat("write_metaimage: the volume holds ", volume.voxels.size(),
                      " bytes, its dims and type need ", expected));

  const bool local = extension == ".mha";
  const fs::path data_file =
      local ? path : path.parent_path() / (path.stem().string() + (compress ? ".zraw" : ".raw"));
  // Each file whole or not at all (atomic_file.h); a .mhd's data file first, so its header never
  // names a data file that is not there.
  AtomicFile header(path, "MetaImage");
  if (!local) {
    AtomicFile data(data_file, "MetaImage data");
    write_data(data, volume, compress, path);
    data.commit();
  }
  header.write(header_text(volume, compress, local ? "LOCAL" : data_file.filename().string()));
  if (local) write_data(header, volume, compress, path);
  header.commit();
}

}  // namespace strata

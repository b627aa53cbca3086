// The label table in a NIfTI header extension (segmentation.h). After the 348-byte (NIfTI-1) or
// 540-byte (NIfTI-2) header come 4 extender bytes; when the first is not 0, extensions follow up
// to vox_offset (to the file's end in a .hdr of a .hdr/.img pair), each an int32 esize (a multiple
// of 16 that counts its own 8 bytes), an int32 ecode and esize - 8 bytes of data, in the header's
// byte order. TotalSegmentator (through nibabel) writes its label table as code 0, a Caret-style
// XML document: <LabelTable><Label Key=".." Red=".." Green=".." Blue=".." Alpha="..">name</Label>.
// Only the header and its extensions are read, never the voxels.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>

#include <pugixml.hpp>

#include "engine/core/text_file.h"
#include "engine/scene/io/names_table_builder.h"
#include "engine/scene/io/volume_io.h"
#include "engine/scene/segmentation.h"

namespace strata {
namespace {

namespace fs = std::filesystem;
using volume_io::concat;
using volume_io::fail;

constexpr size_t kNifti1HeaderBytes = 348, kNifti2HeaderBytes = 540, kExtenderBytes = 4;

template <class T>
T field_at(std::string_view bytes, size_t offset, bool swap) {
  std::array<char, sizeof(T)> raw;
  std::memcpy(raw.data(), bytes.data() + offset, sizeof(T));
  if (swap) std::reverse(raw.begin(), raw.end());
  T value;
  std::memcpy(&value, raw.data(), sizeof(T));
  return value;
}

struct Layout {
  size_t header_bytes = kNifti1HeaderBytes;
  bool swap = false;
  // Where the extensions end: vox_offset in a single file, none for a .hdr (its file's end).
  std::optional<double> vox_offset;
};

// The header's size and byte order from sizeof_hdr (its first 4 bytes): 348 or 540, read either
// way.
Layout header_kind(std::string_view bytes, const fs::path& file) {
  if (bytes.size() < 4) fail(file, concat("header is truncated: ", bytes.size(), " bytes"));
  for (const bool swap : {false, true}) {
    const int32_t size = field_at<int32_t>(bytes, 0, swap);
    if (size == int32_t(kNifti1HeaderBytes) || size == int32_t(kNifti2HeaderBytes))
      return {.header_bytes = size_t(size), .swap = swap};
  }
  fail(file, concat("not a NIfTI file: sizeof_hdr is ", field_at<int32_t>(bytes, 0, false),
                    " (expected 348 or 540)"));
}

// The header's kind and the extensions' end, from bytes holding at least the header.
Layout read_layout(std::string_view bytes, const fs::path& file) {
  Layout layout = header_kind(bytes, file);
  if (bytes.size() < layout.header_bytes)
    fail(file,
         concat("header is truncated: ", bytes.size(), " of ", layout.header_bytes, " bytes"));
  const bool nifti1 = layout.header_bytes == kNifti1HeaderBytes;
  const std::string_view magic = bytes.substr(nifti1 ? 344 : 4, 3);
  if (magic == (nifti1 ? "n+1" : "n+2"))
    layout.vox_offset = nifti1 ? double(field_at<float>(bytes, 108, layout.swap))
                               : double(field_at<int64_t>(bytes, 168, layout.swap));
  return layout;
}

bool has_extensions(std::string_view bytes, const Layout& layout) {
  return bytes.size() >= layout.header_bytes + kExtenderBytes && bytes[layout.header_bytes] != 0;
}

// ---- the XML label table

// The first element called `name`, in document order (walked without recursion: the nesting
// depth is the file's to choose).
pugi::xml_node find_element(const pugi::xml_node& root, const char* name) {
  pugi::xml_node node = root.first_child();
  while (node) {
    if (node.type() == pugi::node_element && std::strcmp(node.name(), name) == 0) return node;
    if (node.first_child()) {
      node = node.first_child();
      continue;
    }
    while (node && !node.next_sibling() && node != root) node = node.parent();
    if (!node || node == root) break;
    node = node.next_sibling();
  }
  return {};
}

std::string element_text(const pugi::xml_node& element) {
  std::string text;
  for (const pugi::xml_node& child : element.children())
    if (child.type() == pugi::node_pcdata || child.type() == pugi::node_cdata)
      text += child.value();
  return std::string(volume_io::trim(text));
}

std::optional<glm::vec3> label_colour(const pugi::xml_node& label, const fs::path& file,
                                      const std::string& where) {
  std::array<float, 3> rgb{};
  const std::array<const char*, 3> names = {"Red", "Green", "Blue"};
  for (size_t i = 0; i < 3; ++i) {
    const pugi::xml_attribute attribute = label.attribute(names[i]);
    if (!attribute) return std::nullopt;
    const std::string_view text = volume_io::trim(attribute.value());
    double value = 0.0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (error != std::errc{} || end != text.data() + text.size() || text.empty() ||
        !(value >= 0.0 && value <= 1.0))
      names_table::fail(
          file, where,
          concat(names[i], " '", volume_io::printable(text), "' is not a number 0..1"));
    rgb[i] = float(value);
  }
  return glm::vec3(rgb[0], rgb[1], rgb[2]);
}

// The table an extension's data holds; none when it holds none. An XML document that mentions a
// LabelTable but does not parse is an error: it is a table, broken.
std::optional<NamesTable> label_table(std::string_view data, const fs::path& file, size_t index) {
  while (!data.empty() && (data.back() == '\0' || data.back() == ' ' || data.back() == '\n'))
    data.remove_suffix(1);  // writers pad the data to the 16-byte size with NULs or spaces
  if (data.find("<LabelTable") == std::string_view::npos) return std::nullopt;
  const std::string where = concat("extension ", index);
  pugi::xml_document document;
  const pugi::xml_parse_result parsed =
      document.load_buffer(data.data(), data.size(), pugi::parse_default, pugi::encoding_utf8);
  if (!parsed)
    names_table::fail(file, where,
                      concat("the label table's XML is malformed: ", parsed.description(),
                             " at byte ", parsed.offset));
  const pugi::xml_node table = find_element(document, "LabelTable");
  if (!table) return std::nullopt;
  names_table::TableBuilder builder{file, {}, {}};
  for (const pugi::xml_node& label : table.children("Label")) {
    const std::string_view key = volume_io::trim(label.attribute("Key").value());
    const auto value = names_table::parse_integer(key);
    if (!value)
      names_table::fail(file, where,
                        "a Label's Key '" + volume_io::printable(key) + "' is not an integer");
    const std::string at = concat(where, ": Label Key=\"", *value, "\"");
    builder.add(at, *value, element_text(label), label_colour(label, file, at));
  }
  if (builder.table.entries.empty())
    names_table::fail(file, where, "the LabelTable holds no Label elements");
  return builder.finish("NIfTI label table (TotalSegmentator)");
}

}  // namespace

std::optional<NamesTable> nifti_label_table_from_bytes(std::string_view bytes,
                                                       const std::filesystem::path& file) {
  const Layout layout = read_layout(bytes, file);
  if (!has_extensions(bytes, layout)) return std::nullopt;
  if (layout.vox_offset && !(*layout.vox_offset >= 0.0 && *layout.vox_offset < 0x1p62))
    fail(file, concat("vox_offset = ", *layout.vox_offset, ": not a byte offset"));
  const uint64_t end = layout.vox_offset ? uint64_t(*layout.vox_offset) : bytes.size();
  const char* end_name = layout.vox_offset ? "vox_offset" : "the file's end";
  uint64_t pos = layout.header_bytes + kExtenderBytes;
  // Fewer bytes than the smallest extension, or a zero esize and ecode, are padding before the
  // voxels, not an extension.
  for (size_t index = 1; end > pos && end - pos >= 16; ++index) {
    if (pos + 8 > bytes.size())
      fail(file, concat("extension ", index, ": the file ends at byte ", bytes.size(), ", before ",
                        end_name, " (", end, ")"));
    const int32_t esize = field_at<int32_t>(bytes, pos, layout.swap);
    const int32_t ecode = field_at<int32_t>(bytes, pos + 4, layout.swap);
    if (esize == 0 && ecode == 0) break;
    if (esize < 16 || esize % 16 != 0)
      fail(file, concat("extension ", index, ": esize = ", esize,
                        " is not a positive multiple of 16 (the chain is broken)"));
    if (pos + uint64_t(esize) > end)
      fail(file, concat("extension ", index, ": esize = ", esize, " at byte ", pos, " runs past ",
                        end_name, " (", end, ")"));
    if (pos + uint64_t(esize) > bytes.size())
      fail(file, concat("extension ", index, ": esize = ", esize, " at byte ", pos,
                        " runs past the file's end (", bytes.size(), " bytes)"));
    if (auto table = label_table(bytes.substr(pos + 8, size_t(esize) - 8), file, index))
      return table;
    pos += uint64_t(esize);
  }
  return std::nullopt;
}

std::optional<NamesTable> nifti_label_table(const std::filesystem::path& nifti) {
  volume_io::existing_file_size(nifti);
  volume_io::InputFile in({.file = nifti,
                           .report_as = nifti,
                           .what = "header extensions",
                           .compressed = volume_io::is_gzip_file(nifti)});
  std::string bytes;
  const auto read_to = [&](size_t size) {  // on to `size` bytes, or the data's end
    const size_t had = bytes.size();
    size = size_t(std::min<uint64_t>(size, had + in.max_remaining()));
    if (size <= had) return;
    bytes.resize(size);
    bytes.resize(had + in.read(reinterpret_cast<std::byte*>(bytes.data() + had), size - had));
  };
  read_to(kNifti1HeaderBytes + kExtenderBytes);
  if (header_kind(bytes, nifti).header_bytes == kNifti2HeaderBytes)
    read_to(kNifti2HeaderBytes + kExtenderBytes);
  if (bytes.size() < header_kind(bytes, nifti).header_bytes + kExtenderBytes)
    return nifti_label_table_from_bytes(bytes, nifti);
  const Layout full = read_layout(bytes, nifti);
  if (!has_extensions(bytes, full)) return std::nullopt;
  // Extensions are text and small; a vox_offset past this is a broken header, not a table.
  const double end = full.vox_offset ? *full.vox_offset : double(kMaxTextFileBytes);
  if (!(end >= 0.0 && end <= double(kMaxTextFileBytes)))
    fail(nifti, concat("vox_offset = ", end, ": more than ", kMaxTextFileBytes >> 20,
                       " MiB of header extensions, which strata does not read"));
  read_to(size_t(end));
  return nifti_label_table_from_bytes(bytes, nifti);
}

}  // namespace strata

#include "engine/scene/io/dicom_structure.h"

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <set>
#include <string>
#include <string_view>

#include "engine/scene/io/volume_io.h"

namespace strata::dicom {

using namespace volume_io;
namespace fs = std::filesystem;

Kind file_kind(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  char head[132] = {};
  in.read(head, sizeof head);
  const auto got = in.gcount();
  if (got == 132 && std::string_view(head + 128, 4) == "DICM") return Kind::part10;
  if (got >= 8 && head[0] == 0x08 && head[1] == 0x00) return Kind::bare;
  return Kind::other;
}

namespace {

// Walks a file's data elements and checks that each one fits in the file before GDCM reads it:
// Debian's GDCM is built with assertions on, and a file cut inside an element header makes it
// abort() rather than fail; a cut value is accepted silently ("Incomplete Pixel Data") and a lying
// length makes it allocate that much. Only headers are read; values are skipped by their length.
class StructureCheck {
 public:
  explicit StructureCheck(const fs::path& file) : file_(file), in_(file, std::ios::binary) {
    std::error_code error;
    size_ = fs::file_size(file, error);
    if (error || !in_) fail(file, "cannot open");
  }

  void run(Kind kind) {
    if (kind == Kind::bare) {  // no meta header: tell explicit from implicit VR by the VR's letters
      walk(0, size_, {.explicit_vr = is_vr(read_bytes(4, 2))}, 0, false);
      return;
    }
    const Syntax meta{.explicit_vr = true};
    uint64_t pos = 132;
    std::string transfer_syntax;
    while (pos < size_) {
      // The group first: the data set after the meta group may be implicit VR, whose header
      // must not be read by the meta group's explicit-VR rules.
      if (number(read_bytes(pos, 2), 0, 2, false) != 0x0002) break;
      const Header h = header_at(pos, meta);
      const uint64_t next = value_end(h, size_);
      if (h.element == 0x0010) transfer_syntax = read_bytes(h.value_start, size_t(h.length));
      pos = next;
    }
    if (pos >= size_) truncated("nothing follows the meta header");
    if (transfer_syntax.empty()) {  // no meta group after all: guess as for a bare data set
      walk(pos, size_, {.explicit_vr = pos + 6 <= size_ && is_vr(read_bytes(pos + 4, 2))}, 0,
           false);
      return;
    }
    walk(pos, size_, syntax_of(std::string(trim(transfer_syntax.c_str()))), 0, false);
  }

 private:
  struct Syntax {
    bool explicit_vr = true;
    bool big_endian = false;
  };
  struct Header {
    uint16_t group = 0, element = 0;
    std::string vr;
    uint64_t length = 0, value_start = 0;
    bool undefined_length() const { return length == 0xffffffff; }
    bool is(uint16_t g, uint16_t e) const { return group == g && element == e; }
  };

  Syntax syntax_of(const std::string& uid) {
    if (uid == "1.2.840.10008.1.2") return {.explicit_vr = false};
    if (uid == "1.2.840.10008.1.2.2") return {.explicit_vr = true, .big_endian = true};
    if (uid == "1.2.840.10008.1.2.1.99")
      fail(file_, "the deflated transfer syntax is not supported");
    return {};  // explicit VR little endian, also for every compressed pixel syntax
  }

  // DICOM PS3.5 table 6.2-1; the second set has a 2-byte reserved field and a 4-byte length.
  inline static const std::set<std::string> known_vrs = {
      "AE", "AS", "AT", "CS", "DA", "DS", "DT", "FD", "FL", "IS", "LO", "LT",
      "OB", "OD", "OF", "OL", "OV", "OW", "PN", "SH", "SL", "SQ", "SS", "ST",
      "SV", "TM", "UC", "UI", "UL", "UN", "UR", "US", "UT", "UV"};
  inline static const std::set<std::string> long_vrs = {"OB", "OD", "OF", "OL", "OV", "OW", "SQ",
                                                        "SV", "UC", "UN", "UR", "UT", "UV"};

  static bool is_vr(const std::string& vr) { return known_vrs.count(vr) > 0; }

  std::string read_bytes(uint64_t pos, size_t n) {
    if (pos + n > size_)
      truncated(concat("it ends after ", size_, " bytes, inside an element header at ", pos));
    std::string bytes(n, '\0');
    in_.seekg(static_cast<std::streamoff>(pos));
    in_.read(bytes.data(), static_cast<std::streamsize>(n));
    if (!in_) fail(file_, "cannot read");
    return bytes;
  }

  // Whether [pos, end) holds only zero bytes (read in blocks; false at the first other byte).
  bool zeros_from(uint64_t pos, uint64_t end) {
    if (number(read_bytes(pos, std::min<uint64_t>(4, end - pos)), 0,
               size_t(std::min<uint64_t>(4, end - pos)), false) != 0) {
      return false;
    }
    constexpr uint64_t kBlock = 1 << 16;
    for (uint64_t at = pos; at < end; at += kBlock) {
      const std::string block = read_bytes(at, size_t(std::min(kBlock, end - at)));
      if (block.find_first_not_of('\0') != std::string::npos) return false;
    }
    return true;
  }

  uint32_t number(const std::string& bytes, size_t at, size_t n, bool big_endian) const {
    uint32_t value = 0;
    for (size_t i = 0; i < n; ++i) {
      const auto byte = static_cast<unsigned char>(bytes[big_endian ? at + i : at + n - 1 - i]);
      value = (value << 8) | byte;
    }
    return value;
  }

  Header header_at(uint64_t pos, Syntax s) {
    const std::string head = read_bytes(pos, 8);
    Header h;
    h.group = static_cast<uint16_t>(number(head, 0, 2, s.big_endian));
    h.element = static_cast<uint16_t>(number(head, 2, 2, s.big_endian));
    h.value_start = pos + 8;
    if (h.group == 0xfffe || !s.explicit_vr) {  // items and implicit VR: a 4-byte length
      h.length = number(head, 4, 4, s.big_endian);
      return h;
    }
    h.vr = head.substr(4, 2);
    if (!is_vr(h.vr)) malformed(h, "has no valid VR");
    if (!long_vrs.count(h.vr)) {
      h.length = number(head, 6, 2, s.big_endian);
      return h;
    }
    h.length = number(read_bytes(pos + 8, 4), 0, 4, s.big_endian);
    h.value_start = pos + 12;
    return h;
  }

  uint64_t value_end(const Header& h, uint64_t end) {
    if (h.value_start + h.length > end)
      truncated(concat("element ", tag(h), " needs ", h.length, " bytes, ",
                       end > h.value_start ? end - h.value_start : 0, " remain"));
    return h.value_start + h.length;
  }

  // The elements in [pos, end); inside an undefined-length item, up to its delimitation item.
  uint64_t walk(uint64_t pos, uint64_t end, Syntax s, int depth, bool until_item_end) {
    if (depth > 32) fail(file_, "DICOM file is malformed: sequences nested too deeply");
    while (pos < end) {
      // Zero bytes after the last element (some writers pad files) end the data set.
      if (depth == 0 && zeros_from(pos, end)) return end;
      const Header h = header_at(pos, s);
      if (h.group == 0xfffe) {
        if (until_item_end && h.is(0xfffe, 0xe00d)) return h.value_start;
        malformed(h, "is an item tag outside a sequence");
      }
      if (h.undefined_length()) {
        // Undefined-length UN holds implicit VR data (DICOM CP-246); pixel data holds fragments.
        const Syntax inner = h.vr == "UN" ? Syntax{.explicit_vr = false} : s;
        pos = items(h.value_start, end, inner, depth + 1, h.is(0x7fe0, 0x0010), true);
        continue;
      }
      const uint64_t next = value_end(h, end);
      if (s.explicit_vr && h.vr == "SQ") items(h.value_start, next, s, depth + 1, false, false);
      pos = next;
    }
    if (until_item_end) truncated("an item has no delimitation item");
    return pos;
  }

  // The items of a sequence (or the fragments of encapsulated pixel data).
  uint64_t items(uint64_t pos, uint64_t end, Syntax s, int depth, bool fragments,
                 bool until_sequence_end) {
    while (pos < end) {
      const Header h = header_at(pos, s);
      if (until_sequence_end && h.is(0xfffe, 0xe0dd)) return h.value_start;
      if (!h.is(0xfffe, 0xe000)) malformed(h, "is not an item inside a sequence");
      if (h.undefined_length() && !fragments) {
        pos = walk(h.value_start, end, s, depth + 1, true);
        continue;
      }
      const uint64_t next = value_end(h, end);
      if (!fragments) walk(h.value_start, next, s, depth + 1, false);
      pos = next;
    }
    if (until_sequence_end) truncated("a sequence has no delimitation item");
    return pos;
  }

  static std::string tag(const Header& h) {
    char text[16];
    std::snprintf(text, sizeof text, "(%04x,%04x)", h.group, h.element);
    return text;
  }
  [[noreturn]] void truncated(const std::string& what) {
    fail(file_, "DICOM file is truncated: " + what);
  }
  [[noreturn]] void malformed(const Header& h, const char* what) {
    fail(file_, concat("DICOM file is malformed: element ", tag(h), " ", what));
  }

  fs::path file_;
  std::ifstream in_;
  uint64_t size_ = 0;
};

}  // namespace

void check_structure(const fs::path& file, Kind kind) {
  StructureCheck(file).run(kind);
}

}  // namespace strata::dicom

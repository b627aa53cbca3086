#include "frame/vector_picture.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>

#include "engine/core/atomic_file.h"
#include "engine/core/error.h"

namespace strata {

std::optional<VectorFormat> vector_format(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  if (extension == ".svg") return VectorFormat::svg;
  if (extension == ".pdf") return VectorFormat::pdf;
  return std::nullopt;
}

VectorPicture image_picture(uint32_t width, uint32_t height, std::span<const uint8_t> rgba) {
  if (rgba.size() != size_t{width} * height * 4) {
    throw Error("vector picture: " + std::to_string(rgba.size()) + " bytes is not a " +
                std::to_string(width) + "x" + std::to_string(height) + " rgba8 image");
  }
  VectorImage image{{0.0f, 0.0f}, {float(width), float(height)}, {width, height, {}}};
  image.pixels.pixels.assign(rgba.begin(), rgba.end());
  VectorPicture picture{width, height, {}};
  picture.groups.push_back({1.0f, {std::move(image)}});
  return picture;
}

namespace {

// A number as SVG reads it: at most three decimals, no trailing zeros.
std::string number(double v) {
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "%.3f", v);
  std::string s = buffer;
  s.erase(s.find_last_not_of('0') + 1);
  if (s.back() == '.') s.pop_back();
  return s == "-0" ? "0" : s;
}

std::string attribute(const char* name, double v) {
  return std::string(" ") + name + "=\"" + number(v) + "\"";
}

// ` fill="#rrggbb" fill-opacity="a"` (or `stroke`), `fill="none"` for a transparent colour.
std::string paint(const std::string& what, glm::vec4 color) {
  if (!(color.a > 0.0f)) return " " + what + "=\"none\"";
  const glm::ivec3 c = glm::ivec3(glm::round(glm::clamp(glm::vec3(color), 0.0f, 1.0f) * 255.0f));
  char hex[8];
  std::snprintf(hex, sizeof hex, "#%02x%02x%02x", unsigned(c.r), unsigned(c.g), unsigned(c.b));
  std::string s = " " + what + "=\"" + hex + "\"";
  if (color.a < 1.0f) s += attribute((what + "-opacity").c_str(), color.a);
  return s;
}

std::string base64(std::span<const uint8_t> bytes) {
  static constexpr char kDigits[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const size_t n = std::min<size_t>(3, bytes.size() - i);
    uint32_t v = uint32_t(bytes[i]) << 16;
    if (n > 1) v |= uint32_t(bytes[i + 1]) << 8;
    if (n > 2) v |= bytes[i + 2];
    for (size_t k = 0; k < 4; ++k) out += k <= n ? kDigits[(v >> (18 - 6 * k)) & 63u] : '=';
  }
  return out;
}

// Text as XML character data or an attribute value: markup characters escaped, and characters
// XML 1.0 does not allow (controls but tab and newline, U+FFFE, U+FFFF) as U+FFFD.
std::string xml_text(std::u32string text) {
  for (char32_t& c : text) {
    const bool allowed = c == 0x9 || c == 0xA || c == 0xD ||
                         (c >= 0x20 && c < 0xFFFE && !(c >= 0xD800 && c <= 0xDFFF)) ||
                         (c >= 0x10000 && c <= 0x10FFFF);
    if (!allowed) c = 0xFFFD;
  }
  std::string out;
  for (const char ch : encode_utf8(text)) {
    switch (ch) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += ch;
    }
  }
  return out;
}

std::string svg_image(const VectorImage& image) {
  const Rgba8Image& p = image.pixels;
  return "<image" + attribute("x", image.origin.x) + attribute("y", image.origin.y) +
         attribute("width", image.size.x) + attribute("height", image.size.y) +
         " preserveAspectRatio=\"none\" xlink:href=\"data:image/png;base64," +
         base64(encode_png(p.width, p.height, p.pixels)) + "\"/>\n";
}

std::string svg_shape(const VectorShape& s) {
  std::string out;
  switch (s.kind) {
    case VectorShape::Kind::line:
      out = "<line" + attribute("x1", s.a.x) + attribute("y1", s.a.y) + attribute("x2", s.b.x) +
            attribute("y2", s.b.y);
      break;
    case VectorShape::Kind::box:
      out = "<rect" + attribute("x", s.a.x) + attribute("y", s.a.y) + attribute("width", s.b.x) +
            attribute("height", s.b.y) + attribute("rx", s.corner);
      break;
    case VectorShape::Kind::circle:
      out = "<circle" + attribute("cx", s.a.x) + attribute("cy", s.a.y) + attribute("r", s.b.x);
      break;
  }
  out += paint("fill", s.fill) + paint("stroke", s.stroke);
  if (s.stroke.a > 0.0f) out += attribute("stroke-width", s.stroke_width);
  if (s.round_caps) out += " stroke-linecap=\"round\"";
  if (s.dash.x > 0.0f) {
    out += " stroke-dasharray=\"" + number(s.dash.x) + " " + number(s.dash.y) + "\"";
    if (s.dash_offset != 0.0f) out += attribute("stroke-dashoffset", s.dash_offset);
  }
  return out + "/>\n";
}

// The faces of the font as a CSS family list, main face first: the renderer takes a character
// the main face lacks from the next that has it, as the label font does.
std::string font_families(const Font& font) {
  std::string out;
  for (size_t f = 0; f < font.face_count(); ++f) {
    const std::string name = font.family_name(f);
    if (name.empty() || name.find('\'') != std::string::npos) continue;
    if (out.find("'" + name + "'") != std::string::npos) continue;
    out += (out.empty() ? "'" : ", '") + name + "'";
  }
  return xml_text(decode_utf8(out.empty() ? "sans-serif" : out));
}

// One <text> per line, anchored at its middle: where the line's advance as the SVG renderer
// shapes it is the label font's, its ink lies where the raster's does, in either direction.
std::string svg_text(const VectorText& t) {
  const glm::vec2 middle = t.origin + glm::vec2(0.5f * t.line.advance, 0.0f);
  std::string out = "<text" + attribute("x", middle.x) + attribute("y", middle.y) +
                    " font-family=\"" + font_families(*t.font) + "\" font-size=\"" +
                    number(t.font->em_pixels()) + "px\"" + paint("fill", t.color) +
                    " text-anchor=\"middle\" xml:space=\"preserve\"";
  if (t.line.right_to_left) out += " direction=\"rtl\" unicode-bidi=\"embed\"";
  return out + ">" + xml_text(t.line.text) + "</text>\n";
}

}  // namespace

std::string svg_document(const VectorPicture& picture) {
  const std::string w = number(picture.width), h = number(picture.height);
  std::string out =
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      "<svg xmlns=\"http://www.w3.org/2000/svg\" xmlns:xlink=\"http://www.w3.org/1999/xlink\" "
      "width=\"" +
      w + "\" height=\"" + h + "\" viewBox=\"0 0 " + w + " " + h + "\">\n";
  for (const VectorGroup& group : picture.groups) {
    const bool grouped = group.opacity < 1.0f;
    if (grouped) out += "<g" + attribute("opacity", group.opacity) + ">\n";
    for (const VectorItem& item : group.items) {
      if (const auto* image = std::get_if<VectorImage>(&item)) out += svg_image(*image);
      if (const auto* shape = std::get_if<VectorShape>(&item)) out += svg_shape(*shape);
      if (const auto* text = std::get_if<VectorText>(&item)) out += svg_text(*text);
    }
    if (grouped) out += "</g>\n";
  }
  return out + "</svg>\n";
}

void write_vector_picture(const std::filesystem::path& path, const VectorPicture& picture) {
  const std::optional<VectorFormat> format = vector_format(path);
  if (!format) throw Error(path.string() + ": not an .svg or .pdf file");
  std::string bytes;
  try {
    bytes = *format == VectorFormat::svg ? svg_document(picture) : pdf_document(picture);
  } catch (const Error& e) {
    throw Error(path.string() + ": " + e.what());
  }
  write_file_atomically(path, bytes, *format == VectorFormat::svg ? "SVG" : "PDF");
}

}  // namespace strata

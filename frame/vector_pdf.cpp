// VectorPicture as PDF through cairo: a page of width x height points (a point a pixel), the text
// drawn with the label font's own faces (cairo-ft) and the characters each glyph draws
// (cairo_show_text_glyphs), so a PDF reader finds and copies the label's text as written.
#include <map>

#include <cairo-ft.h>
#include <cairo-pdf.h>
#include <cairo.h>

#include "engine/core/error.h"
#include "frame/vector_picture.h"

namespace strata {
namespace {

// Straight-alpha rgba8 as cairo's premultiplied native-endian ARGB32.
cairo_surface_t* image_surface(const Rgba8Image& image) {
  cairo_surface_t* surface =
      cairo_image_surface_create(CAIRO_FORMAT_ARGB32, int(image.width), int(image.height));
  cairo_surface_flush(surface);
  unsigned char* data = cairo_image_surface_get_data(surface);
  const int stride = cairo_image_surface_get_stride(surface);
  for (uint32_t y = 0; y < image.height; ++y) {
    auto* row = reinterpret_cast<uint32_t*>(data + ptrdiff_t(y) * stride);
    for (uint32_t x = 0; x < image.width; ++x) {
      const uint8_t* p = &image.pixels[(size_t(y) * image.width + x) * 4];
      const auto premultiplied = [&](int c) { return (uint32_t(p[c]) * p[3] + 127) / 255; };
      row[x] =
          uint32_t(p[3]) << 24 | premultiplied(0) << 16 | premultiplied(1) << 8 | premultiplied(2);
    }
  }
  cairo_surface_mark_dirty(surface);
  return surface;
}

void draw_image(cairo_t* cr, const VectorImage& image) {
  if (image.pixels.width == 0 || image.pixels.height == 0) return;
  cairo_surface_t* surface = image_surface(image.pixels);
  cairo_save(cr);
  cairo_translate(cr, image.origin.x, image.origin.y);
  cairo_scale(cr, double(image.size.x) / image.pixels.width,
              double(image.size.y) / image.pixels.height);
  cairo_set_source_surface(cr, surface, 0.0, 0.0);
  cairo_paint(cr);
  cairo_restore(cr);
  cairo_surface_destroy(surface);
}

void set_color(cairo_t* cr, glm::vec4 c) {
  cairo_set_source_rgba(cr, c.r, c.g, c.b, c.a);
}

void shape_path(cairo_t* cr, const VectorShape& s) {
  constexpr double kQuarter = 1.5707963267948966;
  cairo_new_path(cr);
  switch (s.kind) {
    case VectorShape::Kind::line:
      cairo_move_to(cr, s.a.x, s.a.y);
      cairo_line_to(cr, s.b.x, s.b.y);
      break;
    case VectorShape::Kind::box: {
      const double r = std::min({double(s.corner), 0.5 * s.b.x, 0.5 * s.b.y});
      const double x0 = s.a.x, y0 = s.a.y, x1 = s.a.x + s.b.x, y1 = s.a.y + s.b.y;
      cairo_arc(cr, x1 - r, y0 + r, r, -kQuarter, 0.0);
      cairo_arc(cr, x1 - r, y1 - r, r, 0.0, kQuarter);
      cairo_arc(cr, x0 + r, y1 - r, r, kQuarter, 2.0 * kQuarter);
      cairo_arc(cr, x0 + r, y0 + r, r, 2.0 * kQuarter, 3.0 * kQuarter);
      cairo_close_path(cr);
      break;
    }
    case VectorShape::Kind::circle:
      cairo_arc(cr, s.a.x, s.a.y, s.b.x, 0.0, 4.0 * kQuarter);
      cairo_close_path(cr);
      break;
  }
}

void draw_shape(cairo_t* cr, const VectorShape& s) {
  shape_path(cr, s);
  if (s.fill.a > 0.0f && s.kind != VectorShape::Kind::line) {
    set_color(cr, s.fill);
    cairo_fill_preserve(cr);
  }
  if (s.stroke.a > 0.0f) {
    set_color(cr, s.stroke);
    cairo_set_line_width(cr, s.stroke_width);
    cairo_set_line_cap(cr, s.round_caps ? CAIRO_LINE_CAP_ROUND : CAIRO_LINE_CAP_BUTT);
    const double dashes[2] = {s.dash.x, s.dash.y};
    cairo_set_dash(cr, dashes, s.dash.x > 0.0f ? 2 : 0, s.dash_offset);
    cairo_stroke_preserve(cr);
  }
  cairo_new_path(cr);
}

// The cairo faces of a document, one per label font face drawn.
class Faces {
 public:
  ~Faces() {
    for (auto& [face, cairo_face] : faces_) cairo_font_face_destroy(cairo_face);
  }
  cairo_font_face_t* of(const Font& font, uint32_t index) {
    FT_Face face = font.face(index);
    auto found = faces_.find(face);
    if (found == faces_.end()) {
      found = faces_.emplace(face, cairo_ft_font_face_create_for_ft_face(face, 0)).first;
    }
    return found->second;
  }

 private:
  std::map<FT_Face, cairo_font_face_t*> faces_;
};

// A run of a line (one face, one direction) with the characters each glyph draws (clusters in
// logical order: backwards in a right-to-left run), so a reader extracts the text from the
// glyphs in visual order, as PDF text is read. The glyphs stand where the font shaped them, not
// on the raster's whole pixels (at most half a pixel away): readers take a gap that rounding
// widens for a space between words.
void draw_run(cairo_t* cr, const VectorText& t, const ShapedRun& run) {
  const ShapedLine& line = t.line;
  std::vector<cairo_glyph_t> glyphs;
  for (size_t g = run.first_glyph; g < run.first_glyph + run.glyph_count; ++g) {
    const glm::vec2 at = t.origin + line.glyphs[g].pen;
    glyphs.push_back({line.glyphs[g].key.glyph, at.x, at.y});
  }
  std::vector<cairo_text_cluster_t> clusters;
  std::string utf8;
  const size_t n = run.glyph_count;
  const auto logical = [&](size_t i) -> const ShapedGlyph& {
    return line.glyphs[run.first_glyph + (run.right_to_left ? n - 1 - i : i)];
  };
  for (size_t k = 0; k < n;) {
    const uint32_t cluster = logical(k).cluster;
    size_t next = k;
    while (next < n && logical(next).cluster == cluster) ++next;
    const size_t end = next < n ? logical(next).cluster : run.first_char + run.char_count;
    const std::string chars =
        cluster < end && end <= line.text.size()
            ? encode_utf8(std::u32string_view(line.text).substr(cluster, end - cluster))
            : std::string();
    clusters.push_back({int(chars.size()), int(next - k)});
    utf8 += chars;
    k = next;
  }
  const auto flags =
      run.right_to_left ? CAIRO_TEXT_CLUSTER_FLAG_BACKWARD : cairo_text_cluster_flags_t(0);
  cairo_show_text_glyphs(cr, utf8.data(), int(utf8.size()), glyphs.data(), int(glyphs.size()),
                         clusters.data(), int(clusters.size()), flags);
}

void draw_text(cairo_t* cr, Faces& faces, const VectorText& t) {
  set_color(cr, t.color);
  for (const ShapedRun& run : t.line.runs) {
    if (run.glyph_count == 0) continue;
    cairo_set_font_face(cr, faces.of(*t.font, t.line.glyphs[run.first_glyph].key.face));
    cairo_set_font_size(cr, t.font->em_pixels());
    draw_run(cr, t, run);
  }
}

cairo_status_t append(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

}  // namespace

std::string pdf_document(const VectorPicture& picture) {
  std::string bytes;
  cairo_surface_t* surface =
      cairo_pdf_surface_create_for_stream(append, &bytes, picture.width, picture.height);
  cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_CREATOR, "strata");
  cairo_t* cr = cairo_create(surface);
  {
    Faces faces;
    for (const VectorGroup& group : picture.groups) {
      const bool grouped = group.opacity < 1.0f;
      if (grouped) cairo_push_group(cr);
      for (const VectorItem& item : group.items) {
        if (const auto* image = std::get_if<VectorImage>(&item)) draw_image(cr, *image);
        if (const auto* shape = std::get_if<VectorShape>(&item)) draw_shape(cr, *shape);
        if (const auto* text = std::get_if<VectorText>(&item)) draw_text(cr, faces, *text);
      }
      if (grouped) {
        cairo_pop_group_to_source(cr);
        cairo_paint_with_alpha(cr, group.opacity);
      }
    }
    cairo_destroy(cr);
    cairo_surface_finish(surface);
  }
  const cairo_status_t status = cairo_surface_status(surface);
  cairo_surface_destroy(surface);
  if (status != CAIRO_STATUS_SUCCESS)
    throw Error(std::string("cannot write PDF: ") + cairo_status_to_string(status));
  return bytes;
}

}  // namespace strata

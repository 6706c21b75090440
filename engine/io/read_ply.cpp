/// \file read_ply.cpp
/// PLY (ascii, binary_little_endian, binary_big_endian): any elements and properties; the vertex
/// element's x/y/z (any numeric type) and the face element's index list (any count/index types)
/// are kept, everything else is skipped.

#include <cstdio>
#include <string>
#include <vector>

#include "io/parse_util.h"
#include "io/soup.h"

namespace remesh::io {

namespace {

enum class Type { I8, U8, I16, U16, I32, U32, F32, F64 };

struct Property {
  std::string name;
  Type type = Type::F32;
  bool list = false;
  Type count_type = Type::U8;
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> props;
};

std::size_t size_of(Type t) {
  switch (t) {
    case Type::I8: case Type::U8: return 1;
    case Type::I16: case Type::U16: return 2;
    case Type::I32: case Type::U32: case Type::F32: return 4;
    case Type::F64: return 8;
  }
  return 1;
}

bool parse_type(std::string_view s, Type& t) {
  static const std::pair<const char*, Type> names[] = {
      {"char", Type::I8},   {"int8", Type::I8},     {"uchar", Type::U8},   {"uint8", Type::U8},
      {"short", Type::I16}, {"int16", Type::I16},   {"ushort", Type::U16}, {"uint16", Type::U16},
      {"int", Type::I32},   {"int32", Type::I32},   {"uint", Type::U32},   {"uint32", Type::U32},
      {"float", Type::F32}, {"float32", Type::F32}, {"double", Type::F64}, {"float64", Type::F64}};
  for (const auto& [n, v] : names)
    if (s == n) { t = v; return true; }
  return false;
}

[[noreturn]] void fail_header(std::size_t line, const std::string& what) {
  fail("PLY header line " + std::to_string(line) + ": " + what);
}

enum class Encoding { Ascii, Little, Big };

struct Header {
  Encoding encoding = Encoding::Ascii;
  std::vector<Element> elements;
  std::size_t data_start = 0;
  std::size_t data_line = 0;  ///< line number of the last header line (ascii body counts on)
};

Header parse_header(std::string_view bytes) {
  Header h;
  LineScanner lines(bytes);
  std::string_view line, tok;
  if (!lines.next(line) || line != "ply") fail("PLY: the file does not start with 'ply'");
  bool have_format = false;
  while (true) {
    if (!lines.next(line)) fail("PLY: header has no end_header line");
    std::string_view rest = line;
    if (!next_token(rest, tok)) continue;
    const std::size_t ln = lines.line_number();
    if (tok == "end_header") break;
    if (tok == "comment" || tok == "obj_info") continue;
    if (tok == "format") {
      std::string_view enc;
      next_token(rest, enc);
      if (enc == "ascii") h.encoding = Encoding::Ascii;
      else if (enc == "binary_little_endian") h.encoding = Encoding::Little;
      else if (enc == "binary_big_endian") h.encoding = Encoding::Big;
      else fail_header(ln, "unknown format " + quote(enc));
      have_format = true;
    } else if (tok == "element") {
      Element e;
      std::string_view name, count;
      std::int64_t n = 0;
      if (!next_token(rest, name) || !next_token(rest, count) || !parse_int(count, n) || n < 0)
        fail_header(ln, "bad element line (expected 'element NAME COUNT')");
      e.name = name;
      e.count = static_cast<std::uint64_t>(n);
      h.elements.push_back(std::move(e));
    } else if (tok == "property") {
      if (h.elements.empty()) fail_header(ln, "property before any element");
      Property p;
      std::string_view type, name;
      if (!next_token(rest, type)) fail_header(ln, "bad property line");
      if (type == "list") {
        std::string_view ct, it;
        p.list = true;
        if (!next_token(rest, ct) || !parse_type(ct, p.count_type) || !next_token(rest, it) ||
            !parse_type(it, p.type))
          fail_header(ln, "bad list property types");
        if (p.count_type == Type::F32 || p.count_type == Type::F64)
          fail_header(ln, "list count type must be an integer type");
      } else if (!parse_type(type, p.type)) {
        fail_header(ln, "unknown property type " + quote(type));
      }
      if (!next_token(rest, name)) fail_header(ln, "property without a name");
      p.name = name;
      h.elements.back().props.push_back(std::move(p));
    } else {
      fail_header(ln, "unknown keyword " + quote(tok));
    }
  }
  if (!have_format) fail("PLY: header has no format line");
  h.data_start = lines.position();
  h.data_line = lines.line_number();
  return h;
}

/// Where x, y, z and the face index list are in their elements.
struct Layout {
  int vertex_element = -1, face_element = -1;
  int xyz[3] = {-1, -1, -1};
  int face_list = -1;
};

Layout find_layout(const Header& h) {
  Layout l;
  for (std::size_t e = 0; e < h.elements.size(); ++e) {
    const Element& el = h.elements[e];
    if (el.name == "vertex" && l.vertex_element < 0) {
      l.vertex_element = static_cast<int>(e);
      for (std::size_t p = 0; p < el.props.size(); ++p)
        for (int k = 0; k < 3; ++k)
          if (!el.props[p].list && el.props[p].name == std::string(1, static_cast<char>('x' + k)))
            l.xyz[k] = static_cast<int>(p);
    } else if (el.name == "face" && l.face_element < 0) {
      l.face_element = static_cast<int>(e);
      for (std::size_t p = 0; p < el.props.size(); ++p) {
        const Property& pr = el.props[p];
        if (!pr.list) continue;
        if (pr.name == "vertex_indices" || pr.name == "vertex_index") { l.face_list = static_cast<int>(p); break; }
        if (l.face_list < 0) l.face_list = static_cast<int>(p);
      }
    }
  }
  if (l.vertex_element < 0) fail("PLY: no 'vertex' element");
  if (l.xyz[0] < 0 || l.xyz[1] < 0 || l.xyz[2] < 0) fail("PLY: the vertex element lacks x, y or z");
  if (l.face_element < 0) fail("PLY: no 'face' element (a point cloud has no surface to remesh)");
  if (l.face_list < 0) fail("PLY: the face element has no vertex index list");
  return l;
}

/// Smallest number of bytes one element can take (binary: exact fixed part; ascii: one char per value).
std::uint64_t min_bytes(const Element& e, bool binary) {
  std::uint64_t n = 0;
  for (const Property& p : e.props) n += binary ? size_of(p.list ? p.count_type : p.type) : 2;
  return n == 0 ? 1 : n;
}

double read_binary(ByteReader& r, Type t, bool big) {
  switch (t) {
    case Type::I8: return r.read<std::int8_t>(big);
    case Type::U8: return r.read<std::uint8_t>(big);
    case Type::I16: return r.read<std::int16_t>(big);
    case Type::U16: return r.read<std::uint16_t>(big);
    case Type::I32: return r.read<std::int32_t>(big);
    case Type::U32: return r.read<std::uint32_t>(big);
    case Type::F32: return r.read<float>(big);
    case Type::F64: return r.read<double>(big);
  }
  return 0;
}

/// An element instance, named only when an error needs it.
struct Where {
  const std::string& element;
  std::uint64_t index;
  std::string str() const { return element + " " + std::to_string(index); }
};

/// Walks the body element by element, handing each value to the sink.
class BodyReader {
 public:
  BodyReader(std::string_view bytes, const Header& h) : h_(h), bin_(bytes, h.data_start), text_(bytes), pos_(h.data_start), line_(h.data_line + 1) {}

  std::size_t remaining() const { return h_.encoding == Encoding::Ascii ? text_.size() - pos_ : bin_.remaining(); }
  std::size_t line() const { return line_; }
  bool ascii() const { return h_.encoding == Encoding::Ascii; }

  /// One scalar of type t; `what` names it for errors.
  double scalar(Type t, const Where& where) {
    if (!ascii()) {
      if (!bin_.has(size_of(t))) fail("PLY: file truncated in " + where.str());
      return read_binary(bin_, t, h_.encoding == Encoding::Big);
    }
    std::string_view tok = token(where);
    double v = 0;
    if (!parse_double(tok, v))
      fail("PLY line " + std::to_string(line_) + ": bad number " + quote(tok) + " in " + where.str() +
           too_large_note(tok));
    return v;
  }
  /// Line of the next ascii token (after skipping whitespace), for locations.
  std::uint32_t peek_line() {
    if (!ascii()) return 0;
    skip_space();
    return static_cast<std::uint32_t>(line_);
  }

 private:
  void skip_space() {
    while (pos_ < text_.size() && (is_space(text_[pos_]) || text_[pos_] == '\n')) {
      if (text_[pos_] == '\n') ++line_;
      ++pos_;
    }
  }
  std::string_view token(const Where& where) {
    skip_space();
    if (pos_ >= text_.size()) fail("PLY: file ends early, in " + where.str());
    std::size_t start = pos_;
    while (pos_ < text_.size() && !is_space(text_[pos_]) && text_[pos_] != '\n') ++pos_;
    return text_.substr(start, pos_ - start);
  }

  const Header& h_;
  ByteReader bin_;
  std::string_view text_;
  std::size_t pos_;
  std::size_t line_;
};

bool is_integer(double v, double limit) { return v >= -limit && v <= limit && v == std::floor(v); }

/// A number read from the file, for a message: %g, not std::to_string's fixed notation (an index of
/// 1e300 came out as 301 digits).
std::string number_text(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", v);
  return text;
}

std::int64_t as_count(double v, std::size_t max_items, const Where& where, BodyReader& body) {
  if (!is_integer(v, 1e15) || v < 0 || v > static_cast<double>(max_items))
    fail("PLY" + (body.ascii() ? " line " + std::to_string(body.line()) : std::string()) + ": bad list length " +
         number_text(v) + " in " + where.str() + " (negative, fractional or past the end of the file)");
  return static_cast<std::int64_t>(v);
}

}  // namespace

RawSoup read_ply(std::string_view bytes, const ReadOptions& options) {
  const Header h = parse_header(bytes);
  const Layout layout = find_layout(h);
  const bool binary = h.encoding != Encoding::Ascii;
  // Counts the bytes cannot hold are checked before the face limit: a small file claiming a billion
  // faces is malformed (truncated or not PLY), not too large.
  {
    const std::uint64_t left = bytes.size() - h.data_start;
    std::uint64_t need = 0;
    for (const Element& e : h.elements) {
      const std::uint64_t per = min_bytes(e, binary);
      if (e.count > (left + 2) / per || need + e.count * per > left + 2)
        fail("PLY header claims " + std::to_string(e.count) + " '" + e.name + "' elements, but only " +
             std::to_string(left) + " bytes follow (file truncated?)");
      need += e.count * per;
    }
  }
  check_face_limit(h.elements[static_cast<std::size_t>(layout.face_element)].count, options, "PLY");
  RawSoup soup;
  BodyReader body(bytes, h);
  for (std::size_t e = 0; e < h.elements.size(); ++e) {
    const Element& el = h.elements[e];
    const bool is_vertex = static_cast<int>(e) == layout.vertex_element;
    const bool is_face = static_cast<int>(e) == layout.face_element;
    if (is_vertex) { soup.points.reserve(el.count); if (!binary) soup.point_lines.reserve(el.count); }
    if (is_face) soup.offsets.reserve(el.count + 1);
    for (std::uint64_t i = 0; i < el.count; ++i) {
      const Where what{el.name, i};
      double xyz[3] = {0, 0, 0};
      if (is_vertex && !binary) soup.point_lines.push_back(body.peek_line());
      if (is_face && !binary) soup.face_lines.push_back(body.peek_line());
      for (std::size_t p = 0; p < el.props.size(); ++p) {
        const Property& pr = el.props[p];
        if (!pr.list) {
          double v = body.scalar(pr.type, what);
          if (is_vertex)
            for (int k = 0; k < 3; ++k)
              if (layout.xyz[k] == static_cast<int>(p)) xyz[k] = v;
          continue;
        }
        const std::size_t item = binary ? size_of(pr.type) : 2;
        const std::int64_t n = as_count(body.scalar(pr.count_type, what), body.remaining() / item, what, body);
        const bool keep = is_face && layout.face_list == static_cast<int>(p);
        for (std::int64_t k = 0; k < n; ++k) {
          double v = body.scalar(pr.type, what);
          if (!keep) continue;
          if (!is_integer(v, 1e15))
            fail("PLY: face " + std::to_string(i) + " has a non-integer vertex index " + number_text(v));
          soup.indices.push_back(static_cast<std::int64_t>(v));
        }
        if (keep) soup.offsets.push_back(static_cast<std::uint32_t>(soup.indices.size()));
      }
      if (is_vertex) soup.points.emplace_back(xyz[0], xyz[1], xyz[2]);
    }
  }
  return soup;
}

}  // namespace remesh::io

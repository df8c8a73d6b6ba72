/// \file mesh_scan_ply.cpp
/// PLY pre-pass (see mesh_scan.h): parse the header, then walk every element
/// and property of the body, text tokens or binary bytes, checking that the
/// file holds exactly what the header declares.

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

#include "bsprt/error.h"
#include "geometry/io/mesh_scan.h"
#include "geometry/io/mesh_scan_util.h"

namespace bsprt::detail {
namespace {

struct PlyType {
  int size = 0;          ///< bytes in binary files
  bool floating = false;
  bool is_signed = false;
};

bool ply_type(std::string_view name, PlyType& t) {
  static const struct { const char* name; PlyType type; } table[] = {
      {"char", {1, false, true}},   {"int8", {1, false, true}},     {"uchar", {1, false, false}},
      {"uint8", {1, false, false}}, {"short", {2, false, true}},    {"int16", {2, false, true}},
      {"ushort", {2, false, false}}, {"uint16", {2, false, false}}, {"int", {4, false, true}},
      {"int32", {4, false, true}},  {"uint", {4, false, false}},    {"uint32", {4, false, false}},
      {"float", {4, true, true}},   {"float32", {4, true, true}},   {"double", {8, true, true}},
      {"float64", {8, true, true}}};
  for (const auto& e : table)
    if (name == e.name) { t = e.type; return true; }
  return false;
}

struct PlyProperty {
  std::string name;
  PlyType type;
  bool list = false;
  PlyType count_type;
  int axis = -1;           ///< 0..2 for x, y, z of the vertex element
  bool indices = false;    ///< vertex_indices of the face element
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> props;
  std::int64_t line = 0;
};

enum class PlyFormat { ascii, binary_le, binary_be };

struct PlyHeader {
  PlyFormat format = PlyFormat::ascii;
  std::string format_name;
  std::vector<PlyElement> elements;
  std::size_t body = 0;            ///< byte offset of the first body byte
  std::int64_t body_line = 0;      ///< line number of the first body line (ascii)
};

void add_property(const std::string& path, std::int64_t no, std::string_view line, std::size_t i, PlyElement& e) {
  PlyProperty p;
  std::string_view t = next_token(line, i);
  std::string_view count_name;
  if (t == "list") {
    p.list = true;
    count_name = next_token(line, i);
    if (!ply_type(count_name, p.count_type) || p.count_type.floating)
      throw InputError(path, no, "PLY list count type must be an integer type");
    t = next_token(line, i);
  }
  if (!ply_type(t, p.type)) throw InputError(path, no, "unknown PLY property type " + quote(t));
  p.name = std::string(next_token(line, i));
  if (p.name.empty() || !next_token(line, i).empty())
    throw InputError(path, no, "PLY property line must be 'property TYPE NAME' or 'property list TYPE TYPE NAME'");
  if (e.name == "vertex" && !p.list) p.axis = p.name == "x" ? 0 : p.name == "y" ? 1 : p.name == "z" ? 2 : -1;
  p.indices = e.name == "face" && p.list && (p.name == "vertex_indices" || p.name == "vertex_index");
  e.props.push_back(std::move(p));
}

void add_element(const std::string& path, std::int64_t no, std::string_view line, std::size_t i, PlyHeader& h) {
  PlyElement e;
  e.name = std::string(next_token(line, i));
  std::int64_t n = 0;
  if (e.name.empty() || !parse_index(next_token(line, i), n) || n < 0 || n > std::int64_t{0x7fffffff} ||
      !next_token(line, i).empty())
    throw InputError(path, no, "PLY element line must be 'element NAME COUNT' with 0 <= COUNT < 2^31");
  e.count = static_cast<std::uint64_t>(n);
  e.line = no;
  h.elements.push_back(std::move(e));
}

void set_format(const std::string& path, std::int64_t no, std::string_view line, std::size_t i, PlyHeader& h) {
  const std::string_view f = next_token(line, i);
  h.format = f == "ascii" ? PlyFormat::ascii : f == "binary_little_endian" ? PlyFormat::binary_le
           : f == "binary_big_endian" ? PlyFormat::binary_be
           : throw InputError(path, no, "unknown PLY format " + quote(f));
  if (next_token(line, i) != "1.0" || !next_token(line, i).empty())
    throw InputError(path, no, "PLY format line must be 'format " + std::string(f) + " 1.0'");
  h.format_name = std::string(f);
}

PlyHeader parse_ply_header(const std::string& path, const std::string& bytes) {
  PlyHeader h;
  LineCursor lines(bytes);
  std::string_view line;
  if (!lines.next(line) || line != "ply") throw InputError(path, 1, "not a PLY file: the first line must be 'ply'");
  bool have_format = false;
  while (true) {
    if (!lines.next(line)) throw InputError(path, lines.number(), "PLY header has no end_header");
    std::size_t i = 0;
    const std::string_view kw = next_token(line, i);
    const std::int64_t no = lines.number();
    if (kw == "format") {
      set_format(path, no, line, i, h);
      have_format = true;
    } else if (kw == "element") {
      add_element(path, no, line, i, h);
    } else if (kw == "property") {
      if (h.elements.empty()) throw InputError(path, no, "PLY property before any element");
      add_property(path, no, line, i, h.elements.back());
    } else if (kw == "end_header") {
      if (!next_token(line, i).empty())
        throw InputError(path, no, "PLY end_header line must hold only 'end_header' (the body starts on the next line)");
      break;
    } else if (kw != "comment" && kw != "obj_info" && !kw.empty()) {
      throw InputError(path, no, "unknown PLY header keyword " + quote(kw));
    }
  }
  if (!have_format) throw InputError(path, "PLY header has no format line");
  h.body = lines.offset();
  h.body_line = lines.number() + 1;
  return h;
}

/// The header as OpenMesh will read it: rebuilt from what we parsed, one
/// declaration per line, without comments. OpenMesh 9.0's header parser loops
/// forever (printing to omerr) on some malformed lines, e.g. a bad version;
/// a canonical header keeps whatever we accepted within what it handles.
///
/// Within what OpenMesh handles means (measured on Debian's OpenMesh 9, all
/// sixteen type names, binary and ascii; a review of 2026-12-07 found the
/// gaps): only the vertex's x, y, z and the face's vertex_indices keep their
/// names, every other property is renamed `bsprt_skip_N`, which OpenMesh
/// skips by its size whatever its type (named s, t, u, v, nx or red with a
/// type OpenMesh cannot convert, it printed to std::cerr and misread the rest);
/// list count types are written as the one name of their size OpenMesh takes
/// (uchar, uint16, int: it refuses int32, uint, short, char and the others).
std::string canonical_header(const std::string& path, const PlyHeader& h) {
  const auto count_name = [](const PlyType& t) { return t.size == 1 ? "uchar" : t.size == 2 ? "uint16" : "int"; };
  const auto type_name = [](const PlyType& t) {
    if (t.floating) return t.size == 4 ? "float" : "double";
    static const char* names[2][5] = {{"", "uchar", "uint16", "", "uint"}, {"", "char", "short", "", "int"}};
    return names[t.is_signed ? 1 : 0][t.size];
  };
  std::string s = "ply\nformat " + h.format_name + " 1.0\n";
  int skipped = 0;
  for (const PlyElement& e : h.elements) {
    s += "element " + e.name + " " + std::to_string(e.count) + "\n";
    for (const PlyProperty& p : e.props) {
      if (p.axis >= 0 && h.format != PlyFormat::ascii && !p.type.floating)
        throw InputError(path, e.line, "binary PLY vertex coordinate '" + p.name + "' of type " + type_name(p.type) +
                                           " is not supported (OpenMesh, which reads PLY here, takes float or "
                                           "double coordinates in binary files)");
      s += "property ";
      if (p.list) s += std::string("list ") + count_name(p.count_type) + " ";
      s += type_name(p.type);
      s += p.axis >= 0 || p.indices ? " " + p.name : " bsprt_skip_" + std::to_string(skipped++);
      s += "\n";
    }
  }
  return s + "end_header\n";
}

/// OpenMesh reads the vertex and face elements and skips other elements
/// value by value, which misreads any list property other than the face's
/// vertex_indices (up to and including the face element; it stops after it).
void check_supported(const std::string& path, const PlyHeader& h, ElementScan& scan) {
  bool have_vertex = false, have_face = false;
  for (const PlyElement& e : h.elements) {
    // Records of no bytes: a short header could make both passes loop 2^31
    // times per element (a review of 2026-12-07: 728 bytes, 34 s).
    if (e.props.empty() && e.count > 0)
      throw InputError(path, e.line, "PLY element '" + e.name + "' declares " + std::to_string(e.count) +
                                         " records but no properties");
    if (e.name == "vertex") {
      int axes = 0;
      for (const PlyProperty& p : e.props) axes += p.axis >= 0 ? 1 : 0;
      if (axes != 3) throw InputError(path, e.line, "PLY vertex element needs properties x, y and z");
      scan.vertices = e.count;
      have_vertex = true;
    }
    if (have_face) continue;
    for (const PlyProperty& p : e.props)
      if (p.list && !p.indices)
        throw InputError(path, e.line, "PLY list property '" + p.name + "' in element '" + e.name +
                                           "' is not supported (OpenMesh would misread the data after it)");
    if (e.name == "face") {
      if (std::none_of(e.props.begin(), e.props.end(), [](const PlyProperty& p) { return p.indices; }))
        throw InputError(path, e.line, "PLY face element has no vertex_indices list");
      // Valid PLY, but OpenMesh misreads both layouts (0 vertices, or the
      // scalar taken as part of the index list): say so, not that it disagrees.
      if (!have_vertex)
        throw InputError(path, e.line,
                         "PLY face element before the vertex element is not supported (OpenMesh, which reads PLY "
                         "here, needs the vertices first)");
      if (!e.props.front().indices)
        throw InputError(path, e.line,
                         "PLY face property '" + e.props.front().name +
                             "' before vertex_indices is not supported (OpenMesh reads the index list first)");
      scan.faces = e.count;
      have_face = true;
    }
  }
  if (!have_vertex) throw InputError(path, "PLY file has no vertex element");
}

// --- binary body -------------------------------------------------------------

struct BinaryCursor {
  const std::string& path;
  const std::string& bytes;
  std::size_t pos;
  bool big_endian;

  const char* take(std::size_t n, const PlyElement& e, std::uint64_t i) {
    if (bytes.size() - pos < n)
      throw InputError(path, "truncated binary PLY: the file ends inside " + e.name + " " + std::to_string(i) + " of the " +
                                 std::to_string(e.count) + " the header declares (byte " + std::to_string(bytes.size()) + ")");
    const char* p = bytes.data() + pos;
    pos += n;
    return p;
  }
  std::uint64_t raw(const PlyType& t, const PlyElement& e, std::uint64_t i) {
    unsigned char b[8] = {};
    std::memcpy(b, take(static_cast<std::size_t>(t.size), e, i), static_cast<std::size_t>(t.size));
    if (big_endian) std::reverse(b, b + t.size);
    std::uint64_t v = 0;
    for (int k = t.size - 1; k >= 0; --k) v = (v << 8) | b[k];
    return v;
  }
  std::int64_t integer(const PlyType& t, const PlyElement& e, std::uint64_t i) {
    const std::uint64_t v = raw(t, e, i);
    if (!t.is_signed || t.size == 8) return static_cast<std::int64_t>(v);
    const std::uint64_t sign = std::uint64_t{1} << (8 * t.size - 1);
    return static_cast<std::int64_t>((v ^ sign) - sign);
  }
  float real(const PlyType& t, const PlyElement& e, std::uint64_t i) {
    const std::uint64_t v = raw(t, e, i);
    if (t.size == 4) return std::bit_cast<float>(static_cast<std::uint32_t>(v));
    return static_cast<float>(std::bit_cast<double>(v));
  }
};

void walk_binary_face(const std::string& path, BinaryCursor& in, const PlyElement& e, std::uint64_t i,
                      const PlyProperty& p, ElementScan& scan) {
  const std::int64_t n = in.integer(p.count_type, e, i);
  if (n < 3) throw InputError(path, "binary PLY face " + std::to_string(i) + " has " + std::to_string(n) + " vertices, needs at least 3");
  for (std::int64_t k = 0; k < n; ++k) {
    const std::int64_t idx = p.type.floating ? -1 : in.integer(p.type, e, i);
    if (idx < 0 || static_cast<std::uint64_t>(idx) >= scan.vertices)
      throw InputError(path, "binary PLY face " + std::to_string(i) + ": vertex index " + std::to_string(idx) +
                                 " is not in " + valid_range(scan.vertices));
    scan.index_sum += static_cast<std::uint64_t>(idx);
  }
  scan.corners += static_cast<std::size_t>(n);
}

void walk_binary(const std::string& path, const std::string& bytes, const PlyHeader& h, ElementScan& scan) {
  BinaryCursor in{path, bytes, h.body, h.format == PlyFormat::binary_be};
  for (const PlyElement& e : h.elements) {
    const bool vertex = e.name == "vertex";
    for (std::uint64_t i = 0; i < e.count; ++i) {
      Vec3f p;
      for (const PlyProperty& prop : e.props) {
        if (prop.indices) {
          walk_binary_face(path, in, e, i, prop, scan);
        } else if (prop.list) {
          const std::int64_t n = in.integer(prop.count_type, e, i);
          if (n < 0) throw InputError(path, e.name + " " + std::to_string(i) + ": negative list length");
          in.take(static_cast<std::size_t>(n) * static_cast<std::size_t>(prop.type.size), e, i);
        } else if (vertex && prop.axis >= 0) {
          p[prop.axis] = prop.type.floating ? in.real(prop.type, e, i) : static_cast<float>(in.integer(prop.type, e, i));
        } else {
          in.take(static_cast<std::size_t>(prop.type.size), e, i);
        }
      }
      if (!vertex) continue;
      for (int a = 0; a < 3; ++a)
        if (!std::isfinite(p[a])) scan.nonfinite.push_back({scan.coords.size(), a, p[a], -1});
      scan.coords.push_back(p);
    }
  }
  // Newlines after the data are harmless, but a record of whitespace bytes (a
  // face 9 10 11 ... as uchar) is data, and skipping it lost the face without
  // a word (review of 2026-12-07): only whitespace too short to be a face or
  // a vertex record may follow; anything more means the counts lie.
  std::size_t shortest = std::numeric_limits<std::size_t>::max();
  for (const PlyElement& e : h.elements) {
    if (e.name != "vertex" && e.name != "face") continue;
    std::size_t size = 0;
    for (const PlyProperty& p : e.props)
      size += std::size_t(p.list ? p.count_type.size + (p.indices ? 3 * p.type.size : 0) : p.type.size);
    shortest = std::min(shortest, size);
  }
  std::size_t rest = in.pos;
  while (rest < bytes.size() && rest - in.pos + 1 < shortest && is_blank(bytes[rest])) ++rest;
  if (rest != bytes.size())
    throw InputError(path, std::to_string(bytes.size() - in.pos) + " bytes after the last element the header declares "
                                                                 "(do the counts lie?)");
}

// --- ascii body --------------------------------------------------------------

struct TokenCursor {
  std::string_view text;
  std::size_t pos;
  std::int64_t line;

  /// Next token and its line; empty at the end.
  std::string_view next(std::int64_t& tok_line) {
    while (pos < text.size() && is_blank(text[pos])) line += text[pos++] == '\n' ? 1 : 0;
    const std::size_t b = pos;
    while (pos < text.size() && !is_blank(text[pos])) ++pos;
    tok_line = line;
    return text.substr(b, pos - b);
  }
};

std::string_view need(const std::string& path, TokenCursor& in, const PlyElement& e, std::uint64_t i, std::int64_t& no) {
  const std::string_view t = in.next(no);
  if (t.empty())
    throw InputError(path, no, "file ends inside " + e.name + " " + std::to_string(i) + " of the " +
                                   std::to_string(e.count) + " the header declares");
  return t;
}

/// One scalar value; non-finite floats are blanked to 0 for OpenMesh's sake.
float ascii_value(const std::string& path, std::string& bytes, TokenCursor& in, const PlyElement& e, std::uint64_t i,
                  const PlyType& type, NumberKind& kind, std::int64_t& no) {
  const std::string_view t = need(path, in, e, i, no);
  if (!type.floating) {
    std::int64_t v = 0;
    if (!parse_index(t, v)) throw InputError(path, no, "integer PLY property holds " + quote(t));
    kind = NumberKind::finite;
    return static_cast<float>(v);
  }
  float v = 0;
  kind = parse_coordinate(t, v);
  if (kind == NumberKind::malformed) throw InputError(path, no, "PLY value " + quote(t) + " is not a number");
  if (kind == NumberKind::nonfinite) blank_out(bytes, t, '0');
  return v;
}

void walk_ascii_face(const std::string& path, TokenCursor& in, const PlyElement& e, std::uint64_t i,
                     const PlyProperty& p, ElementScan& scan) {
  std::int64_t no = 0, n = 0;
  const std::string_view c = need(path, in, e, i, no);
  if (!parse_index(c, n) || n < 3) throw InputError(path, no, "face vertex count " + quote(c) + " must be an integer >= 3");
  for (std::int64_t k = 0; k < n; ++k) {
    const std::string_view t = need(path, in, e, i, no);
    std::int64_t idx = 0;
    if (!parse_index(t, idx) || idx < 0 || static_cast<std::uint64_t>(idx) >= scan.vertices)
      throw InputError(path, no, "face vertex index " + quote(t) + " is not in " + valid_range(scan.vertices));
    scan.index_sum += static_cast<std::uint64_t>(idx);
  }
  scan.corners += static_cast<std::size_t>(n);
}

void walk_ascii(const std::string& path, std::string& bytes, const PlyHeader& h, ElementScan& scan) {
  TokenCursor in{bytes, h.body, h.body_line};
  std::int64_t no = 0;
  NumberKind kind = NumberKind::finite;
  for (const PlyElement& e : h.elements) {
    const bool vertex = e.name == "vertex";
    for (std::uint64_t i = 0; i < e.count; ++i) {
      Vec3f p;
      std::int64_t first_line = -1;
      for (const PlyProperty& prop : e.props) {
        if (prop.indices) {
          walk_ascii_face(path, in, e, i, prop, scan);
          continue;
        }
        if (prop.list) {
          std::int64_t n = 0;
          const std::string_view c = need(path, in, e, i, no);
          if (!parse_index(c, n) || n < 0) throw InputError(path, no, "PLY list length " + quote(c) + " is not an integer >= 0");
          for (std::int64_t k = 0; k < n; ++k) ascii_value(path, bytes, in, e, i, prop.type, kind, no);
          continue;
        }
        const float v = ascii_value(path, bytes, in, e, i, prop.type, kind, no);
        if (first_line < 0) first_line = no;
        if (!vertex || prop.axis < 0) continue;
        p[prop.axis] = kind == NumberKind::nonfinite ? 0.f : v;
        if (kind == NumberKind::nonfinite) scan.nonfinite.push_back({scan.coords.size(), prop.axis, v, no});
      }
      if (!vertex) continue;
      scan.coords.push_back(p);
      scan.vertex_line.push_back(first_line);
    }
  }
  const std::string_view extra = in.next(no);
  if (!extra.empty())
    throw InputError(path, no, "data after the last element the header declares (do the counts lie?): " + quote(extra));
}

}  // namespace

ElementScan scan_ply(const std::string& path, std::string& bytes) {
  const PlyHeader header = parse_ply_header(path, bytes);
  ElementScan scan;
  check_supported(path, header, scan);
  scan.binary = header.format != PlyFormat::ascii;
  scan.openmesh_header = canonical_header(path, header);
  scan.body_offset = header.body;
  scan.coords.reserve(std::min<std::size_t>(scan.vertices, 1u << 24));
  if (scan.binary)
    walk_binary(path, bytes, header, scan);
  else
    walk_ascii(path, bytes, header, scan);
  return scan;
}

}  // namespace bsprt::detail

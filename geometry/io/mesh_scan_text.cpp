/// \file mesh_scan_text.cpp
/// Pre-passes for the line-based formats: OBJ, OFF and STL (see mesh_scan.h),
/// and the shared number parsing.

#include <algorithm>
#include <cctype>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>

#include "bsprt/error.h"
#include "geometry/io/mesh_scan.h"
#include "geometry/io/mesh_scan_util.h"

namespace bsprt::detail {

// ---------------------------------------------------------------------------
// Numbers

namespace {

bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i])))
      return false;
  return true;
}

/// MSVC's printf spellings of non-finite values: 1.#INF, 1.#IND, 1.#QNAN,
/// 1.#SNAN, possibly followed by digits ("1.#INF00"). `s` has no sign.
bool parse_msvc_nonfinite(std::string_view s, bool negative, float& value) {
  const std::size_t hash = s.find('#');
  if (hash == std::string_view::npos || hash == 0) return false;
  for (std::size_t i = 0; i < hash; ++i)
    if (!std::isdigit(static_cast<unsigned char>(s[i])) && s[i] != '.') return false;
  std::string_view word = s.substr(hash + 1);
  while (!word.empty() && std::isdigit(static_cast<unsigned char>(word.back()))) word.remove_suffix(1);
  if (iequals(word, "INF")) {
    value = negative ? -std::numeric_limits<float>::infinity() : std::numeric_limits<float>::infinity();
    return true;
  }
  if (iequals(word, "IND") || iequals(word, "QNAN") || iequals(word, "SNAN")) {
    value = std::numeric_limits<float>::quiet_NaN();
    return true;
  }
  return false;
}

}  // namespace

NumberKind parse_coordinate(std::string_view token, float& value) {
  std::string_view s = token;
  bool negative = false;
  if (!s.empty() && (s[0] == '+' || s[0] == '-')) {
    negative = s[0] == '-';
    s.remove_prefix(1);
  }
  if (s.empty() || s[0] == '+' || s[0] == '-') return NumberKind::malformed;
  const char* end = s.data() + s.size();
  float f = 0;
  auto [p, ec] = std::from_chars(s.data(), end, f);
  if (p == end && ec == std::errc()) {
    value = negative ? -f : f;
    return std::isfinite(value) ? NumberKind::finite : NumberKind::nonfinite;
  }
  if (p == end && ec == std::errc::result_out_of_range) {
    // Overflow is +-Inf; underflow is a tiny (denormal or zero) finite value.
    const std::string copy(token);
    const double d = std::strtod(copy.c_str(), nullptr);
    value = static_cast<float>(d);
    return std::isfinite(value) ? NumberKind::finite : NumberKind::nonfinite;
  }
  if (parse_msvc_nonfinite(s, negative, value)) return NumberKind::nonfinite;
  return NumberKind::malformed;
}

bool parse_index(std::string_view token, std::int64_t& value) {
  if (!token.empty() && token[0] == '+') token.remove_prefix(1);
  const char* end = token.data() + token.size();
  auto [p, ec] = std::from_chars(token.data(), end, value);
  return !token.empty() && p == end && ec == std::errc();
}

void blank_out(std::string& bytes, std::string_view token, char first) {
  const std::size_t pos = static_cast<std::size_t>(token.data() - bytes.data());
  bytes[pos] = first;
  std::fill(bytes.begin() + static_cast<std::ptrdiff_t>(pos) + 1,
            bytes.begin() + static_cast<std::ptrdiff_t>(pos + token.size()), ' ');
}

std::string quote(std::string_view token) {
  std::string t(token.substr(0, 40));
  if (token.size() > 40) t += "...";
  return "'" + t + "'";
}

// ---------------------------------------------------------------------------
// OBJ

namespace {

/// Whether `line` holds a CR followed by non-blank text that is a statement:
/// any text on a statement line, on a comment line text starting with an OBJ
/// keyword.
bool cr_joins_statements(std::string_view line) {
  std::size_t end = line.size();
  while (end > 0 && is_blank(line[end - 1])) --end;  // trailing CRs and blanks end the line
  line = line.substr(0, end);
  const std::size_t cr = line.find('\r');
  if (cr == std::string_view::npos) return false;
  std::size_t i = 0;
  if (next_token(line, i).substr(0, 1) != "#") return true;
  for (std::size_t at = cr; at != std::string_view::npos; at = line.find('\r', at + 1)) {
    std::size_t j = at + 1;
    const std::string_view kw = next_token(line, j);
    for (const char* k : {"v", "vt", "vn", "vp", "f", "l", "p", "o", "g", "s", "usemtl", "mtllib"})
      if (kw == k) return true;
  }
  return false;
}

void scan_obj_vertex(const std::string& path, std::string& bytes, std::string_view line,
                     std::size_t& i, std::int64_t line_no, ObjScan& scan) {
  const std::size_t vertex = scan.vertices++;
  scan.vertex_line.push_back(line_no);
  for (int axis = 0; axis < 3; ++axis) {
    const std::string_view tok = next_token(line, i);
    if (tok.empty())
      throw InputError(path, line_no, "vertex " + std::to_string(vertex + 1) + " has " +
                                          std::to_string(axis) + " coordinates, needs 3");
    float value = 0;
    const NumberKind kind = parse_coordinate(tok, value);
    if (kind == NumberKind::malformed)
      throw InputError(path, line_no, "vertex coordinate " + quote(tok) + " is not a number");
    if (kind == NumberKind::nonfinite) {
      // OpenMesh would skip the whole line (shifting later indices): hand it
      // a 0 and put the real value back afterwards.
      scan.nonfinite.push_back({vertex, axis, value, line_no});
      blank_out(bytes, tok, '0');
    }
  }
  // After x y z: numbers only (w, a colour, or what an exporter adds; OpenMesh
  // reads x y z and at most a colour). A word there was ignored, and with the
  // CR check above it no longer hides a vertex (review of 2026-12-07).
  for (std::string_view tok = next_token(line, i); !tok.empty() && tok[0] != '#'; tok = next_token(line, i)) {
    float value = 0;
    const NumberKind kind = parse_coordinate(tok, value);
    if (kind == NumberKind::malformed)
      throw InputError(path, line_no, "vertex " + std::to_string(vertex + 1) + ": " + quote(tok) +
                                          " after the coordinates is not a number");
    if (kind == NumberKind::nonfinite) blank_out(bytes, tok, '0');  // unused; OpenMesh would skip the line
  }
}

void scan_obj_face(const std::string& path, std::string_view line, std::size_t& i,
                   std::int64_t line_no, ObjScan& scan) {
  std::size_t count = 0;
  for (std::string_view tok = next_token(line, i); !tok.empty(); tok = next_token(line, i)) {
    if (tok[0] == '#') break;
    const std::string_view first = tok.substr(0, tok.find('/'));
    std::int64_t value = 0;
    if (!parse_index(first, value))
      throw InputError(path, line_no, "face vertex " + quote(tok) + " does not start with an integer index");
    if (value == 0) throw InputError(path, line_no, "face vertex index 0 (OBJ indices start at 1)");
    // Negative indices count back from the last `v` line read so far.
    const std::int64_t index = value > 0 ? value - 1 : static_cast<std::int64_t>(scan.vertices) + value;
    if (index < 0)
      throw InputError(path, line_no, "relative face index " + std::to_string(value) + " reaches before vertex 1 (only " +
                                          std::to_string(scan.vertices) + " vertices read so far)");
    if (index > std::int64_t{std::numeric_limits<std::uint32_t>::max() - 1})
      throw InputError(path, line_no, "face vertex index " + std::to_string(value) + " is too large");
    scan.corners.push_back(static_cast<std::uint32_t>(index));
    ++count;
  }
  if (count < 3)
    throw InputError(path, line_no, "face has " + std::to_string(count) + " vertices, needs at least 3");
  scan.face_line.push_back(line_no);
  scan.face_begin.push_back(scan.corners.size());
}

}  // namespace

ObjScan scan_obj(const std::string& path, std::string& bytes) {
  ObjScan scan;
  // A UTF-8 byte order mark would hide the first line's keyword from both
  // OpenMesh and us; make it blanks.
  if (bytes.compare(0, 3, "\xEF\xBB\xBF") == 0) bytes.replace(0, 3, "   ");
  LineCursor lines(bytes);
  std::string_view line;
  while (lines.next(line)) {
    // A CR followed by more text is an old Mac line end: neither pass would
    // see the lines it separates (`v 1 0 0`CR`v 9 9 9` lost a vertex, a CR-only
    // file read as one line and had "no triangles"). Trailing CRs (CR CR LF)
    // are line ends, and a comment may hold a CR unless what follows it is a
    // statement.
    if (cr_joins_statements(line))
      throw InputError(path, lines.number(), "carriage return inside a line: CR-only line ends are not supported "
                                             "(use LF or CR LF)");
    std::size_t i = 0;
    const std::string_view keyword = next_token(line, i);
    if (keyword == "v")
      scan_obj_vertex(path, bytes, line, i, lines.number(), scan);
    else if (keyword == "f")
      scan_obj_face(path, line, i, lines.number(), scan);
    else if (keyword == "vt")
      // Texture coordinates are not used. OpenMesh refuses a whole file over a
      // `vt` with one value (legal OBJ) or a NaN, without a line: blank them.
      blank_out(bytes, line, ' ');
    else if (keyword == "mtllib")
      // OpenMesh would open and read the named file (relative to whatever
      // folder its reader singleton last saw; with "/dev/zero" it reads until a
      // 2 GB line fails).
      // Materials are not used: blank the line.
      blank_out(bytes, line, ' ');
  }
  // Positive indices may refer forward (OpenMesh reads all `v` lines first).
  for (std::size_t f = 0; f < scan.face_count(); ++f)
    for (std::size_t c = scan.face_begin[f]; c < scan.face_begin[f + 1]; ++c)
      if (scan.corners[c] >= scan.vertices)
        throw InputError(path, scan.face_line[f], "face refers to vertex " + std::to_string(scan.corners[c] + 1) +
                                                      " but the file has " + std::to_string(scan.vertices) + " vertices");
  return scan;
}

// ---------------------------------------------------------------------------
// OFF

namespace {

/// Reads the OFF keyword line: whether faces carry colors ('C'), vertices
/// normals ('N'), and where counts written on the keyword line start (npos if
/// none).
bool scan_off_keyword(const std::string& path, const std::string& bytes, std::string_view line, bool& normals,
                      std::size_t& inline_counts) {
  std::size_t i = 0;
  const std::string_view kw = next_token(line, i);
  std::string_view k = kw;
  if (k.substr(0, 2) == "ST") k.remove_prefix(2);
  const bool colors = !k.empty() && k[0] == 'C';
  if (colors) k.remove_prefix(1);
  normals = !k.empty() && k[0] == 'N';
  if (normals) k.remove_prefix(1);
  if (k == "4OFF" || k == "nOFF" || k == "4nOFF")
    throw InputError(path, 1, "OFF with vertex dimension other than 3 (" + quote(kw) + ") is not supported");
  if (k != "OFF" || kw.data() != bytes.data())
    throw InputError(path, 1, "not an OFF file: the first line must start with OFF, found " + quote(line.substr(0, 20)));
  const std::string_view next = next_token(line, i);
  if (next == "BINARY") throw InputError(path, 1, "binary OFF is not supported (use ascii OFF or PLY)");
  inline_counts = next.empty() || next[0] == '#' ? std::string_view::npos : kw.size();
  return colors;
}

/// Returns the next line that holds a token (after comments were blanked).
bool next_content_line(LineCursor& lines, std::string_view& line) {
  while (lines.next(line)) {
    std::size_t i = 0;
    if (!next_token(line, i).empty()) return true;
  }
  return false;
}

void blank_comments(std::string& bytes) {
  bool in_comment = false;
  for (char& c : bytes) {
    if (c == '\n') in_comment = false;
    else if (c == '#') in_comment = true;
    if (in_comment && c != '\r') c = ' ';
  }
}

void scan_off_vertex(const std::string& path, std::string& bytes, std::string_view line, std::int64_t line_no,
                     bool normals, ElementScan& scan) {
  const std::size_t vertex = scan.coords.size();
  Vec3f p;
  std::size_t i = 0;
  for (int axis = 0; axis < (normals ? 6 : 3); ++axis) {
    const std::string_view tok = next_token(line, i);
    if (tok.empty())
      throw InputError(path, line_no, "vertex " + std::to_string(vertex) + " has " + std::to_string(axis) +
                                          " values, needs " + (normals ? "6 (NOFF)" : "3"));
    float value = 0;
    const NumberKind kind = parse_coordinate(tok, value);
    if (kind == NumberKind::malformed)
      throw InputError(path, line_no, "vertex value " + quote(tok) + " is not a number");
    if (kind == NumberKind::nonfinite) {
      blank_out(bytes, tok, '0');  // OpenMesh's `>> float` would fail and derail the rest
      if (axis < 3) scan.nonfinite.push_back({vertex, axis, value, line_no});
      value = 0;
    }
    if (axis < 3) p[axis] = value;
  }
  scan.coords.push_back(p);
  scan.vertex_line.push_back(line_no);
}

void scan_off_face(const std::string& path, std::string& bytes, std::string_view line, std::int64_t line_no,
                   bool colors, ElementScan& scan) {
  std::size_t i = 0;
  std::int64_t k = 0;
  const std::string_view count = next_token(line, i);
  if (!parse_index(count, k) || k < 3)
    throw InputError(path, line_no, "face vertex count " + quote(count) + " must be an integer >= 3");
  for (std::int64_t j = 0; j < k; ++j) {
    const std::string_view tok = next_token(line, i);
    std::int64_t index = 0;
    if (tok.empty())
      throw InputError(path, line_no, "face declares " + std::to_string(k) + " vertices but lists " + std::to_string(j));
    if (!parse_index(tok, index) || index < 0 || static_cast<std::size_t>(index) >= scan.vertices)
      throw InputError(path, line_no, "face vertex index " + quote(tok) + " is not in " + valid_range(scan.vertices));
    scan.index_sum += static_cast<std::uint64_t>(index);
  }
  scan.corners += static_cast<std::size_t>(k);
  // OpenMesh would read trailing values (a face color) as the next face's
  // vertex count, or, with a 'C' header, misread a face that has none (face
  // colors are optional per face: a COFF whose faces carry colors only in
  // part failed; review of 2026-12-07). Colors are not used: blank them.
  (void)colors;
  for (std::string_view tok = next_token(line, i); !tok.empty(); tok = next_token(line, i)) blank_out(bytes, tok, ' ');
}

void scan_off_counts(const std::string& path, std::string_view line, std::int64_t line_no, ElementScan& scan) {
  std::size_t i = 0;
  std::int64_t n[3] = {0, 0, 0};
  for (int c = 0; c < 3; ++c) {
    const std::string_view tok = next_token(line, i);
    if (!parse_index(tok, n[c]) || n[c] < 0)
      throw InputError(path, line_no, "OFF counts must be three non-negative integers (vertices faces edges)");
  }
  if (!next_token(line, i).empty())
    throw InputError(path, line_no, "extra values after the OFF counts (vertices faces edges)");
  scan.vertices = static_cast<std::size_t>(n[0]);
  scan.faces = static_cast<std::size_t>(n[1]);
}

}  // namespace

ElementScan scan_off(const std::string& path, std::string& bytes) {
  ElementScan scan;
  LineCursor lines(bytes);
  std::string_view line;
  lines.next(line);
  bool normals = false;
  std::size_t inline_counts = std::string_view::npos;
  const bool colors = scan_off_keyword(path, bytes, line, normals, inline_counts);
  blank_comments(bytes);
  if (inline_counts != std::string_view::npos) {
    scan_off_counts(path, line.substr(inline_counts), 1, scan);
  } else {
    if (!next_content_line(lines, line)) throw InputError(path, "OFF file ends before its vertex/face/edge counts");
    scan_off_counts(path, line, lines.number(), scan);
  }
  scan.coords.reserve(std::min<std::size_t>(scan.vertices, 1u << 24));
  for (std::size_t v = 0; v < scan.vertices; ++v) {
    if (!next_content_line(lines, line))
      throw InputError(path, lines.number(), "file ends after " + std::to_string(v) + " of the " +
                                                 std::to_string(scan.vertices) + " vertices the header declares");
    scan_off_vertex(path, bytes, line, lines.number(), normals, scan);
  }
  for (std::size_t f = 0; f < scan.faces; ++f) {
    if (!next_content_line(lines, line))
      throw InputError(path, lines.number(), "file ends after " + std::to_string(f) + " of the " +
                                                 std::to_string(scan.faces) + " faces the header declares");
    scan_off_face(path, bytes, line, lines.number(), colors, scan);
  }
  if (next_content_line(lines, line))
    throw InputError(path, lines.number(), "data after the last of the " + std::to_string(scan.faces) +
                                               " faces the header declares (do the counts lie?)");
  // OpenMesh reads the whole first line as the keyword: move inline counts to
  // a line of their own (done last, so our line numbers above stay right).
  if (inline_counts != std::string_view::npos) bytes[inline_counts] = '\n';
  return scan;
}

// ---------------------------------------------------------------------------
// STL

namespace {

/// Binary STL records: normal, 3 corners, attribute count (little-endian
/// floats; this host is little-endian, as OpenMesh's reader also assumes).
void scan_stl_binary(const std::string& bytes, StlScan& scan) {
  std::uint32_t n = 0;
  std::memcpy(&n, bytes.data() + 80, 4);
  scan.corners.resize(std::size_t{n} * 3);
  for (std::size_t f = 0; f < n; ++f) {
    const char* rec = bytes.data() + 84 + 50 * f + 12;  // skip the normal
    for (int k = 0; k < 3; ++k) {
      float xyz[3];
      std::memcpy(xyz, rec + 12 * k, 12);
      scan.corners[3 * f + static_cast<std::size_t>(k)] = Vec3f(xyz[0], xyz[1], xyz[2]);
      for (int a = 0; a < 3; ++a)
        if (!std::isfinite(xyz[a])) scan.nonfinite.push_back({3 * f + static_cast<std::size_t>(k), a, xyz[a], -1});
    }
  }
}

struct StlState {
  bool in_solid = false, in_facet = false, in_loop = false, seen_solid = false;
  int corners = 0;
};

void scan_stl_line(const std::string& path, std::string& bytes, std::string_view line, std::int64_t no, StlState& st,
                   StlScan& scan) {
  std::size_t i = 0;
  const std::string_view kw = next_token(line, i);
  auto expect = [&](bool ok, const char* what) {
    if (!ok) throw InputError(path, no, std::string("unexpected ") + quote(kw) + " (" + what + ")");
  };
  if (kw.empty()) return;
  if (iequals(kw, "solid") || iequals(kw, "endsolid")) {
    // OpenMesh starts a triangle at any line containing "outer": blank the
    // solid's name (unused) so that "solid outer_shell" cannot trigger it.
    for (std::string_view t = next_token(line, i); !t.empty(); t = next_token(line, i)) blank_out(bytes, t, ' ');
  }
  if (iequals(kw, "solid")) {
    expect(!st.in_solid, "solid inside a solid");
    st.in_solid = st.seen_solid = true;
  } else if (iequals(kw, "facet")) {
    expect(st.in_solid && !st.in_facet, "facet outside a solid or inside a facet");
    st.in_facet = true;
    scan.facet_line.push_back(no);
  } else if (iequals(kw, "outer")) {
    expect(st.in_facet && !st.in_loop, "outer loop outside a facet");
    st.in_loop = true;
    st.corners = 0;
  } else if (iequals(kw, "vertex")) {
    expect(st.in_loop && st.corners < 3, "a facet's loop must have exactly 3 vertices");
    Vec3f p;
    for (int a = 0; a < 3; ++a) {
      const std::string_view tok = next_token(line, i);
      float value = 0;
      const NumberKind kind = parse_coordinate(tok, value);
      if (kind == NumberKind::malformed) throw InputError(path, no, "vertex coordinate " + quote(tok) + " is not a number");
      if (kind == NumberKind::nonfinite) scan.nonfinite.push_back({scan.corners.size(), a, value, no});
      p[a] = value;
    }
    scan.corners.push_back(p);
    ++st.corners;
  } else if (iequals(kw, "endloop")) {
    expect(st.in_loop && st.corners == 3, "a facet's loop must have exactly 3 vertices");
    st.in_loop = false;
  } else if (iequals(kw, "endfacet")) {
    expect(st.in_facet && !st.in_loop && st.corners == 3, "endfacet without a complete loop");
    st.in_facet = false;
  } else if (iequals(kw, "endsolid")) {
    expect(st.in_solid && !st.in_facet, "endsolid inside a facet");
    st.in_solid = false;
  } else {
    throw InputError(path, no, "unknown ascii STL keyword " + quote(kw));
  }
}

}  // namespace

StlScan scan_stl(const std::string& path, std::string& bytes) {
  StlScan scan;
  std::uint32_t n = 0;
  if (bytes.size() >= 84) std::memcpy(&n, bytes.data() + 80, 4);
  if (bytes.size() >= 84 && bytes.size() == 84 + 50 * std::uint64_t{n}) {
    scan.binary = true;
    scan_stl_binary(bytes, scan);
    return scan;
  }
  std::size_t i = 0;
  // Binary files may begin with "solid" too; a NUL byte (never in an ascii
  // STL) says which this is, so that a wrong count gets the binary message,
  // not "ascii STL ends inside a solid" (review of 2026-12-07).
  const bool has_nul = bytes.find('\0') != std::string::npos;
  if (!iequals(next_token(bytes, i), "solid") || (has_nul && bytes.size() >= 84)) {
    if (bytes.size() < 84) throw InputError(path, "binary STL shorter than its 84-byte header");
    throw InputError(path, "binary STL: header declares " + std::to_string(n) + " triangles (" +
                               std::to_string(84 + 50 * std::uint64_t{n}) + " bytes) but the file has " +
                               std::to_string(bytes.size()) + " bytes");
  }
  LineCursor lines(bytes);
  std::string_view line;
  StlState st;
  while (lines.next(line)) scan_stl_line(path, bytes, line, lines.number(), st, scan);
  if (st.in_solid || !st.seen_solid)
    throw InputError(path, lines.number(), "ascii STL ends inside a solid (truncated? no endsolid)");
  return scan;
}

}  // namespace bsprt::detail

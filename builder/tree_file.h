#pragma once
/// \file tree_file.h
/// The container every tree file uses (kd and BSP): a versioned header, tagged
/// sections, a CRC-32 over every byte but its own field (header included), and a
/// fingerprint of the scene's triangle data so a tree cannot be used with
/// another scene. Layout (little-endian):
///
///   offset  size  field
///   0       8     magic "BSPRTREE"
///   8       4     version (kTreeFileVersion)
///   12      4     kind (TreeKind)
///   16      8     scene fingerprint (scene_fingerprint)
///   24      8     triangle count of the scene
///   32      4     section count S
///   36      4     CRC-32 of bytes [0, 36) then [40, end) (version 1: [40, end) only)
///   40      S x { uint32 tag; uint32 reserved; uint64 size; size bytes; pad to 8 }

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "bsprt/error.h"
#include "bsprt/tree_kind.h"
#include "geometry/core/triangle_soup.h"

namespace bsprt {

/// Version written. Version 1 files (CRC not covering the header) are still read.
inline constexpr std::uint32_t kTreeFileVersion = 2;

/// A section tag from four characters, e.g. tree_tag("KNOD") (first char in the lowest byte).
constexpr std::uint32_t tree_tag(const char (&s)[5]) {
  return std::uint32_t(std::uint8_t(s[0])) | std::uint32_t(std::uint8_t(s[1])) << 8 |
         std::uint32_t(std::uint8_t(s[2])) << 16 | std::uint32_t(std::uint8_t(s[3])) << 24;
}
/// The CRC-32 a tree file of `version` stores at offset 36. Version 2 (and
/// later): every byte but the CRC field, header included. Version 1 covered only
/// [40, end), so its header's fingerprint and triangle count went unchecked
/// (`bsprt stats` printed a corrupt count; regression test in test_regressions.cpp).
std::uint32_t tree_file_crc(std::span<const std::byte> file, std::uint32_t version);

/// The four characters of a tag, for messages.
std::string tree_tag_name(std::uint32_t tag);


/// A 64-bit fingerprint of the triangle data (vertex coordinates of every
/// triangle's corners, in triangle order); equal soups give equal fingerprints.
std::uint64_t scene_fingerprint(const TriangleSoup& soup);

/// Collects sections and writes them as one tree file.
class TreeFileWriter {
 public:
  TreeFileWriter(TreeKind kind, const TriangleSoup& soup);
  /// Adds a section; tags must be unique within a file.
  void add_section(std::uint32_t tag, std::span<const std::byte> bytes);
  template <typename T>
  void add_array(std::uint32_t tag, const std::vector<T>& v) {
    add_section(tag, std::as_bytes(std::span<const T>(v)));
  }
  /// The whole file image (header, sections, CRC), as `write` puts it on disk.
  std::vector<std::byte> bytes() const;
  /// Writes the file; throws InputError when it cannot be written.
  void write(const std::string& path) const;

 private:
  TreeKind kind_;
  std::uint64_t fingerprint_;
  std::uint64_t triangle_count_;
  std::map<std::uint32_t, std::vector<std::byte>> sections_;
};

/// Reads and checks a tree file: magic, version, CRC, sizes. Throws InputError
/// naming the file and the problem (corrupt, truncated, wrong version, ...).
class TreeFileReader {
 public:
  explicit TreeFileReader(const std::string& path);
  /// Checks a file image held in memory (TreeFileWriter::bytes); `path` names
  /// it in messages. The image is copied once; sections are views into it.
  TreeFileReader(const std::string& path, const std::vector<std::byte>& image);
  /// The same, sharing the image instead of copying it (bsprt::Tree keeps
  /// its file once in memory, not once as bytes and again as sections).
  TreeFileReader(const std::string& path, std::shared_ptr<const std::vector<std::byte>> image);
  /// The whole file image the sections point into.
  std::span<const std::byte> image() const { return *image_; }
  TreeKind kind() const { return kind_; }
  /// The file's format version (1: its header is not covered by the CRC).
  std::uint32_t version() const { return version_; }
  /// Triangle count of the scene the tree was built for.
  std::uint64_t triangle_count() const { return triangle_count_; }
  const std::string& path() const { return path_; }
  /// Throws InputError unless the file was built for this scene (fingerprint
  /// and triangle count).
  void check_scene(const TriangleSoup& soup) const;
  /// The bytes of a section; throws InputError if it is missing.
  std::span<const std::byte> section(std::uint32_t tag) const;
  /// True when the file has a section with this tag.
  bool has_section(std::uint32_t tag) const { return sections_.count(tag) != 0; }
  /// A section as an array of T; throws InputError if its size is not a
  /// multiple of sizeof(T).
  template <typename T>
  std::vector<T> array(std::uint32_t tag) const;
  /// A section holding exactly one T; throws InputError otherwise.
  template <typename T>
  T record(std::uint32_t tag) const;

 private:
  std::string path_;
  std::uint32_t version_ = 0;
  TreeKind kind_{};
  std::uint64_t fingerprint_ = 0;
  std::uint64_t triangle_count_ = 0;
  std::shared_ptr<const std::vector<std::byte>> image_;
  std::map<std::uint32_t, std::span<const std::byte>> sections_;  ///< views into *image_
};

template <typename T>
std::vector<T> TreeFileReader::array(std::uint32_t tag) const {
  static_assert(std::is_trivially_copyable_v<T>, "tree file arrays hold plain data");
  const std::span<const std::byte> bytes = section(tag);
  if (bytes.size() % sizeof(T) != 0)
    throw InputError(path_, "section " + tree_tag_name(tag) + " has " + std::to_string(bytes.size()) +
                                " bytes, not a multiple of " + std::to_string(sizeof(T)));
  std::vector<T> v(bytes.size() / sizeof(T));
  if (!v.empty()) std::memcpy(v.data(), bytes.data(), bytes.size());
  return v;
}

template <typename T>
T TreeFileReader::record(std::uint32_t tag) const {
  const std::vector<T> v = array<T>(tag);
  if (v.size() != 1)
    throw InputError(path_, "section " + tree_tag_name(tag) + " must hold exactly one " + std::to_string(sizeof(T)) +
                                "-byte record, it has " + std::to_string(v.size() * sizeof(T)) + " bytes");
  return v[0];
}

/// The whole file at `path` (throws InputError when it cannot be read).
std::vector<std::byte> read_tree_file_image(const std::string& path);

/// Writes a file image (TreeFileWriter::bytes) to `path` (throws InputError when it cannot).
void write_tree_file_image(const std::string& path, std::span<const std::byte> image);

}  // namespace bsprt

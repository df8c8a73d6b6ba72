/// \file tree_file.cpp
/// The tree-file container of tree_file.h: header, tagged sections, CRC-32
/// (boost::crc_32_type) and the scene fingerprint.
#include "builder/tree_file.h"

#include <boost/crc.hpp>

#include <fstream>
#include <iterator>

#include "geometry/core/read_file.h"

namespace bsprt {
namespace {

constexpr char kMagic[8] = {'B', 'S', 'P', 'R', 'T', 'R', 'E', 'E'};
constexpr std::size_t kHeaderSize = 40;
constexpr std::size_t kCrcField = 36;  // the CRC's own 4 bytes, the only ones it does not cover
constexpr std::size_t kSectionHeader = 16;

std::size_t padded(std::size_t n) { return (n + 7) & ~std::size_t(7); }

template <typename T>
void put(std::vector<std::byte>& out, T value) {
  const std::size_t at = out.size();
  out.resize(at + sizeof(T));
  std::memcpy(out.data() + at, &value, sizeof(T));  // little-endian hosts only (x86-64, arm64)
}

template <typename T>
T get(const std::vector<std::byte>& in, std::size_t at) {
  T value;
  std::memcpy(&value, in.data() + at, sizeof(T));
  return value;
}

}  // namespace

std::vector<std::byte> read_tree_file_image(const std::string& path) {
  const std::string chars = read_file_bytes(path, "tree file");
  std::vector<std::byte> bytes(chars.size());
  if (!chars.empty()) std::memcpy(bytes.data(), chars.data(), chars.size());
  return bytes;
}

std::uint32_t tree_file_crc(std::span<const std::byte> file, std::uint32_t version) {
  if (file.size() < kHeaderSize) throw UsageError("tree_file_crc: a tree file has at least 40 bytes");
  boost::crc_32_type crc;
  if (version >= 2) crc.process_bytes(file.data(), kCrcField);
  crc.process_bytes(file.data() + kHeaderSize, file.size() - kHeaderSize);
  return crc.checksum();
}

std::string tree_tag_name(std::uint32_t tag) {
  std::string s = "'";
  for (int i = 0; i < 4; ++i) {
    const char c = char((tag >> (8 * i)) & 0xFF);
    s += (c >= 32 && c < 127) ? c : '?';
  }
  return s + "'";
}

std::uint64_t scene_fingerprint(const TriangleSoup& soup) {
  // FNV-1a over the bit patterns of every corner coordinate, triangle by triangle.
  std::uint64_t h = 0xcbf29ce484222325ull;
  auto mix = [&h](std::uint32_t word) {
    for (int i = 0; i < 4; ++i) {
      h ^= (word >> (8 * i)) & 0xFFu;
      h *= 0x100000001b3ull;
    }
  };
  for (std::uint32_t t = 0; t < soup.size(); ++t) {
    for (int c = 0; c < 3; ++c) {
      const Vec3f& p = soup.corner(t, c);
      for (int k = 0; k < 3; ++k) {
        std::uint32_t bits;
        const float f = p[k];
        std::memcpy(&bits, &f, 4);
        mix(bits);
      }
    }
  }
  return h;
}

TreeFileWriter::TreeFileWriter(TreeKind kind, const TriangleSoup& soup)
    : kind_(kind), fingerprint_(scene_fingerprint(soup)), triangle_count_(soup.size()) {}

void TreeFileWriter::add_section(std::uint32_t tag, std::span<const std::byte> bytes) {
  if (sections_.count(tag)) throw UsageError("tree file: section " + tree_tag_name(tag) + " added twice");
  sections_[tag].assign(bytes.begin(), bytes.end());
}

std::vector<std::byte> TreeFileWriter::bytes() const {
  std::vector<std::byte> out;
  out.insert(out.end(), reinterpret_cast<const std::byte*>(kMagic),
             reinterpret_cast<const std::byte*>(kMagic) + 8);
  put<std::uint32_t>(out, kTreeFileVersion);
  put<std::uint32_t>(out, std::uint32_t(kind_));
  put<std::uint64_t>(out, fingerprint_);
  put<std::uint64_t>(out, triangle_count_);
  put<std::uint32_t>(out, std::uint32_t(sections_.size()));
  put<std::uint32_t>(out, 0);  // CRC, filled below
  for (const auto& [tag, bytes] : sections_) {
    put<std::uint32_t>(out, tag);
    put<std::uint32_t>(out, 0);
    put<std::uint64_t>(out, bytes.size());
    out.insert(out.end(), bytes.begin(), bytes.end());
    out.resize(padded(out.size()), std::byte{0});
  }
  const std::uint32_t crc = tree_file_crc(out, kTreeFileVersion);
  std::memcpy(out.data() + kCrcField, &crc, 4);
  return out;
}

void TreeFileWriter::write(const std::string& path) const { write_tree_file_image(path, bytes()); }

void write_tree_file_image(const std::string& path, std::span<const std::byte> out) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  if (!f) throw InputError(path, "cannot create tree file");
  f.write(reinterpret_cast<const char*>(out.data()), std::streamsize(out.size()));
  f.close();
  if (!f) throw InputError(path, "cannot write tree file");
}

TreeFileReader::TreeFileReader(const std::string& path)
    : TreeFileReader(path, std::make_shared<const std::vector<std::byte>>(read_tree_file_image(path))) {}

TreeFileReader::TreeFileReader(const std::string& path, const std::vector<std::byte>& image)
    : TreeFileReader(path, std::make_shared<const std::vector<std::byte>>(image)) {}

TreeFileReader::TreeFileReader(const std::string& path, std::shared_ptr<const std::vector<std::byte>> image)
    : path_(path), image_(std::move(image)) {
  const std::vector<std::byte>& in = *image_;
  if (in.size() < kHeaderSize)
    throw InputError(path, "truncated tree file: " + std::to_string(in.size()) + " bytes, header needs 40");
  if (std::memcmp(in.data(), kMagic, 8) != 0) throw InputError(path, "not a bsprt tree file (bad magic)");
  const auto version = get<std::uint32_t>(in, 8);
  if (version != kTreeFileVersion && version != 1)
    throw InputError(path, "tree file version " + std::to_string(version) + ", expected " +
                               std::to_string(kTreeFileVersion) + " (or 1)");
  version_ = version;
  if (get<std::uint32_t>(in, kCrcField) != tree_file_crc(in, version))
    throw InputError(path, "corrupt tree file (CRC mismatch) or truncated");
  const auto kind = get<std::uint32_t>(in, 12);
  if (kind != std::uint32_t(TreeKind::Kd) && kind != std::uint32_t(TreeKind::Bsp))
    throw InputError(path, "unknown tree kind " + std::to_string(kind));
  kind_ = TreeKind(kind);
  fingerprint_ = get<std::uint64_t>(in, 16);
  triangle_count_ = get<std::uint64_t>(in, 24);
  const auto count = get<std::uint32_t>(in, 32);
  std::size_t at = kHeaderSize;
  for (std::uint32_t i = 0; i < count; ++i) {
    if (in.size() - at < kSectionHeader)
      throw InputError(path, "truncated tree file: section " + std::to_string(i) + " header missing");
    const auto tag = get<std::uint32_t>(in, at);
    const auto size = get<std::uint64_t>(in, at + 8);
    at += kSectionHeader;
    if (size > in.size() - at || padded(size) > in.size() - at)
      throw InputError(path, "truncated tree file: section " + tree_tag_name(tag) + " needs " +
                                 std::to_string(size) + " bytes");
    if (sections_.count(tag)) throw InputError(path, "section " + tree_tag_name(tag) + " appears twice");
    sections_[tag] = std::span<const std::byte>(in.data() + at, static_cast<std::size_t>(size));
    at += padded(size);
  }
  if (at != in.size())
    throw InputError(path, std::to_string(in.size() - at) + " unexpected bytes after the last section");
}

void TreeFileReader::check_scene(const TriangleSoup& soup) const {
  if (triangle_count_ != soup.size())
    throw InputError(path_, "tree was built for a scene with " + std::to_string(triangle_count_) +
                                " triangles, this scene has " + std::to_string(soup.size()));
  if (fingerprint_ != scene_fingerprint(soup))
    throw InputError(path_, "tree was built for another scene (fingerprint mismatch)");
}

std::span<const std::byte> TreeFileReader::section(std::uint32_t tag) const {
  const auto it = sections_.find(tag);
  if (it == sections_.end()) throw InputError(path_, "section " + tree_tag_name(tag) + " is missing");
  return it->second;
}

}  // namespace bsprt

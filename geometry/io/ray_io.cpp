/// \file ray_io.cpp
/// `.rays` and `.hits` files (shared/formats.md): a 16-byte header (magic,
/// uint32 version 1, uint64 N) and N fixed-size records, little-endian. Ray and
/// Hit are byte-compatible with the records, so records are read and written
/// in one block. N is checked against the file size before anything is
/// allocated, so garbage never causes a huge allocation.
#include "bsprt/io.h"

#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "bsprt/compare.h"
#include "bsprt/error.h"

namespace bsprt {

static_assert(std::endian::native == std::endian::little,
              "ray/hit files are little-endian; add byte swapping for this platform");

namespace {

constexpr std::uint32_t kVersion = 1;
constexpr std::uint64_t kHeaderBytes = 16;

/// What differs between the two formats.
struct Format {
  const char* magic;      ///< 4 characters
  std::uint64_t record;   ///< bytes per record
  const char* noun;       ///< "rays" or "hits", for messages
};
constexpr Format kRays{"RAYS", sizeof(Ray), "rays"};
constexpr Format kHits{"HITS", sizeof(Hit), "hits"};

/// Printable form of 4 magic bytes (non-printable bytes as \xNN).
std::string show_magic(const char* m) {
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const auto c = static_cast<unsigned char>(m[i]);
    if (c >= 32 && c < 127) {
      s += char(c);
    } else {
      static const char* hex = "0123456789abcdef";
      s += "\\x";
      s += hex[c >> 4];
      s += hex[c & 15];
    }
  }
  return s;
}

/// Reads and checks a file of `fmt` records (T = Ray or Hit).
template <typename T>
std::vector<T> read_records(const std::string& path, const Format& fmt) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError(path, std::string("is a directory, not a file"));
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw InputError(path, std::string("cannot open file for reading"));
  const std::streamoff end = in.tellg();
  if (end < 0) throw InputError(path, "cannot determine the file size");
  const auto size = static_cast<std::uint64_t>(end);
  if (size == 0) throw InputError(path, std::string("file is empty (expected a .") + fmt.noun + " file)");
  if (size < kHeaderBytes)
    throw InputError(path, "truncated header: file has " + std::to_string(size) + " bytes, a ." + fmt.noun +
                               " header needs 16");
  char header[kHeaderBytes];
  in.seekg(0);
  if (!in.read(header, sizeof(header))) throw InputError(path, "cannot read the header");
  if (std::memcmp(header, fmt.magic, 4) != 0)
    throw InputError(path, "bad magic '" + show_magic(header) + "', expected '" + fmt.magic + "'");
  std::uint32_t version;
  std::uint64_t n;
  std::memcpy(&version, header + 4, 4);
  std::memcpy(&n, header + 8, 8);
  if (version != kVersion)
    throw InputError(path, "unsupported version " + std::to_string(version) + ", expected " +
                               std::to_string(kVersion));
  const std::uint64_t payload = size - kHeaderBytes;
  if (n > payload / fmt.record || payload != n * fmt.record) {
    // n * record may overflow for garbage n: say so instead of printing a wrapped number.
    const std::string expected = n > (UINT64_MAX - kHeaderBytes) / fmt.record
                                     ? std::string("more than 2^64")
                                     : std::to_string(kHeaderBytes + n * fmt.record);
    throw InputError(path, "expected " + expected + " bytes for " + std::to_string(n) + " " + fmt.noun +
                               ", file has " + std::to_string(size));
  }
  std::vector<T> records(static_cast<std::size_t>(n));
  if (n > 0 && !in.read(reinterpret_cast<char*>(records.data()), static_cast<std::streamsize>(payload)))
    throw InputError(path, std::string("read error after the header"));
  return records;
}

/// Writes the header and the records; throws InputError when writing fails.
void write_records(const std::string& path, const Format& fmt, const void* data, std::uint64_t n) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw InputError(path, std::string("cannot open file for writing"));
  char header[kHeaderBytes];
  std::memcpy(header, fmt.magic, 4);
  std::memcpy(header + 4, &kVersion, 4);
  std::memcpy(header + 8, &n, 8);
  out.write(header, sizeof(header));
  if (n > 0) out.write(static_cast<const char*>(data), static_cast<std::streamsize>(n * fmt.record));
  out.flush();
  if (!out) throw InputError(path, "write failed after " + std::to_string(n) + " " + fmt.noun);
}

}  // namespace

std::vector<Ray> read_rays(const std::string& path) { return read_records<Ray>(path, kRays); }

void write_rays(const std::string& path, std::span<const Ray> rays) {
  write_records(path, kRays, rays.data(), rays.size());
}

std::vector<Hit> read_hits(const std::string& path) {
  std::vector<Hit> hits = read_records<Hit>(path, kHits);
  for (std::size_t i = 0; i < hits.size(); ++i)
    if (const char* why = hit_record_problem(hits[i]))
      throw InputError(path, "hit record " + std::to_string(i) + " is " + why + " (formats.md)");
  return hits;
}

void write_hits(const std::string& path, std::span<const Hit> hits) {
  // What read_hits refuses is not written: a file this writes can be read
  // back (Python's write_hits wrote t = NaN with a triangle; review of 2026-12-07).
  for (std::size_t i = 0; i < hits.size(); ++i)
    if (const char* why = hit_record_problem(hits[i]))
      throw UsageError("write_hits: hit record " + std::to_string(i) + " is " + why + " (formats.md); not writing " + path);
  write_records(path, kHits, hits.data(), hits.size());
}

}  // namespace bsprt

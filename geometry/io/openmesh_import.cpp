/// \file openmesh_import.cpp
/// The recording importer (a subclass of OpenMesh::IO::BaseImporter) and the
/// guarded call into OpenMesh's IO layer.

#include "geometry/io/openmesh_import.h"

#include <OpenMesh/Core/IO/IOManager.hh>
#include <OpenMesh/Core/IO/importer/BaseImporter.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include <algorithm>
#include <iostream>
#include <mutex>
#include <sstream>

#include "bsprt/error.h"

namespace bsprt::detail {
namespace {

using OpenMesh::EdgeHandle;
using OpenMesh::FaceHandle;
using OpenMesh::HalfedgeHandle;
using OpenMesh::VertexHandle;
namespace omio = OpenMesh::IO;

/// Appends vertices and faces to an OpenMeshResult as the reader delivers
/// them. Unlike OpenMesh's ImporterT (which builds a halfedge mesh and drops
/// faces that would make it non-manifold or that use invalid handles), this
/// importer keeps every face, with whatever indices it carries; load_mesh
/// validates them afterwards. Attributes (normals, colors, texture
/// coordinates, status) are ignored.
class SoupImporter final : public omio::BaseImporter {
 public:
  explicit SoupImporter(OpenMeshResult& out) : out_(out) { out_.face_begin.assign(1, 0); }

  VertexHandle add_vertex(const OpenMesh::Vec3f& p) override {
    out_.vertices.emplace_back(p[0], p[1], p[2]);
    return VertexHandle(static_cast<int>(out_.vertices.size() - 1));
  }
  // Readers that parse doubles (OBJ) hand over doubles; round once to float.
  VertexHandle add_vertex(const OpenMesh::Vec3d& p) override {
    return add_vertex(OpenMesh::Vec3f(static_cast<float>(p[0]), static_cast<float>(p[1]),
                                      static_cast<float>(p[2])));
  }
  VertexHandle add_vertex() override { return add_vertex(OpenMesh::Vec3f(0.f, 0.f, 0.f)); }
  void set_point(VertexHandle vh, const OpenMesh::Vec3f& p) override {
    // PLY adds the vertex first and sets its point after reading the record.
    if (vh.idx() >= 0 && static_cast<std::size_t>(vh.idx()) < out_.vertices.size())
      out_.vertices[static_cast<std::size_t>(vh.idx())] = Vec3f(p[0], p[1], p[2]);
  }
  FaceHandle add_face(const VHandles& idx) override {
    for (const VertexHandle& vh : idx) out_.corners.push_back(vh.idx());
    out_.face_begin.push_back(out_.corners.size());
    return FaceHandle(static_cast<int>(out_.face_count() - 1));
  }
  std::size_t n_vertices() const override { return out_.vertices.size(); }
  std::size_t n_faces() const override { return out_.face_count(); }
  std::size_t n_edges() const override { return 0; }
  void reserve(unsigned int nv, unsigned int, unsigned int nf) override {
    // Header counts may lie; cap the reservation so a hostile header cannot
    // make us allocate gigabytes before the pre-pass's checks have run.
    out_.vertices.reserve(std::min(nv, 1u << 24));
    out_.face_begin.reserve(std::min(nf, 1u << 24) + 1u);
  }

  // Connectivity-building entry points: only OpenMesh's own .om reader uses
  // them, and we never hand it a file. Attributes: ignored.
  HalfedgeHandle add_edge(VertexHandle, VertexHandle) override { return HalfedgeHandle(); }
  FaceHandle add_face(HalfedgeHandle) override { return FaceHandle(); }
  void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<OpenMesh::Vec2f>&) override {}
  void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<OpenMesh::Vec3f>&) override {}
  void set_face_texindex(FaceHandle, int) override {}
  void set_halfedge(VertexHandle, HalfedgeHandle) override {}
  void set_normal(VertexHandle, const OpenMesh::Vec3f&) override {}
  void set_normal(VertexHandle, const OpenMesh::Vec3d&) override {}
  void set_color(VertexHandle, const OpenMesh::Vec3uc&) override {}
  void set_color(VertexHandle, const OpenMesh::Vec4uc&) override {}
  void set_color(VertexHandle, const OpenMesh::Vec3f&) override {}
  void set_color(VertexHandle, const OpenMesh::Vec4f&) override {}
  void set_texcoord(VertexHandle, const OpenMesh::Vec2f&) override {}
  void set_status(VertexHandle, const OpenMesh::Attributes::StatusInfo&) override {}
  void set_next(HalfedgeHandle, HalfedgeHandle) override {}
  void set_face(HalfedgeHandle, FaceHandle) override {}
  void request_face_texcoords2D() override {}
  void set_texcoord(HalfedgeHandle, const OpenMesh::Vec2f&) override {}
  void set_texcoord(VertexHandle, const OpenMesh::Vec3f&) override {}
  void set_texcoord(HalfedgeHandle, const OpenMesh::Vec3f&) override {}
  void set_status(HalfedgeHandle, const OpenMesh::Attributes::StatusInfo&) override {}
  void set_color(EdgeHandle, const OpenMesh::Vec3uc&) override {}
  void set_color(EdgeHandle, const OpenMesh::Vec4uc&) override {}
  void set_color(EdgeHandle, const OpenMesh::Vec3f&) override {}
  void set_color(EdgeHandle, const OpenMesh::Vec4f&) override {}
  void set_status(EdgeHandle, const OpenMesh::Attributes::StatusInfo&) override {}
  void set_normal(FaceHandle, const OpenMesh::Vec3f&) override {}
  void set_normal(FaceHandle, const OpenMesh::Vec3d&) override {}
  void set_color(FaceHandle, const OpenMesh::Vec3uc&) override {}
  void set_color(FaceHandle, const OpenMesh::Vec4uc&) override {}
  void set_color(FaceHandle, const OpenMesh::Vec3f&) override {}
  void set_color(FaceHandle, const OpenMesh::Vec4f&) override {}
  void set_status(FaceHandle, const OpenMesh::Attributes::StatusInfo&) override {}
  void add_texture_information(int, std::string) override {}

 private:
  OpenMeshResult& out_;
};

/// Keeps the first 4096 characters written to it and counts the rest, so that
/// a reader printing in a loop cannot exhaust memory.
class CappedBuffer final : public std::streambuf {
 public:
  std::string text() const {
    return dropped_ ? text_ + "... (" + std::to_string(dropped_) + " more characters)" : text_;
  }

 protected:
  int_type overflow(int_type c) override {
    if (!traits_type::eq_int_type(c, traits_type::eof())) put(traits_type::to_char_type(c));
    return traits_type::not_eof(c);
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    for (std::streamsize i = 0; i < n; ++i) put(s[i]);
    return n;
  }

 private:
  void put(char c) {
    if (text_.size() < kCap) text_.push_back(c);
    else ++dropped_;
  }
  static constexpr std::size_t kCap = 4096;
  std::string text_;
  std::size_t dropped_ = 0;
};

/// Library code must not print. OpenMesh writes warnings to its global
/// streams omerr (forwarded to std::cerr), omlog and omout, and in a few
/// places straight to std::cerr. A read first runs with the three OpenMesh
/// streams disabled (QuietOpenMesh), which touches nothing of the process's
/// own: std::cerr keeps its buffer, and other threads' output is theirs. Only
/// when OpenMesh fails, which the pre-pass makes rare, is the read repeated
/// with CaptureOpenMeshOutput, so that the error can quote what OpenMesh
/// said: for that read std::cerr writes into a capped string (another
/// thread's std::cerr output during it is captured too, and swapping the
/// buffer races with a concurrent writer; an API review of 2026-12-07 found
/// that every load did this). Reconnecting the OpenMesh streams instead would
/// leak: mostream::disconnect never frees the target that connect allocated.
/// Both only under the global read mutex.
class QuietOpenMesh {
 public:
  QuietOpenMesh()
      : err_(::omerr().is_enabled()), log_(::omlog().is_enabled()), out_(::omout().is_enabled()) {
    ::omerr().flush();
    ::omerr().disable();
    ::omlog().disable();
    ::omout().disable();
  }
  ~QuietOpenMesh() {
    ::omerr().flush();  // dropped while disabled
    if (err_) ::omerr().enable();
    if (log_) ::omlog().enable();
    if (out_) ::omout().enable();
  }
  QuietOpenMesh(const QuietOpenMesh&) = delete;
  QuietOpenMesh& operator=(const QuietOpenMesh&) = delete;

 private:
  bool err_, log_, out_;
};

class CaptureOpenMeshOutput {
 public:
  CaptureOpenMeshOutput()
      : log_was_enabled_(::omlog().is_enabled()), out_was_enabled_(::omout().is_enabled()) {
    ::omerr().flush();
    ::omlog().disable();
    ::omout().disable();
    saved_cerr_ = std::cerr.rdbuf(&buffer_);
  }
  ~CaptureOpenMeshOutput() {
    ::omerr().flush();
    std::cerr.rdbuf(saved_cerr_);
    if (log_was_enabled_) ::omlog().enable();
    if (out_was_enabled_) ::omout().enable();
  }
  CaptureOpenMeshOutput(const CaptureOpenMeshOutput&) = delete;
  CaptureOpenMeshOutput& operator=(const CaptureOpenMeshOutput&) = delete;

  std::string text() {
    ::omerr().flush();
    return buffer_.text();
  }

 private:
  CappedBuffer buffer_;
  bool log_was_enabled_;
  bool out_was_enabled_;
  std::streambuf* saved_cerr_ = nullptr;
};

std::mutex& openmesh_mutex() {
  static std::mutex m;
  return m;
}

}  // namespace

OpenMeshResult openmesh_read(const std::string& path, const std::string& bytes,
                             const std::string& ext, bool stl_binary) {
  OpenMeshResult result;
  bool ok = false;
  {
    std::lock_guard<std::mutex> lock(openmesh_mutex());
    const auto read = [&] {
      result = OpenMeshResult{};
      SoupImporter importer(result);
      std::istringstream in(bytes, std::ios::in | std::ios::binary);
      omio::Options opt = stl_binary ? omio::Options(omio::Options::Binary) : omio::Options();
      try {
        ok = omio::IOManager().read(in, ext, importer, opt);
      } catch (const std::exception& e) {
        ok = false;
        result.log += std::string("exception: ") + e.what() + "\n";
      }
    };
    {
      QuietOpenMesh quiet;
      read();
    }
    if (!ok) {  // again, to quote OpenMesh in the error
      CaptureOpenMeshOutput capture;
      read();
      result.log = capture.text() + result.log;
    }
  }
  if (!ok) {
    std::string msg = "OpenMesh could not read this " + ext + " file";
    if (!result.log.empty()) msg += " (OpenMesh says: " + result.log + ")";
    while (!msg.empty() && (msg.back() == '\n' || msg.back() == ' ')) msg.pop_back();
    throw InputError(path, msg);
  }
  return result;
}

}  // namespace bsprt::detail

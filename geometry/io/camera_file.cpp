/// \file camera_file.cpp
/// Camera files (camera_file.h), parsed with nlohmann::json.
#include "geometry/io/camera_file.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>

#include "bsprt/error.h"

namespace bsprt {
namespace {

using json = nlohmann::json;

/// 1-based line of byte offset `at` in `text`.
std::int64_t line_of(const std::string& text, std::size_t at) {
  return 1 + std::count(text.begin(), text.begin() + std::ptrdiff_t(std::min(at, text.size())), '\n');
}

/// A 3-vector field of camera `who` (messages name the camera: JSON values
/// carry no line numbers once parsed).
Vec3f vec_field(const std::string& path, const json& cam, const std::string& who, const char* key) {
  if (!cam.contains(key)) throw InputError(path, who + ": field \"" + key + "\" is missing");
  const json& v = cam[key];
  if (!v.is_array() || v.size() != 3 || !std::all_of(v.begin(), v.end(), [](const json& x) { return x.is_number(); }))
    throw InputError(path, who + ": \"" + key + "\" must be an array of 3 numbers");
  const Vec3f r(v[0].get<float>(), v[1].get<float>(), v[2].get<float>());
  if (!is_finite(r)) throw InputError(path, who + ": \"" + key + "\" is not finite");
  return r;
}

}  // namespace

std::vector<NamedCamera> read_camera_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot open camera file");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::parse_error& e) {
    throw InputError(path, line_of(text, e.byte > 0 ? e.byte - 1 : 0), std::string("not valid JSON: ") + e.what());
  }
  if (!doc.is_object() || !doc.contains("cameras") || !doc["cameras"].is_array())
    throw InputError(path, "expected an object with an array \"cameras\"");
  std::vector<NamedCamera> out;
  for (std::size_t i = 0; i < doc["cameras"].size(); ++i) {
    const json& c = doc["cameras"][i];
    std::string who = "camera " + std::to_string(i);
    if (!c.is_object()) throw InputError(path, who + " is not an object");
    if (!c.contains("name") || !c["name"].is_string()) throw InputError(path, who + ": \"name\" (a string) is missing");
    NamedCamera nc;
    nc.name = c["name"].get<std::string>();
    who += " \"" + nc.name + "\"";
    if (c.contains("scene")) {
      if (!c["scene"].is_string()) throw InputError(path, who + ": \"scene\" must be a string");
      nc.scene = c["scene"].get<std::string>();
    }
    if (c.contains("what") && c["what"].is_string()) nc.what = c["what"].get<std::string>();
    nc.camera.vp = vec_field(path, c, who, "vp");
    nc.camera.vi = vec_field(path, c, who, "vi");
    nc.camera.vu = vec_field(path, c, who, "vu");
    if (!c.contains("fov") || !c["fov"].is_number()) throw InputError(path, who + ": \"fov\" (degrees) is missing");
    nc.camera.fov = c["fov"].get<float>();
    if (!(nc.camera.fov > 0.0f && nc.camera.fov < 180.0f))
      throw InputError(path, who + ": fov " + std::to_string(nc.camera.fov) + " is not in (0, 180) degrees");
    const Vec3f view = nc.camera.vi - nc.camera.vp;
    if (dot(view, view) == 0.0f) throw InputError(path, who + ": vp and vi are the same point");
    const Vec3f side = cross(view, nc.camera.vu);
    if (dot(side, side) == 0.0f) throw InputError(path, who + ": vu is parallel to the view direction (or zero)");
    for (const NamedCamera& o : out)
      if (o.name == nc.name) throw InputError(path, who + ": the name is used twice");
    out.push_back(std::move(nc));
  }
  if (out.empty()) throw InputError(path, "the file has no cameras");
  return out;
}

NamedCamera camera_from_spec(const std::string& spec) {
  // FILE:NAME when the part after the last ':' is not itself a path to an existing file.
  const std::size_t colon = spec.rfind(':');
  const bool named = colon != std::string::npos && !std::ifstream(spec).good();
  const std::string path = named ? spec.substr(0, colon) : spec;
  const std::vector<NamedCamera> cams = read_camera_file(path);
  std::string names;
  for (const NamedCamera& c : cams) names += (names.empty() ? "" : ", ") + c.name;
  if (!named) {
    if (cams.size() != 1)
      throw UsageError("--camera " + path + " holds " + std::to_string(cams.size()) + " cameras; name one: " + path +
                       ":NAME (" + names + ")");
    return cams[0];
  }
  const std::string name = spec.substr(colon + 1);
  for (const NamedCamera& c : cams)
    if (c.name == name) return c;
  throw UsageError("--camera: " + path + " has no camera '" + name + "' (it has: " + names + ")");
}

const NamedCamera* camera_for_scene(const std::vector<NamedCamera>& file, const std::string& scene_file_name) {
  for (const NamedCamera& c : file)
    if (!c.scene.empty() && c.scene == scene_file_name) return &c;
  return nullptr;
}

}  // namespace bsprt

/// \file camera_file.cpp
/// Camera files (camera_file.h), parsed with nlohmann::json.
#include "geometry/io/camera_file.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <system_error>

#include "bsprt/error.h"
#include "geometry/core/read_file.h"

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
  const std::string text = read_file_bytes(path, "camera file");
  json doc;
  // A key given twice in one object: JSON leaves it open, nlohmann keeps the
  // last one; a camera file that says fov twice is refused (review of
  // 2026-12-07). The parser's callback sees each key of each object in order.
  std::vector<std::vector<std::string>> keys;  // per open object
  const auto no_duplicates = [&](int, json::parse_event_t event, json& parsed) {
    if (event == json::parse_event_t::object_start) keys.emplace_back();
    if (event == json::parse_event_t::object_end && !keys.empty()) keys.pop_back();
    if (event == json::parse_event_t::key && !keys.empty()) {
      const std::string k = parsed.get<std::string>();
      if (std::find(keys.back().begin(), keys.back().end(), k) != keys.back().end())
        throw InputError(path, "the key \"" + k + "\" is given twice in one object");
      keys.back().push_back(k);
    }
    return true;
  };
  try {
    doc = json::parse(text, no_duplicates);
  } catch (const json::parse_error& e) {
    throw InputError(path, line_of(text, e.byte > 0 ? e.byte - 1 : 0), std::string("not valid JSON: ") + e.what());
  }
  if (!doc.is_object() || !doc.contains("cameras") || !doc["cameras"].is_array())
    throw InputError(path, "expected an object with an array \"cameras\"");
  for (const auto& [key, value] : doc.items())
    if (key != "cameras") throw InputError(path, "unknown top-level key \"" + key + "\" (a camera file holds \"cameras\")");
  std::vector<NamedCamera> out;
  for (std::size_t i = 0; i < doc["cameras"].size(); ++i) {
    const json& c = doc["cameras"][i];
    std::string who = "camera " + std::to_string(i);
    if (!c.is_object()) throw InputError(path, who + " is not an object");
    if (!c.contains("name") || !c["name"].is_string()) throw InputError(path, who + ": \"name\" (a string) is missing");
    NamedCamera nc;
    nc.name = c["name"].get<std::string>();
    who += " \"" + nc.name + "\"";
    // A misspelt key ("fov_deg", "secne") was ignored, and the camera used a
    // default or none at all.
    static const char* const known[] = {"name", "scene", "what", "vp", "vi", "vu", "fov"};
    for (const auto& [key, value] : c.items())
      if (std::find(std::begin(known), std::end(known), key) == std::end(known))
        throw InputError(path, who + ": unknown key \"" + key + "\" (the keys are name, scene, what, vp, vi, vu, fov)");
    if (c.contains("what") && !c["what"].is_string()) throw InputError(path, who + ": \"what\" must be a string");
    if (c.contains("scene")) {
      if (!c["scene"].is_string()) throw InputError(path, who + ": \"scene\" must be a string");
      nc.scene = c["scene"].get<std::string>();
    }
    if (c.contains("what")) nc.what = c["what"].get<std::string>();
    nc.camera.vp = vec_field(path, c, who, "vp");
    nc.camera.vi = vec_field(path, c, who, "vi");
    nc.camera.vu = vec_field(path, c, who, "vu");
    if (!c.contains("fov")) throw InputError(path, who + ": field \"fov\" (degrees) is missing");
    if (!c["fov"].is_number()) throw InputError(path, who + ": \"fov\" must be a number (degrees)");
    nc.camera.fov = c["fov"].get<float>();
    if (const std::string problem = camera_problem(nc.camera); !problem.empty())
      throw InputError(path, who + ": " + problem);
    for (const NamedCamera& o : out)
      if (o.name == nc.name) throw InputError(path, who + ": the name is used twice");
    out.push_back(std::move(nc));
  }
  if (out.empty()) throw InputError(path, "the file has no cameras");
  return out;
}

NamedCamera camera_from_spec(const std::string& spec) {
  // FILE:NAME, split at the first ':' whose left part is an existing file, so
  // that a name may hold ':' too; the whole spec is FILE when it is a file.
  std::error_code ec;
  std::size_t colon = std::string::npos;
  if (!std::filesystem::is_regular_file(spec, ec))
    for (std::size_t at = spec.find(':'); at != std::string::npos; at = spec.find(':', at + 1))
      if (std::filesystem::is_regular_file(spec.substr(0, at), ec)) {
        colon = at;
        break;
      }
  if (colon == std::string::npos && !std::filesystem::is_regular_file(spec, ec)) colon = spec.rfind(':');
  const bool named = colon != std::string::npos;
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

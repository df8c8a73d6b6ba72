#pragma once
/// \file camera_file.h
/// Camera files (`--camera FILE[:NAME]`, docs/rendering.md "Camera files"): JSON,
///   { "cameras": [ { "name": "sponza-atrium", "scene": "sponza.obj",
///                    "vp": [x, y, z], "vi": [x, y, z], "vu": [x, y, z], "fov": 65,
///                    "what": "one line for people" }, ... ] }
/// vp: eye, vi: point looked at, vu: up, fov: vertical field of view in degrees
/// (Embree's tutorial flags). "scene" is the mesh's file name; `bsprt bench
/// --cameras FILE` uses a scene's camera for its primary rays. bench/cameras.json
/// holds the project's views.

#include <string>
#include <vector>

#include "geometry/scenes/camera.h"

namespace bsprt {

/// One camera of a camera file.
struct NamedCamera {
  std::string name;   ///< unique within the file
  std::string scene;  ///< mesh file name it is for ("" = any)
  std::string what;   ///< description
  Camera camera;
};

/// Reads every camera of a camera file. Throws InputError naming the file, the
/// line and what is wrong: malformed JSON, a missing or mistyped field, a
/// non-finite number, vp == vi, vu parallel to the view, fov outside (0, 180),
/// a repeated name.
std::vector<NamedCamera> read_camera_file(const std::string& path);

/// `spec` is FILE (a file with exactly one camera) or FILE:NAME. Throws
/// InputError (bad file) or UsageError (no camera of that name: the names are listed).
NamedCamera camera_from_spec(const std::string& spec);

/// The camera of `file` for the mesh whose file name is `scene_file_name`, if any.
const NamedCamera* camera_for_scene(const std::vector<NamedCamera>& file, const std::string& scene_file_name);

}  // namespace bsprt

// Scene: the one JSON document the CLI, the benches and the protocol share.
//
// Plain data; parsing and printing live in scene.cpp, the meaning of every
// key in docs/scene.md. Positions, step and unit_distance are world lengths.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "grid.h"
#include "vec.h"

namespace pvr::core {

struct VolumeSpec {
  std::string file;        // a volume file (any registered format); or
  std::string procedural;  // a procedural volume name with
  IVec3 dims{64, 64, 64};  // its resolution
  std::optional<Vec3> spacing;  // procedural only: overrides the default isotropic spacing
};

// One control point: scalar -> linear RGB colour and opacity (per unit_distance).
struct TransferPoint {
  double scalar = 0;
  double r = 0, g = 0, b = 0;
  double opacity = 0;
};

struct TransferFunctionSpec {
  // Sorted by scalar; linear between points, clamped outside them.
  std::vector<TransferPoint> points;
  // World length over which `opacity` applies. 0 means "one voxel": the
  // grid's smallest spacing, resolved when the volume is known.
  double unitDistance = 0;
};

enum class Projection { kOrthographic, kPerspective };

struct CameraSpec {
  Projection projection = Projection::kPerspective;
  Vec3 eye{0, 0, 0};
  Vec3 lookAt{0, 0, 0};
  Vec3 up{0, 0, 1};
  double height = 0;      // orthographic: view height in world units
  double fovYDeg = 30;    // perspective: vertical field of view
  bool automatic = true;  // no "camera" key: fit the volume (resolveDefaults)
};

struct ImageSpec {
  int width = 512;
  int height = 512;
  std::array<double, 4> background{0, 0, 0, 1};  // straight (not premultiplied) RGBA
};

struct SamplingSpec {
  double step = 0;              // world length; 0 = half the smallest spacing
  bool preintegrated = false;
  double earlyTermination = 1;  // a_max; 1 = off (rays run to the end)
};

struct ShadingSpec {
  bool enabled = false;
  double ambient = 0.2;
  double diffuse = 0.7;
  double specular = 0.3;
  double shininess = 32;
  // Light direction in camera space (x right, y up, z towards the viewer);
  // (0,0,1) is the headlight.
  Vec3 lightDirection{0, 0, 1};
};

struct Scene {
  VolumeSpec volume;
  TransferFunctionSpec transfer;
  CameraSpec camera;
  ImageSpec image;
  SamplingSpec sampling;
  ShadingSpec shading;
};

// Parses a scene document. Relative paths (volume file, ParaView preset)
// resolve against `baseDir`. Unknown keys, wrong types and bad values throw
// pvr::Error naming the key path ("camera.fov_y_deg: must be in (0, 180)").
Scene parseScene(const nlohmann::json& doc, const std::string& baseDir);
Scene loadSceneFile(const std::string& path);
// The inverse of parseScene: every key written, defaults included.
nlohmann::json sceneToJson(const Scene& scene);

// Reads a ParaView transfer-function preset (JSON array of presets or one
// preset object with "RGBPoints" and optionally "Points" for opacity) as
// it is: colours and opacities are merged into one set of points.
TransferFunctionSpec loadParaViewPreset(const std::string& path);

// Fills what depends on the volume: unit distance, step, and the automatic
// camera (looks at the centre from -y, tilted, the whole domain in view).
void resolveDefaults(Scene& scene, const GridGeometry& grid);

}  // namespace pvr::core

// Scene: the one JSON document the CLI, the benches and the protocol share.
//
// Plain data and the functions that read, print and complete it; the
// meaning of every key is in docs/scene.md. Positions, step and
// unit_distance are world lengths. One file per job: scene.cpp (the
// document), scene_*_section.cpp (one section each, read and written),
// paraview_preset.cpp (ParaView presets), scene_defaults.cpp (what needs
// the volume: unit distance, step, the automatic camera).
#pragma once

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "grid.h"
#include "vec.h"

namespace pvr::core {

struct VolumeSpec {
  std::string file;         // a volume file (any registered format); or
  std::string procedural;   // a procedural volume name; or
  std::string computation;  // a user computation's name (node/computations/), run on the ranks;
  IVec3 dims{64, 64, 64};   // procedural and computation: the resolution
  std::optional<Vec3> spacing;  // procedural and computation: overrides the default isotropic spacing
  int timestep = 0;             // 0-based step of a time series (the scene's "timestep")
};

// One control point: scalar -> colour and opacity (per unit_distance). The
// colour is display sRGB (1 = white), as ParaView presets and colour
// pickers mean it; the renderer converts it to linear light once
// (evaluateMedium, transfer.h), so a swatch renders as it looks.
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
  // The scene gave no transfer function: `points` is a placeholder until
  // the data's value range is known, then a white ramp over it
  // (resolveDataDefaults).
  bool automatic = false;
  // A ParaView preset without "absolute": true: its points' scalars are
  // stretched from their own span onto the data's value range when that is
  // known (resolveDataDefaults), as ParaView applies a preset.
  bool rescaleToData = false;
};

enum class Projection { kOrthographic, kPerspective };

struct CameraSpec {
  Projection projection = Projection::kPerspective;
  Vec3 eye{0, 0, 0};
  Vec3 lookAt{0, 0, 0};
  Vec3 up{0, 0, 1};
  double height = 0;      // orthographic: view height in world units
  double fovYDeg = 30;    // perspective: vertical field of view
  bool automatic = true;  // no "camera" key: automaticCamera, set by resolveDefaults
};

// The largest image side, in pixels, the renderer library renders: a scene
// may ask for up to kMaxImageSide x kMaxImageSide, and Camera refuses more.
// A full frame that size is 4 GiB of float RGBA, for pvr-render (one
// process, writing a file). It is NOT the size a session may stream: frames
// sent to a client must also fit the wire protocol (proto::checkImageSize
// in protocol/image_limits.h, a smaller limit), which the node checks when
// a scene is set; and images exchanged between ranks must fit the sparse
// image codec (kImageCodecMaxPixels, image_codec.h). The renderer does not
// depend on protocol/, so these are separate facts.
inline constexpr int kMaxImageSide = 16384;

struct ImageSpec {
  int width = 512;
  int height = 512;
  std::array<double, 4> background{0, 0, 0, 1};  // straight (not premultiplied) RGBA, colour in display sRGB
};

// The most samples a ray may take across the scene's domain: a step so
// small that the domain's diagonal needs more is refused when the scene is
// resolved (a step of 1e-9 would otherwise render for hours, and one of
// 1e-20 would not advance at all). 2^20 samples is a quarter-voxel step
// across the diagonal of a 240000-voxel-wide grid.
inline constexpr double kMaxSamplesPerRay = 1 << 20;

// The most a sampling.target_psnr may ask (dB): beyond what float
// rendering resolves.
inline constexpr double kMaxTargetPsnr = 120;

// The opacity at which a ray stops unless the scene says otherwise: what
// lies behind is hidden, so it is not sampled. The light it would add is
// at most 1 - a_max = 1e-4 of full scale, a third of the finest step of
// 8-bit sRGB output (1/255/12.92 = 3.0e-4 linear, near black) and below
// half-float EXR's precision at 1; bench scenes' RMSE against the exact
// rendering is unchanged to four digits, while the CT head's shaded frame
// takes 0.72 of its time and the MRI head's 0.86
// (bench/results/early_termination.txt).
inline constexpr double kDefaultEarlyTermination = 0.9999;

struct SamplingSpec {
  double step = 0;              // world length; 0 = half the smallest spacing
  bool preintegrated = false;
  double earlyTermination = kDefaultEarlyTermination;  // a_max; 1 = off (rays run to the end)
  // "target_psnr": > 0 lets the renderer pick the step of each region,
  // from step / 8 to 8 step, to meet this PSNR in dB (raycast/step_levels.h);
  // 0 = off, every region at `step`.
  double targetPsnr = 0;
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
  // A scene document that does not say "enabled" (parseScene):
  // resolveDefaults turns shading on for 3-D data (every dimension above
  // one node), off for a slice or a line. A ShadingSpec built in code says
  // what it means.
  bool automatic = false;
};

// One volume of a scene: its data, its transfer function, whether it shows.
struct SceneVolume {
  std::string name = "volume";  // unique in the scene; the single "volume" form's is "volume"
  VolumeSpec source;
  TransferFunctionSpec transfer;
  bool visible = true;
};

struct Scene {
  // At least one. Each keeps its own grid and transfer function; where they
  // overlap their media mix (docs/scene.md, "Several volumes"). Code that
  // renders one volume only takes the first.
  std::vector<SceneVolume> volumes{1};
  // Steering parameters of a computation volume, by name ("parameters").
  std::map<std::string, double> parameters;
  CameraSpec camera;
  ImageSpec image;
  SamplingSpec sampling;
  ShadingSpec shading;
};

// Parses a scene document. Relative paths (volume file, ParaView preset
// file) resolve against `baseDir`. Unknown keys, wrong types and bad values
// throw pvr::Error naming the key path ("camera.fov_y_deg: must be in (0, 180)").
Scene parseScene(const nlohmann::json& doc, const std::string& baseDir);
// Reads and parses a scene file; relative paths resolve against its directory
// and every error starts with the file's path.
Scene loadSceneFile(const std::string& path);
// The inverse of parseScene: every key written, defaults included, except
// the values that mean "not set yet" (docs/scene.md, "Printing a scene").
nlohmann::json sceneToJson(const Scene& scene);

// The "camera" section alone, read (errors name "camera.<key>") and written
// as in a scene document; the camera read is not automatic.
CameraSpec parseCameraSection(const nlohmann::json& section);
nlohmann::json cameraSectionToJson(const CameraSpec& camera);

// The camera of a scene without a "camera" section, for a width x height
// image of `grid`: perspective, 30 degrees vertical field of view, up +z,
// looking at the domain's centre from the -y side turned 30 degrees about
// +z towards +x and raised 20 degrees, at the distance where the domain's
// bounding sphere enlarged by 5 % (half a voxel for a one-node grid) fits
// the narrower field of view. The one
// place that computes it; docs/scene.md "camera" says the same.
CameraSpec automaticCamera(const GridGeometry& grid, int width, int height);
// The same for the box [lo, hi] (several volumes: their union); minSpacing
// sizes a box that is a point.
CameraSpec automaticCamera(Vec3 lo, Vec3 hi, double minSpacing, int width, int height);

// Fills what depends on the volume: unit distance (the smallest spacing),
// step (half of it) and, for an automatic camera, automaticCamera. Throws
// pvr::Error for an invalid grid. Afterwards nothing is automatic.
// Shading without "enabled" is resolved too (on for 3-D data).
void resolveDefaults(Scene& scene, const GridGeometry& grid);
// The same for a scene of several volumes, grids[i] being volume i's: each
// volume's unit distance is its own smallest spacing; the step is half the
// smallest spacing of all, the automatic camera frames the union of their
// domains, shading is on when every one is 3-D. One grid: the form above.
void resolveDefaults(Scene& scene, const std::vector<GridGeometry>& grids);

// A white ramp of opacity 0 at `min` to 1 at `max` (a one-value range gets
// a span of 1 above it): the transfer function of a scene that names none.
TransferFunctionSpec rampTransfer(double min, double max);

// Fills what depends on the data's values, [min, max] over the finite
// voxels of the whole volume: an automatic transfer function becomes
// rampTransfer(min, max), and a preset to rescale has its scalars mapped
// linearly from its first..last point onto [min, max]. Both are done once:
// afterwards the function is neither automatic nor to rescale.
void resolveDataDefaults(TransferFunctionSpec& transfer, double min, double max);

}  // namespace pvr::core

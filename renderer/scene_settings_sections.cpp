// The scene's "image", "sampling" and "shading" sections: how to render.
#include "scene_json.h"
#include "scene_sections.h"

namespace pvr::core {

using namespace scene_json;

ImageSpec parseImage(const json& v) {
  const std::string path = "image";
  requireObject(v, path, {"width", "height", "background"});
  ImageSpec img;
  auto side = [&](const char* key, int& out) {
    const json* k = find(v, key);
    if (!k) return;
    const std::string p = childPath(path, key);
    const std::int64_t n = asInteger(*k, p);
    if (n < 1 || n > kMaxImageSide)
      fail(p, "must be in 1.." + std::to_string(kMaxImageSide) + ", got " + std::to_string(n));
    out = int(n);
  };
  side("width", img.width);
  side("height", img.height);
  if (const json* bg = find(v, "background")) {
    const std::string p = path + ".background";
    if (!bg->is_array() || bg->size() != 4)
      fail(p, "must be an array of 4 numbers [r, g, b, a], got " + describeValue(*bg));
    for (std::size_t i = 0; i < 4; ++i) img.background[i] = unitInterval((*bg)[i], indexPath(p, i));
  }
  return img;
}

json imageToJson(const ImageSpec& image) {
  return {{"width", image.width}, {"height", image.height}, {"background", image.background}};
}

SamplingSpec parseSampling(const json& v) {
  const std::string path = "sampling";
  requireObject(v, path, {"step", "preintegrated", "early_termination", "target_psnr"});
  SamplingSpec s;
  if (const json* k = find(v, "step")) s.step = positive(*k, path + ".step");
  if (const json* k = find(v, "preintegrated")) s.preintegrated = asBool(*k, path + ".preintegrated");
  if (const json* k = find(v, "early_termination")) {
    s.earlyTermination = asNumber(*k, path + ".early_termination");
    if (!(s.earlyTermination > 0 && s.earlyTermination <= 1))
      fail(path + ".early_termination", "must be in (0, 1], got " + numberText(s.earlyTermination));
  }
  if (const json* k = find(v, "target_psnr")) {
    s.targetPsnr = asNumber(*k, path + ".target_psnr");
    if (!(s.targetPsnr >= 0 && s.targetPsnr <= kMaxTargetPsnr))
      fail(path + ".target_psnr", "must be in [0, " + numberText(kMaxTargetPsnr) + "] dB (0 = off), got " +
                                      numberText(s.targetPsnr));
    if (s.targetPsnr > 0 && s.preintegrated)
      fail(path + ".target_psnr", "chooses the step of plain sampling; it cannot be combined with preintegrated");
  }
  return s;
}

json samplingToJson(const SamplingSpec& sampling) {
  // Step 0 ("half a voxel") is the absent key.
  json out = {{"preintegrated", sampling.preintegrated}, {"early_termination", sampling.earlyTermination}};
  if (sampling.step > 0) out["step"] = sampling.step;
  if (sampling.targetPsnr > 0) out["target_psnr"] = sampling.targetPsnr;
  return out;
}

ShadingSpec parseShading(const json& v) {
  const std::string path = "shading";
  requireObject(v, path, {"enabled", "ambient", "diffuse", "specular", "shininess", "light_direction"});
  ShadingSpec s;
  s.automatic = true;
  if (const json* k = find(v, "enabled")) {
    s.enabled = asBool(*k, path + ".enabled");
    s.automatic = false;
  }
  if (const json* k = find(v, "ambient")) s.ambient = nonNegative(*k, path + ".ambient");
  if (const json* k = find(v, "diffuse")) s.diffuse = nonNegative(*k, path + ".diffuse");
  if (const json* k = find(v, "specular")) s.specular = nonNegative(*k, path + ".specular");
  if (const json* k = find(v, "shininess")) s.shininess = positive(*k, path + ".shininess");
  if (const json* k = find(v, "light_direction")) {
    s.lightDirection = asVec3(*k, path + ".light_direction");
    if (!(length(s.lightDirection) > 0)) fail(path + ".light_direction", "must not be the zero vector");
  }
  return s;
}

json shadingToJson(const ShadingSpec& shading) {
  // "enabled" left to the data is the absent key.
  json out = {{"ambient", shading.ambient},
          {"diffuse", shading.diffuse},
          {"specular", shading.specular},
          {"shininess", shading.shininess},
          {"light_direction", toJson(shading.lightDirection)}};
  if (!shading.automatic) out["enabled"] = shading.enabled;
  return out;
}

}  // namespace pvr::core

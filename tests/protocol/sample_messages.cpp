#include "sample_messages.h"

#include <numeric>

namespace pvr::proto::testing {
namespace {

ImageFrame sampleImage() {
  // A 4 x 3 RGB frame with a gradient, uncompressed.
  ImageFrame image;
  image.frameNumber = 7;
  image.width = 4;
  image.height = 3;
  image.format = PixelFormat::kRgb8;
  image.compression = Compression::kNone;
  image.timing = {0.125, 1.5, 0.25, 0.0625, 0.03125};
  image.pixels.resize(4 * 3 * 3);
  std::iota(image.pixels.begin(), image.pixels.end(), std::uint8_t{10});
  return image;
}

}  // namespace

std::vector<Message> sampleMessages() {
  AuthChallenge challenge;
  std::iota(challenge.nonce.begin(), challenge.nonce.end(), std::uint8_t{1});
  AuthResponse response;
  std::iota(response.mac.begin(), response.mac.end(), std::uint8_t{0xA0});
  const std::vector<ClusterSpec> figure5Layout{
      // paper 003, Figure 5: 4 rendering clusters of 16 in 2 groups, 2 compositing clusters of 15
      {ClusterRole::kRender, 16, 0},    {ClusterRole::kRender, 16, 0},    {ClusterRole::kRender, 16, 1},
      {ClusterRole::kRender, 16, 1},    {ClusterRole::kComposite, 15, 0}, {ClusterRole::kComposite, 15, 0},
      {ClusterRole::kCollector, 1, 0}};

  std::vector<Message> samples{
      Hello{"pvrsh 0.1"},
      Welcome{"pvrd 0.1", 96, true},
      challenge,
      response,
      Ok{},
      ErrorMessage{ErrorCode::kDatasetNotFound, "dataset \"brain.slc\" is not in the catalog"},
      Close{"client quit"},
      JobHello{"5f1e0c7a9b2d4e6f8a0b1c2d3e4f5a6b5f1e0c7a9b2d4e6f8a0b1c2d3e4f5a6b"},
      SessionOpen{96, figure5Layout, "astro-42"},
      SessionReady{96, figure5Layout},
      SetScene{"brain.slc", R"({"image":{"width":512,"height":512}})"},
      SetLayout{{{ClusterRole::kRender, 32, 0}, {ClusterRole::kComposite, 31, 0}}},
      RenderFrame{},
      RenderRotation{{0, 1, 0}, 15, 59, 60},
      RenderTimeSteps{0, 48, 2},
      RenderSteps{96, 4},
      RenderInteractive{4, {0, 1, 0}, 15, 60},
      sampleImage(),
      Cancel{42},
      StatusRequest{},
      StatusReply{{{"connected", "yes"}, {"dataset", "brain.slc"}, {"imagesz", "512,512"}}},
      PerformanceRequest{PerformanceQuery::kCompositing, kAllClusters},
      PerformanceReply{PerformanceQuery::kMemory, R"({"clusters":[{"index":0,"bytes":16777216}]})"},
      CatalogRequest{},
      CatalogReply{{{"brain", 1, "brain.nii", "nifti", {256, 256, 20}, "int16", ""},
                    {"marschner_lobb", 1, "marschner_lobb.json", "raw+json", {41, 41, 41}, "float32", ""},
                    {"visible_human_256", 40, "visible_human_256.series.json", "series", {256, 256, 256}, "uint8", ""},
                    {"scan64", 1, "scan64.nrrd", "nrrd", {0, 0, 0}, "", "cannot be loaded: float64 is not supported"}}},
      Heartbeat{},
  };
  return samples;
}

std::string seedFileName(const Message& message) { return std::string(messageInfo(message).name) + ".bin"; }

std::vector<std::uint8_t> seedFrame(const Message& message, std::size_t index) {
  const bool reply = std::holds_alternative<Ok>(message) || std::holds_alternative<ErrorMessage>(message) ||
                     std::holds_alternative<ImageFrame>(message);
  return encode(message, static_cast<std::uint32_t>(index + 1), reply ? kFlagFinal : 0);
}

}  // namespace pvr::proto::testing

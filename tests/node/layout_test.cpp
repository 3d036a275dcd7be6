// Layout rules (layout.h) and the collector's pixel codes, serially.
#include <catch2/catch.hpp>

#include "frame_pixels.h"
#include "layout.h"

using namespace pvr;
using proto::ClusterRole;

TEST_CASE("an empty layout is one render cluster of every rank, rank 0 included") {
  const auto l = node::makeLayout({}, 4);
  REQUIRE(l.clusters.size() == 1);
  CHECK(l.clusters[0].ranks == std::vector<int>{0, 1, 2, 3});
  CHECK_FALSE(l.dedicatedMaster);
  CHECK(l.groups == 1);
}

TEST_CASE("two clusters of one group split the scanlines, two groups take alternate frames") {
  const auto band = node::makeLayout({{ClusterRole::kRender, 2, 0}, {ClusterRole::kRender, 2, 0}}, 4);
  CHECK(band.groups == 1);
  CHECK(band.clusters[1].band == 1);
  CHECK(band.clusters[1].bands == 2);
  CHECK(band.clusters[1].ranks == std::vector<int>{2, 3});
  const auto time = node::makeLayout({{ClusterRole::kRender, 0, 5}, {ClusterRole::kRender, 0, 7}}, 5);
  CHECK(time.groups == 2);
  CHECK(time.clusters[0].ranks.size() + time.clusters[1].ranks.size() == 5);
  CHECK(time.clusters[1].group == 1);
}

TEST_CASE("clusters covering all but one rank leave rank 0 as a dedicated collector") {
  const auto l = node::makeLayout({{ClusterRole::kRender, 2, 0}, {ClusterRole::kComposite, 1, 0}}, 4);
  CHECK(l.dedicatedMaster);
  CHECK(l.clusters[0].ranks == std::vector<int>{1, 2});
  CHECK(l.clusters[0].compositor == 1);
  CHECK(l.clusters[1].serves == std::vector<int>{0});
  CHECK(l.clusterOfRank[0] == -1);
}

TEST_CASE("a cache cluster serves the render clusters of its group, j mod M") {
  const auto l = node::makeLayout({{ClusterRole::kRender, 1, 0}, {ClusterRole::kRender, 1, 0}, {ClusterRole::kCache, 1, 0}}, 4);
  CHECK(l.dedicatedMaster);
  CHECK(l.clusters[0].cacheCluster == 2);
  CHECK(l.clusters[1].cacheCluster == 2);
  CHECK(l.clusters[2].serves == std::vector<int>{0, 1});
  CHECK(l.clusters[2].ranks == std::vector<int>{3});
  CHECK(node::roleName(ClusterRole::kCache) == "cache");
  CHECK_THROWS_WITH(node::makeLayout({{ClusterRole::kRender, 2, 0}, {ClusterRole::kCache, 1, 5}}, 4),
                    Catch::Contains("cache cluster of group 5 has no render cluster to serve"));
}

TEST_CASE("impossible layouts are refused with a reason") {
  CHECK_THROWS_WITH(node::makeLayout({{ClusterRole::kRender, 8, 0}}, 4), Catch::Contains("job of 4"));
  CHECK_THROWS_WITH(node::makeLayout({{ClusterRole::kComposite, 4, 0}}, 4), Catch::Contains("no render cluster"));
  CHECK_THROWS_WITH(node::makeLayout({{ClusterRole::kRender, 2, 0}, {ClusterRole::kComposite, 2, 1}}, 4),
                    Catch::Contains("no render cluster to serve"));
  CHECK_THROWS(node::makeLayout({{ClusterRole::kRender, 1, 0}}, 4));
}

TEST_CASE("bands cover every row once") {
  int next = 0;
  for (int b = 0; b < 3; ++b) {
    const auto r = node::bandRect(10, 64, b, 3);
    CHECK(r.y0 == next);
    next = r.y1;
  }
  CHECK(next == 64);
}

TEST_CASE("the collector's frames decode to its sRGB pixels, compressed only when that pays") {
  core::Image image = core::Image::fullFrame(7, 5);
  image.at(3, 2) = {0.5f, 0.25f, 0.125f, 0.5f};
  const std::array<double, 4> background{0.1, 0.2, 0.3, 1};
  for (auto format : {proto::PixelFormat::kRgb8, proto::PixelFormat::kRgba8}) {
    const auto raw = node::srgbPixels(image, background, format);
    REQUIRE(raw.size() == 7 * 5 * proto::channelCount(format));
    for (auto c : {proto::Compression::kNone, proto::Compression::kRle, proto::Compression::kZlib}) {
      proto::ImageFrame f;
      f.width = 7;
      f.height = 5;
      f.format = format;
      node::setFramePixels(f, image, background, c);
      // A flat frame with one odd pixel compresses, so the wanted code is kept.
      CHECK(f.compression == c);
      const auto decoded = proto::decompressPixels(f);
      REQUIRE(std::holds_alternative<std::vector<std::uint8_t>>(decoded));
      CHECK(std::get<std::vector<std::uint8_t>>(decoded) == raw);
    }
  }
  // Noise does not compress: the frame goes out raw.
  core::Image noise = core::Image::fullFrame(16, 16);
  std::uint32_t seed = 12345;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      const auto next = [&] { return float((seed = seed * 1664525u + 1013904223u) >> 8) / float(1 << 24); };
      noise.at(x, y) = {next(), next(), next(), 1.0f};
    }
  proto::ImageFrame f;
  f.width = f.height = 16;
  f.format = proto::PixelFormat::kRgb8;
  node::setFramePixels(f, noise, background, proto::Compression::kRle);
  CHECK(f.compression == proto::Compression::kNone);
  CHECK(f.pixels == node::srgbPixels(noise, background, f.format));
}

// The coarse frame of an interactive render (proto::RenderInteractive):
// the wave renders, composites and collects a frame of 1/reduction of the
// pixels per axis, and the collector sends it at that size; the client
// zooms it to the image size (docs/runtime.md, "Progressive refinement").
// Sending it small is the point: converting, compressing, sending and
// decoding a frame cost by its pixels, and an upscaled frame has r^2 times
// the pixels of the information it carries.
#pragma once

#include "image.h"
#include "scene.h"

namespace pvr::node {

// Pixels along an axis of `size` pixels at 1/reduction: rounded up, so a
// coarse frame never has fewer than one pixel, nor covers less of the view
// once zoomed by `reduction`.
int reducedSize(int size, int reduction);

// While it lives, `image` is reduced to 1/reduction per axis (reduction 1:
// unchanged); then restored. Every rank holds one for the same wave, so
// the render, compositing and collecting steps agree on the size.
class ReducedImage {
 public:
  ReducedImage(core::ImageSpec& image, int reduction);
  ~ReducedImage() { image_ = full_; }
  ReducedImage(const ReducedImage&) = delete;
  ReducedImage& operator=(const ReducedImage&) = delete;

 private:
  core::ImageSpec& image_;
  core::ImageSpec full_;
};

}  // namespace pvr::node

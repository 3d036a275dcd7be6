// The coarse frame of an interactive render (proto::RenderInteractive):
// the wave renders, composites and collects a frame of 1/reduction of the
// pixels per axis, and the collector upscales it to the session's image
// size, so that every client sees frames of one size (docs/runtime.md,
// "Progressive refinement").
#pragma once

#include "image.h"
#include "scene.h"

namespace pvr::node {

// Pixels along an axis of `size` pixels at 1/reduction: rounded up, so a
// coarse frame never has fewer than one pixel, nor covers less of the view.
int reducedSize(int size, int reduction);

// `coarse` (a full frame) stretched to width x height by bilinear
// interpolation between pixel centres, clamped at the edges. Colours are
// premultiplied, so blending them is blending light and coverage alike.
core::Image upscaleFrame(const core::Image& coarse, int width, int height);

// While it lives, `image` is reduced to 1/reduction per axis (reduction 1:
// unchanged); then restored. Every rank holds one for the same wave, so
// the render, compositing and collecting steps agree on the size.
class ReducedImage {
 public:
  ReducedImage(core::ImageSpec& image, int reduction);
  ~ReducedImage() { image_ = full_; }
  ReducedImage(const ReducedImage&) = delete;
  ReducedImage& operator=(const ReducedImage&) = delete;
  // The size frames are sent at.
  const core::ImageSpec& full() const { return full_; }

 private:
  core::ImageSpec& image_;
  core::ImageSpec full_;
};

}  // namespace pvr::node

// Filling the kernel's inputs (kernel.h): what a brick, the render options
// and a camera ray say. One place for the single-volume caster
// (raycaster.cpp) and the several-volume one (scene_renderer.cpp), so both
// march a volume's samples from the same numbers.
#pragma once

#include <vector>

#include "../brick.h"
#include "../camera.h"
#include "../region.h"
#include "kernel.h"
#include "macrocells.h"
#include "raycaster.h"
#include "step_levels.h"

namespace pvr::core {

// Voxels, strides, owned and stored boxes, cell clamps, spacing and
// macrocells of `brick`; the classification table is the caller's.
void setBrick(KernelParams& p, const Brick& brick, const MacrocellGrid& macrocells);

// The direction octants (kernel::octantOf) of the camera's rays through
// the pixels of `rect`, those with the most rays first.
std::vector<int> frameOctants(const Camera& camera, const PixelRect& rect);

// The fields rays leap by, per octant (MacrocellGrid::leapFields); `fields`
// must outlive p. Without it every octant leaps by distance() (setBrick).
void setLeapFields(KernelParams& p, const MacrocellGrid::LeapFields& fields);

// Ownership by a region instead of the owned box: the region's faces in
// index units, clipped to the domain [0, dims - 1], the far face closed
// where the region reaches beyond the domain (raycaster.h, restrictTo).
void ownRegion(KernelParams& p, const GridGeometry& grid, const WorldRegion& region);

// The one-volume classification: the plain table, the pre-integration
// tables when there are any (null: plain), and the step's world length.
// Both tables must outlive p.
void setTables(KernelParams& p, const TransferTable& table, const PreintegratedTable* preintegrated,
               double step);

// Quality chosen by error: `levels`' field in p (filled but for it), and
// in `atLevel` a copy of p per level with that level's table and step
// (tables[l], 2^l fineStep), and p's clear cells where the level's table
// has the same transparent ends; p.atLevel points to it. The tables and
// atLevel must outlive p.
void setLevels(KernelParams& p, const StepLevels& levels, const std::vector<TransferTable>& tables,
               double fineStep, std::vector<KernelParams>& atLevel);

// Early termination and shading parameters of `options`. `specularTable`
// (specularTable() of the same shininess) must outlive p.
void setOptions(KernelParams& p, const RenderOptions& options, const float* specularTable);

// kSpecularTableSize values of x^shininess over [0, 1].
std::vector<float> specularTable(double shininess);

// The camera ray in `grid`'s index space, sample k at world distance
// k * step, without the lighting vectors (an unshaded kernel reads none:
// they were a third of a ray's setup on the peer scene).
RaySetup raySetup(const Ray& ray, const GridGeometry& grid, double step);

// raySetup() with the headlight's vectors: the light fixed in camera space,
// the viewer looking back along the ray.
RaySetup raySetup(const Ray& ray, const GridGeometry& grid, double step, const Vec3& lightWorld);

}  // namespace pvr::core

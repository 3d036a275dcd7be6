// A batch rank's brick, read while MPI starts (pvr-node --batch), when
// PVR_EARLY_READ=1 asks for it.
//
// MPI_Init takes 0.4-0.6 s on one host of 2 cores with 8 ranks, most of it
// waiting on the launcher with the cores idle, and a first frame's rank
// then spends about as long reading its brick and preprocessing it (the
// bounds pass over every voxel). Open MPI's launcher names the rank and the
// world's size in the environment before MPI_Init, and the scene names all
// that places a brick (grid, decomposition, ghost layers): so a thread
// started before MPI_Init opens the volume as the frame will
// (openFrameVolume), builds the same k-d tree and reads this rank's box,
// while the main thread waits in MPI_Init. The frame takes that brick when
// it asks for exactly that box of exactly that volume; any other box, a
// failed early read (the frame reads again and reports the error where it
// always did), a volume read whole and scattered or a balanced
// decomposition (it reads twice) reads as before.
//
// The thread calls no MPI. It reads with the frame's reader, so the brick,
// its bounds and its value range are those of a read after MPI_Init; its
// load times stay the reader's own seconds, which overlap `start`.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "frame.h"

namespace pvr::node {

class EarlyRead {
 public:
  // Starts the thread when PVR_EARLY_READ=1 and the launcher's environment
  // names this rank and the world's size (OMPI_COMM_WORLD_RANK,
  // OMPI_COMM_WORLD_SIZE); `scene`
  // loads the batch scene as the frame will (it runs on the thread, and
  // whatever it throws only stops the early read).
  EarlyRead(std::function<core::Scene()> scene, const FrameOptions& options);
  ~EarlyRead();  // waits for the thread
  EarlyRead(const EarlyRead&) = delete;
  EarlyRead& operator=(const EarlyRead&) = delete;

  // For FrameOptions::openVolume: opens the volume as openSceneVolume does;
  // the source's readBox hands over the early brick (once) when it asks for
  // its box with the histogram's counts off, and reads otherwise.
  VolumeOpener opener() const;

  // Whether the frame took the early brick.
  bool handedOver() const;

  struct State;  // early_read.cpp

 private:
  std::shared_ptr<State> state_;
};

}  // namespace pvr::node

// The frame that starts a placement beside the frames copies its picture and layers for it
// (frame/placement_beside.cpp), with a compute pass: a transfer copy of these storage images
// ran at a twentieth of the memory's speed on an NVIDIA H100 (docs/performance.md).
#ifndef STRATA_SHARED_PLACEMENT_SNAPSHOT_H
#define STRATA_SHARED_PLACEMENT_SNAPSHOT_H

#include "common.h"

#define SNAPSHOT_GROUP 8
#define SNAPSHOT_BINDING_FINAL 0        // image2D rgba8: the frame's picture
#define SNAPSHOT_BINDING_LAYERS 1       // image2DArray rgba16f: its layers
#define SNAPSHOT_BINDING_FINAL_COPY 2   // the copies the placement reads
#define SNAPSHOT_BINDING_LAYERS_COPY 3

STRATA_BEGIN

struct SnapshotParams {
  uvec2 size;
  uint layer_count;
  uint pad0;
};

STRATA_END

#endif

// Summed-area table of a float32 image (row-major buffer, viewport-sized), in three dispatches
// that need no forward progress between workgroups (reduce, then scan):
//   sums:    per 32x32 tile, the sum of each tile row and tile column
//   carries: per image row, an exclusive scan of its tile-row sums over the tiles to its left;
//            per image column, the same over the tiles above
//   scan:    per tile, a local 2D inclusive scan seeded with those carries (and the corner sum
//            of everything above-left, reduced from the column carries) gives the final values
#ifndef STRATA_SHARED_SUMMED_AREA_TABLE_H
#define STRATA_SHARED_SUMMED_AREA_TABLE_H

#include "common.h"

#define SAT_TILE 32
#define SAT_GROUP_ROWS 8  // a workgroup is SAT_TILE x SAT_GROUP_ROWS threads
#define SAT_RUN 4         // elements each thread scans serially along a tile line
#define SAT_CARRY_GROUP 64

#define SAT_BINDING_INPUT 0
#define SAT_BINDING_OUTPUT 1
#define SAT_BINDING_CARRIES \
  2  // row carries [tiles_x][height], then column carries [tiles_y][width]

STRATA_BEGIN
struct SatParams {
  uint width;
  uint height;
  uint tiles_x;
  uint tiles_y;
  uint layers;  // a stack of images, one after the other in the buffers (workgroup z / y)
  uint pad0;
  uint pad1;
  uint pad2;
};
STRATA_END

#endif

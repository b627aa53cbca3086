// Shared by the summed-area-table shaders: one tile of the input in shared memory.
layout(local_size_x = SAT_TILE, local_size_y = SAT_GROUP_ROWS) in;

layout(binding = SAT_BINDING_INPUT, std430) readonly buffer Input { float values[]; } src;
layout(push_constant) uniform Push { SatParams p; };

shared float tile[SAT_TILE][SAT_TILE + 1];  // +1: no bank conflicts down a column

uvec2 tile_origin() { return gl_WorkGroupID.xy * SAT_TILE; }

// Where the carries of image row y (for tile column tx) and of image column x (for tile row ty)
// live in the carries buffer.
// Each image of the stack has its own carries, one block after the other.
uint carries_per_image() { return p.tiles_x * p.height + p.tiles_y * p.width; }
uint row_carry_index(uint tx, uint y) { return gl_WorkGroupID.z * carries_per_image() + tx * p.height + y; }
uint column_carry_index(uint ty, uint x) {
  return gl_WorkGroupID.z * carries_per_image() + p.tiles_x * p.height + ty * p.width + x;
}
uint image_offset() { return gl_WorkGroupID.z * p.width * p.height; }

// Coalesced: each pass of the loop reads SAT_GROUP_ROWS rows of 32 consecutive floats.
void load_tile() {
  const uvec2 origin = tile_origin();
  const uint x = origin.x + gl_LocalInvocationID.x;
  for (uint r = gl_LocalInvocationID.y; r < SAT_TILE; r += SAT_GROUP_ROWS) {
    const uint y = origin.y + r;
    tile[r][gl_LocalInvocationID.x] =
        (x < p.width && y < p.height) ? src.values[image_offset() + y * p.width + x] : 0.0;
  }
}

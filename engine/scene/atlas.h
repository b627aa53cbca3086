// Anatomical atlases: a label volume (each voxel holds a region index) and a names file in AAL's
// format ("index name colour" per line, e.g. "2001 Precentral_L 1"). From them: each region's
// centroid in world space as a label, a region as a mask volume (for multi-volume rendering) and
// as a smoothed surface mesh (for the transparent-mesh path).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "engine/scene/scene.h"

namespace strata {

struct AtlasRegion {
  int index = 0;     // the value of its voxels in the label volume
  std::string name;  // as in the names file, e.g. "Precentral_L"
  int colour = 0;    // the names file's third column
};

std::vector<AtlasRegion> load_atlas_names(const std::filesystem::path& path);

// One label per region that has voxels, at its centroid (world space), text = region name with
// '_' as ' '; ids are region indices. Regions without voxels are skipped.
std::vector<Label> atlas_labels(const Volume& labels, const std::vector<AtlasRegion>& regions);

// The region a world point lies in (the label volume's nearest voxel), its name with '_' as ' '
// ("Thalamus R"); empty outside the volume, on index 0 or an index the names file does not list.
std::string atlas_region_at(const SceneAtlas& atlas, glm::vec3 world);
// The first of the scene's atlases that names the point; empty if none does.
std::string atlas_region_at(const Scene& scene, glm::vec3 world);

// A uint8 volume on the label volume's grid: 255 inside the region, 0 outside.
Volume atlas_mask(const Volume& labels, const AtlasRegion& region);

// A mask's transfer function: transparent up to the boundary between outside (0) and inside
// (255), `colour` inside, so the mask shows its region's shape and nothing of its box.
TransferFunction mask_transfer_function(const std::string& name, glm::vec4 colour);

// The region's boundary as a triangle mesh (marching cubes on the mask, then Taubin smoothing),
// in world space, with per-vertex normals.
Mesh atlas_surface(const Volume& labels, const AtlasRegion& region, int smoothing_iterations = 10);

}  // namespace strata

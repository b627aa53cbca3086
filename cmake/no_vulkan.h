// Forced into every file of strata_core, strata_scene (engine/CMakeLists.txt) and strata_labeling
// (labeling/CMakeLists.txt): the scene side builds without Vulkan, and a Vulkan header reached
// from it, directly or through another header, stops the build at the header's first use of this
// name.
#pragma GCC poison VK_HEADER_VERSION

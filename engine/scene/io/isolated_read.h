// Third-party parsers (Assimp for meshes, GDCM for DICOM) run in a child process, so that a crash,
// an assertion, an endless loop or a runaway allocation inside them becomes one strata::Error
// naming the file instead of taking strata down (docs/ARCHITECTURE.md, "Invariants").
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "engine/scene/scene.h"

namespace strata {

struct Segmentation;  // engine/scene/segmentation.h

// What one read in a child process may take. A zero field takes the default for the input's size.
struct ParserLimits {
  double seconds = 0.0;       // wall-clock time; also the child's CPU-time limit
  uint64_t memory_bytes = 0;  // memory the child may add to what it shares with strata
};

// The limits a read of `input` (a file, or a folder's files together) runs under: zero fields of
// `limits` become 120 s plus 1 s per 16 MiB of input, and max(2 GiB, 16 x the input's size) but
// not more than the memory the machine has available.
ParserLimits resolved_parser_limits(const std::filesystem::path& input, ParserLimits limits);

// Runs `read` in a forked child and returns what it returned, or throws one strata::Error:
// `read`'s own Error as it is, or "<file>: <parser> crashed (SIGSEGV)", "... took more than N s",
// "... needed more than N MiB of memory". `parser` names the reader in messages, e.g.
// "the mesh reader (Assimp)". `read` runs in the child only: it must not touch Vulkan or GLFW.
std::vector<Mesh> read_meshes_isolated(const std::filesystem::path& file, std::string_view parser,
                                       const ParserLimits& limits,
                                       const std::function<std::vector<Mesh>()>& read);
// The same for a volume; the child's warnings are appended to `warnings`.
Volume read_volume_isolated(const std::filesystem::path& file, std::string_view parser,
                            const ParserLimits& limits, std::vector<std::string>& warnings,
                            const std::function<Volume(std::vector<std::string>&)>& read);

// The same for a segmentation (its layers and regions).
Segmentation read_segmentation_isolated(
    const std::filesystem::path& file, std::string_view parser, const ParserLimits& limits,
    std::vector<std::string>& warnings,
    const std::function<Segmentation(std::vector<std::string>&)>& read);

// The same for texts (a DICOM folder's series, each as its fields).
std::vector<std::string> read_texts_isolated(const std::filesystem::path& file,
                                             std::string_view parser, const ParserLimits& limits,
                                             const std::function<std::vector<std::string>()>& read);

}  // namespace strata

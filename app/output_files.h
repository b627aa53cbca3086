// Where a command's outputs go, checked once its inputs are read and before it renders anything:
// every file it will write or remove can be written there, and none is a file it read (the scene,
// its volumes, transfer functions, meshes, label files and pictures: engine/core/files_read.h).
// Commands whose purpose is to save a file they read (the viewer's save-position, its `save` to
// the label file it opened) do not check that file.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "app/viewer/script.h"

namespace strata::app {

// A file `option` names: a UsageError (exit 2) when writing it would replace an input ("--layout:
// scene.json would replace the input scene.json; give another file"); an Error when it is a
// folder, or its folder does not exist or cannot be written to (saying which and why).
void check_output_file(const std::string& option, const std::filesystem::path& path);

// A folder `option` names and the files to be written (or removed) in it: an Error when it is a
// file, or cannot be made or written to (the nearest folder that exists is not writable), saying
// which and why; a UsageError when one of the files is an input, as check_output_file.
void check_output_folder(const std::string& option, const std::filesystem::path& folder,
                         const std::vector<std::filesystem::path>& files = {});
// Makes the folder and those above it; an Error naming the option, the folder and why not.
void create_output_folder(const std::string& option, const std::filesystem::path& folder);

// A sequence's numbered files in a folder (`video -o FOLDER`, --layout-dir, --still-layouts):
// frame_file_name(f, extension) for each frame. Before a run writes them, the files of an
// earlier run there (those named so, and no others) are removed, so the folder holds one run and
// `strata eval FOLDER/*` measures only it.
struct FrameFolder {
  std::string option;
  std::filesystem::path folder;
  const char* extension = "png";

  // The folder, the `count` files to write and the earlier run's to remove, as outputs.
  void check(size_t count) const;
  // Removes the earlier run's files (after check()), saying how many on stderr.
  void remove_earlier_frames() const;
};

// The files a viewer script writes (screenshot, capture, layout, record, report, save), each as
// an output named "SCRIPT:LINE: COMMAND"; `save` may write the label file the viewer opened
// (`labels`, --labels), as saving it is its purpose.
void check_script_outputs(const std::string& script, const std::vector<ScriptCommand>& commands,
                          const std::string& labels);

}  // namespace strata::app

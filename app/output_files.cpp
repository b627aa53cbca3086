#include "app/output_files.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <utility>

#include "app/commands.h"
#include "engine/core/error.h"
#include "engine/core/files_read.h"
#include "engine/core/frame_writer.h"

namespace strata::app {
namespace {

namespace fs = std::filesystem;

fs::path folder_of(const fs::path& path) {
  return path.parent_path().empty() ? fs::path(".") : path.parent_path();
}

void refuse_input(const std::string& option, const fs::path& path) {
  const std::optional<fs::path> input = input_replaced_by(path);
  if (!input) return;
  std::error_code error;
  const bool in_folder = fs::is_directory(*input, error);
  throw UsageError(option + ": " + path.string() + " would replace " +
                   (in_folder ? "a file of the input folder " : "the input ") + input->string() +
                   "; give another file");
}

// An existing folder that files can be made in; else an Error: "<option>: <what>: <reason>".
void check_writable_folder(const std::string& option, const std::string& what,
                           const fs::path& folder) {
  std::error_code error;
  const fs::file_status status = fs::status(folder, error);
  if (status.type() == fs::file_type::not_found)
    throw Error(option + ": " + what + ": the folder " + folder.string() + " does not exist");
  if (status.type() != fs::file_type::directory)
    throw Error(option + ": " + what + ": " + folder.string() + " is not a folder");
  if (::access(folder.c_str(), W_OK | X_OK) != 0)
    throw Error(option + ": " + what + ": cannot write into the folder " + folder.string() + ": " +
                std::strerror(errno));
}

}  // namespace

void check_output_file(const std::string& option, const fs::path& path) {
  refuse_input(option, path);
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (status.type() == fs::file_type::directory)
    throw Error(option + ": " + path.string() + ": is a folder; give a file name");
  // (a device or a pipe, -o /dev/null, is written directly, not through its folder)
  if (fs::exists(status) && status.type() != fs::file_type::regular) return;
  check_writable_folder(option, path.string(), folder_of(path));
}

void check_output_folder(const std::string& option, const fs::path& folder,
                         const std::vector<fs::path>& files) {
  for (const fs::path& file : files) refuse_input(option, file);
  // The folder, or the nearest one above it that exists: the rest is made there.
  fs::path existing = folder.lexically_normal();
  bool made = false;
  std::error_code error;
  while (!fs::exists(fs::symlink_status(existing, error)) && folder_of(existing) != existing) {
    existing = folder_of(existing);
    made = true;
  }
  check_writable_folder(option, folder.string() + (made ? ": cannot create the folder" : ""),
                        existing);
}

void create_output_folder(const std::string& option, const fs::path& folder) {
  std::error_code error;
  fs::create_directories(folder, error);
  if (error)
    throw Error(option + ": " + folder.string() + ": cannot create the folder: " + error.message());
}

void FrameFolder::check(size_t count) const {
  std::vector<fs::path> files = frame_files_in(folder, extension);
  for (size_t f = 0; f < count; ++f) files.push_back(folder / frame_file_name(f, extension));
  check_output_folder(option, folder, files);
}

void FrameFolder::remove_earlier_frames() const {
  const std::vector<fs::path> earlier = frame_files_in(folder, extension);
  for (const fs::path& file : earlier) {
    std::error_code error;
    fs::remove(file, error);
    if (error)
      throw Error(option + ": " + file.string() +
                  ": cannot remove a frame of an earlier run: " + error.message());
  }
  if (earlier.empty()) return;
  std::fprintf(stderr, "strata: %s: removed %zu %s files of an earlier run (%s to %s)\n",
               folder.string().c_str(), earlier.size(), extension,
               earlier.front().filename().c_str(), earlier.back().filename().c_str());
}

void check_script_outputs(const std::string& script, const std::vector<ScriptCommand>& commands,
                          const std::string& labels) {
  for (const ScriptCommand& c : commands) {
    const char* writing = c.spec().writes;
    // (a screenshot without a name gets a new one; save may write the label file opened)
    std::error_code error;
    if (!writing || c.word.empty() ||
        (c.name == "save" && !labels.empty() && fs::equivalent(c.word, labels, error)))
      continue;
    check_output_file(script + ":" + std::to_string(c.line) + ": " + writing, c.word);
  }
}

}  // namespace strata::app

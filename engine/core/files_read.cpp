#include "engine/core/files_read.h"

#include <sys/stat.h>

#include <mutex>
#include <vector>

namespace strata {
namespace {

struct FileRead {
  dev_t device = 0;
  ino_t inode = 0;
  bool folder = false;
  std::filesystem::path path;  // as the reader named it
};

struct FilesRead {
  std::mutex mutex;
  std::vector<FileRead> files;
};

FilesRead& files_read() {
  static FilesRead record;
  return record;
}

std::optional<struct stat> status_of(const std::filesystem::path& path) {
  struct stat s {};
  if (::stat(path.c_str(), &s) != 0) return std::nullopt;  // (follows links: the target counts)
  return s;
}

bool same(const FileRead& f, const struct stat& s) {
  return f.device == s.st_dev && f.inode == s.st_ino;
}

// The folder read whole that holds `path` at any depth (its real location: links resolved).
std::optional<std::filesystem::path> folder_holding(const std::vector<FileRead>& files,
                                                    const std::filesystem::path& path) {
  std::error_code error;
  std::filesystem::path folder = std::filesystem::canonical(path, error);
  if (error) return std::nullopt;
  while (folder.has_relative_path()) {
    folder = folder.parent_path();
    const std::optional<struct stat> s = status_of(folder);
    if (!s) return std::nullopt;
    for (const FileRead& f : files)
      if (f.folder && same(f, *s)) return f.path;
  }
  return std::nullopt;
}

}  // namespace

void record_file_read(const std::filesystem::path& path) {
  const std::optional<struct stat> s = status_of(path);
  if (!s) return;
  FilesRead& record = files_read();
  std::lock_guard lock(record.mutex);
  for (const FileRead& f : record.files)
    if (same(f, *s)) return;
  record.files.push_back({s->st_dev, s->st_ino, S_ISDIR(s->st_mode), path});
}

std::optional<std::filesystem::path> input_replaced_by(const std::filesystem::path& path) {
  const std::optional<struct stat> s = status_of(path);
  if (!s || S_ISDIR(s->st_mode)) return std::nullopt;
  FilesRead& record = files_read();
  std::lock_guard lock(record.mutex);
  for (const FileRead& f : record.files)
    if (!f.folder && same(f, *s)) return f.path;
  return folder_holding(record.files, path);
}

}  // namespace strata

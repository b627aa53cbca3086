// Files written whole or not at all. The bytes go to an unnamed file in the target's folder
// (O_TMPFILE; where the file system lacks it, "<path>.tmp-XXXXXX"), are flushed to the disk and
// given the target's name only when every one was written (a link, then a rename over the old
// file, on one file system). A failure, an exception or a kill before that leaves the old file
// as it was, or none, never a cut one.
#pragma once

#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>

namespace strata {

class AtomicFile {
 public:
  enum class Replace { yes, no };  // no: commit() fails if the target exists meanwhile

  // Creates the temporary; `what` names the content in errors ("<path>: cannot write PNG: ...").
  // A target that is a device or a pipe (-o /dev/null) is written directly: nothing to lose.
  explicit AtomicFile(std::filesystem::path path, std::string what = "the file",
                      Replace replace = Replace::yes);
  ~AtomicFile();  // removes the temporary unless commit() ran
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::filesystem::path& path() const { return path_; }
  // Where the bytes go until commit(), for writers that open files by name (FFmpeg): the unnamed
  // file as /proc/self/fd/N, or the named temporary.
  const std::filesystem::path& temporary() const { return temporary_; }

  // Appends bytes; an Error naming the target and the reason (a full disk: "No space left").
  void write(const void* data, size_t size);
  void write(std::string_view text) { write(text.data(), text.size()); }
  void write(std::span<const uint8_t> bytes) { write(bytes.data(), bytes.size()); }
  // Flushes to the disk, closes and renames the temporary to the target.
  void commit();

 private:
  [[noreturn]] void fail(const std::string& reason) const;
  void close_or_fail();

  std::filesystem::path path_, temporary_;
  std::string what_;
  Replace replace_;
  int fd_ = -1;
  bool direct_ = false;   // a device or pipe: no temporary
  bool unnamed_ = false;  // O_TMPFILE: the temporary has no name yet
  bool committed_ = false;
};

// The whole of `bytes` to `path` through an AtomicFile.
void write_file_atomically(const std::filesystem::path& path, std::string_view bytes,
                           const std::string& what = "the file",
                           AtomicFile::Replace replace = AtomicFile::Replace::yes);

}  // namespace strata

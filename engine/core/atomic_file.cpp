#include "engine/core/atomic_file.h"

#include <fcntl.h>
#include <stdio.h>  // renameat2
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <random>

#include "engine/core/error.h"

namespace strata {
namespace {

std::string random_suffix() {
  static constexpr char kLetters[] =
      "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789";
  thread_local std::mt19937_64 random{std::random_device{}()};
  std::string suffix(6, 'x');
  for (char& c : suffix) c = kLetters[random() % (sizeof kLetters - 1)];
  return suffix;
}

std::filesystem::path named_temporary(const std::filesystem::path& path) {
  std::filesystem::path name = path;
  name += ".tmp-" + random_suffix();
  return name;
}

}  // namespace

AtomicFile::AtomicFile(std::filesystem::path path, std::string what, Replace replace)
    : path_(std::move(path)), what_(std::move(what)), replace_(replace) {
  struct stat target {};
  const bool exists = ::stat(path_.c_str(), &target) == 0;
  if (exists && (S_ISCHR(target.st_mode) || S_ISFIFO(target.st_mode))) {
    direct_ = true;
    temporary_ = path_;
    fd_ = ::open(path_.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd_ < 0) fail(std::strerror(errno));
    return;
  }
  if (exists && S_ISDIR(target.st_mode)) fail("it is a folder");
  // An unnamed file in the target's folder (O_TMPFILE): a process killed before commit() leaves
  // nothing behind. File systems without it get a named temporary that only a kill leaves.
  const std::filesystem::path folder =
      path_.parent_path().empty() ? std::filesystem::path(".") : path_.parent_path();
  fd_ = ::open(folder.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666);
  if (fd_ >= 0) {
    unnamed_ = true;
    temporary_ = "/proc/self/fd/" + std::to_string(fd_);
  } else if (errno != EOPNOTSUPP && errno != EISDIR && errno != EINVAL) {
    fail(std::string(std::strerror(errno)) + " (does the folder exist and is it writable?)");
  }
  // O_EXCL: a name nobody else holds; mode 0666 less the umask, as a plain create would give.
  for (int attempt = 0; attempt < 100 && fd_ < 0; ++attempt) {
    temporary_ = named_temporary(path_);
    fd_ = ::open(temporary_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd_ < 0 && errno != EEXIST) {
      const int error = errno;
      temporary_.clear();
      fail(std::string(std::strerror(error)) + " (does the folder exist and is it writable?)");
    }
  }
  if (fd_ < 0) fail("no free temporary name");
  // A replaced file keeps its permissions.
  if (exists && replace_ == Replace::yes) (void)::fchmod(fd_, target.st_mode & 07777);
}

AtomicFile::~AtomicFile() {
  if (fd_ >= 0) ::close(fd_);
  if (!committed_ && !direct_ && !unnamed_ && !temporary_.empty()) ::unlink(temporary_.c_str());
}

void AtomicFile::fail(const std::string& reason) const {
  throw Error(path_.string() + ": cannot write " + what_ + ": " + reason);
}

void AtomicFile::close_or_fail() {
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) fail(std::strerror(errno));
}

void AtomicFile::write(const void* data, size_t size) {
  const auto* bytes = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t written = ::write(fd_, bytes, size);
    if (written < 0) {
      if (errno == EINTR) continue;
      fail(std::strerror(errno));
    }
    bytes += written;
    size -= size_t(written);
  }
}

void AtomicFile::commit() {
  if (committed_) return;
  // A device or pipe cannot be synced (EINVAL); a file's data must be on the disk before the
  // rename makes it the target, or a crash could leave an empty file under the old name.
  if (!direct_ && ::fsync(fd_) != 0) fail(std::strerror(errno));
  if (direct_) {
    close_or_fail();
    committed_ = true;
    return;
  }
  if (unnamed_) {
    // The unnamed file gets its name: directly where it must not replace (linkat fails on an
    // existing name), else a temporary one that the rename below puts over the target.
    const std::filesystem::path name = replace_ == Replace::no ? path_ : named_temporary(path_);
    if (::linkat(AT_FDCWD, temporary_.c_str(), AT_FDCWD, name.c_str(), AT_SYMLINK_FOLLOW) != 0) {
      if (errno == EEXIST && replace_ == Replace::no)
        fail("it exists (it was not there a moment ago)");
      fail(std::strerror(errno));
    }
    unnamed_ = false;
    temporary_ = name;
    if (replace_ == Replace::no) {
      close_or_fail();
      committed_ = true;
      return;
    }
  }
  close_or_fail();
  int result = 0;
  if (replace_ == Replace::yes) {
    result = ::rename(temporary_.c_str(), path_.c_str());
  } else {
    result = ::renameat2(AT_FDCWD, temporary_.c_str(), AT_FDCWD, path_.c_str(), RENAME_NOREPLACE);
    if (result != 0 && errno == EEXIST) fail("it exists (it was not there a moment ago)");
  }
  if (result != 0) fail(std::strerror(errno));
  committed_ = true;
}

void write_file_atomically(const std::filesystem::path& path, std::string_view bytes,
                           const std::string& what, AtomicFile::Replace replace) {
  AtomicFile file(path, what, replace);
  file.write(bytes);
  file.commit();
}

}  // namespace strata

// A read in a forked child: the child runs the parser and streams the result (or its Error)
// through a pipe; the parent reads it while the child runs, watches the clock and the child's
// memory, and turns a signal, an exit without a result or a limit into one strata::Error.
#include "engine/scene/io/isolated_read.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <fstream>
#include <new>
#include <sstream>
#include <type_traits>

#include "engine/core/error.h"
#include "engine/scene/segmentation.h"

// AddressSanitizer reserves terabytes of address space for its shadow memory, so an address-space
// limit would stop every read there; the parent's watch of the child's resident memory remains.
#if defined(__SANITIZE_ADDRESS__)
#define STRATA_ADDRESS_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define STRATA_ADDRESS_SANITIZER 1
#endif
#endif

namespace strata {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr uint64_t kMiB = uint64_t{1} << 20;
constexpr uint64_t kGiB = uint64_t{1} << 30;

// The result crosses the process boundary field by field (mesh_fields, volume_fields): a field
// added to Mesh or Volume must be added there too, or it is silently lost for meshes and DICOM.
static_assert(sizeof(Mesh) == 224, "Mesh changed: update mesh_fields (isolated_read.cpp)");
static_assert(sizeof(Volume) == 360, "Volume changed: update volume_fields (isolated_read.cpp)");
static_assert(sizeof(SegmentRegion) == 64,
              "SegmentRegion changed: update region_fields (isolated_read.cpp)");

template <class T>
constexpr bool is_vector = false;
template <class T>
constexpr bool is_vector<std::vector<T>> = true;

enum class Outcome : uint8_t { value = 1, error = 2, out_of_memory = 3 };

template <class... Parts>
std::string concat(const Parts&... parts) {
  std::ostringstream out;
  (out << ... << parts);
  return out.str();
}

std::string seconds_text(double seconds) {
  char text[32];
  std::snprintf(text, sizeof text, seconds == std::floor(seconds) ? "%.0f s" : "%.1f s", seconds);
  return text;
}

// Pages of /proc/<pid>/statm's field `index` (0: address space, 1: resident), in bytes.
uint64_t statm_bytes(const std::string& pid, int index) {
  std::ifstream in("/proc/" + pid + "/statm");
  uint64_t pages = 0;
  for (int i = 0; i <= index && in; ++i) in >> pages;
  return in ? pages * uint64_t(sysconf(_SC_PAGESIZE)) : 0;
}

uint64_t available_memory() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  uint64_t kib = 0;
  std::string unit;
  while (in >> key >> kib >> unit)
    if (key == "MemAvailable:") return kib * 1024;
  return 0;
}

uint64_t input_bytes(const fs::path& input) {
  std::error_code error;
  if (!fs::is_directory(input, error)) {
    const uint64_t size = fs::file_size(input, error);
    return error ? 0 : size;
  }
  uint64_t total = 0;
  for (fs::recursive_directory_iterator
           it(input, fs::directory_options::skip_permission_denied, error),
       end;
       !error && it != end; it.increment(error)) {
    if (it->is_regular_file(error)) total += it->file_size(error);
  }
  return total;
}

// ---- the child's side: everything here runs after fork() and ends in _exit()

int result_fd = -1;  // the child's end of the result pipe
volatile sig_atomic_t out_of_memory = 0;
bool outcome_sent = false;

// Writes all of it or ends the child: a write fails only when the parent has stopped listening.
void write_all(const void* data, size_t n) {
  const char* p = static_cast<const char*>(data);
  while (n > 0) {
    const ssize_t written = ::write(result_fd, p, n);
    if (written < 0 && errno == EINTR) continue;
    if (written <= 0) _exit(3);
    p += written;
    n -= size_t(written);
  }
}

struct Writer {
  template <class T>
  void pod(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    write_all(&value, sizeof value);
  }
  void text(const std::string& s) {
    pod(uint64_t{s.size()});
    write_all(s.data(), s.size());
  }
  template <class T>
  void array(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    pod(uint64_t{v.size()});
    write_all(v.data(), v.size() * sizeof(T));
  }
  void outcome(Outcome o) {
    outcome_sent = true;
    pod(o);
  }
  // One field of a result, by its type (mesh_fields, volume_fields).
  template <class T>
  void field(const T& value) {
    if constexpr (std::is_same_v<T, std::string>) {
      text(value);
    } else if constexpr (std::is_same_v<T, std::filesystem::path>) {
      text(value.string());
    } else if constexpr (is_vector<T>) {
      array(value);
    } else {
      pod(value);
    }
  }
};

// operator new failed (the address-space limit): remember it, so that an error the parser makes
// of the bad_alloc (Assimp returns "std::bad_alloc" as its message) is reported as memory.
void on_out_of_memory() {
  out_of_memory = 1;
  std::set_new_handler(nullptr);
  throw std::bad_alloc();
}

// A bad_alloc thrown through a noexcept function ends in std::terminate: still a memory limit.
void on_terminate() {
  if (out_of_memory && !outcome_sent) {
    const Outcome o = Outcome::out_of_memory;
    write_all(&o, 1);
    _exit(4);
  }
  std::abort();
}

void limit(int resource, uint64_t soft, uint64_t hard) {
  const rlimit value{rlim_t(soft), rlim_t(hard)};
  setrlimit(resource, &value);
}

[[noreturn]] void run_child(int result_write, int message_write, const ParserLimits& limits,
                            const std::function<void(Writer&)>& produce) {
  // Dies with strata, whichever way strata ends.
  prctl(PR_SET_PDEATHSIG, SIGKILL);
  sigset_t none;
  sigemptyset(&none);
  sigprocmask(SIG_SETMASK, &none, nullptr);
  // A crash must end the child with its signal (the parent reports it), not in a handler that
  // strata, a test framework or a sanitizer installed. Ctrl-C is strata's to handle.
  for (int s : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGXCPU, SIGPIPE, SIGTERM})
    signal(s, SIG_DFL);
  signal(SIGINT, SIG_IGN);
  limit(RLIMIT_CORE, 0, 0);  // a parser's crash is reported, not dumped
  const auto cpu = uint64_t(std::max(1.0, std::ceil(limits.seconds)));
  limit(RLIMIT_CPU, cpu, cpu + 1);
#ifndef STRATA_ADDRESS_SANITIZER
  // On top of what the child shares with strata (a viewer's mapped driver memory, its scene).
  const uint64_t mapped = statm_bytes("self", 0);
  limit(RLIMIT_AS, mapped + limits.memory_bytes, mapped + limits.memory_bytes);
#endif
  // Parsers print to stderr on their way down (GDCM's and Assimp's assertions); the parent keeps
  // the last of it for the message.
  dup2(message_write, STDOUT_FILENO);
  dup2(message_write, STDERR_FILENO);
  // Nothing else of strata's stays open here: not its files or driver handles, and not another
  // child's pipe end (a concurrent read's end of file would wait for this child).
  result_fd = 3;
  if (result_write != result_fd) dup2(result_write, result_fd);
  close_range(4, ~0u, 0);
  std::set_new_handler(on_out_of_memory);
  std::set_terminate(on_terminate);
  Writer writer;
  try {
    produce(writer);
  } catch (const std::bad_alloc&) {
    writer.outcome(Outcome::out_of_memory);
  } catch (const std::exception& e) {
    // Parsers turn the bad_alloc into their own error (Assimp's message is "std::bad_alloc"); the
    // new-handler's mark misses it where operator new is replaced (a heap-counting test binary).
    if (out_of_memory || std::string_view(e.what()).find("bad_alloc") != std::string_view::npos) {
      writer.outcome(Outcome::out_of_memory);
    } else {
      writer.outcome(Outcome::error);
      writer.text(e.what());
    }
  }
  // No atexit handlers, no second flush of strata's stdio buffers, no leak check of a process
  // that is about to vanish.
  _exit(0);
}

// ---- the parent's side

class Child {
 public:
  Child(const fs::path& file, std::string_view parser, const ParserLimits& limits,
        const std::function<void(Writer&)>& produce)
      : file_(file.string()), parser_(parser), limits_(limits) {
    int result[2], message[2];
    if (pipe2(result, O_CLOEXEC) != 0) fail_to_start();
    if (pipe2(message, O_CLOEXEC) != 0) {
      close(result[0]);
      close(result[1]);
      fail_to_start();
    }
    fcntl(result[1], F_SETPIPE_SZ, int(kMiB));  // fewer wake-ups for a volume's voxels
    baseline_ = statm_bytes("self", 1);
    deadline_ = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                   std::chrono::duration<double>(limits.seconds));
    pid_ = fork();
    if (pid_ == 0) {
      close(result[0]);
      close(message[0]);
      run_child(result[1], message[1], limits, produce);
    }
    close(result[1]);
    close(message[1]);
    result_fd_ = result[0];
    message_fd_ = message[0];
    if (pid_ < 0) fail_to_start();
  }

  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  ~Child() {
    if (pid_ > 0) {
      kill(pid_, SIGKILL);
      int status = 0;
      while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
      }
    }
    if (result_fd_ >= 0) close(result_fd_);
    if (message_fd_ >= 0) close(message_fd_);
  }

  // Exactly n bytes of the result; when the child ends first, the Error that says why.
  void read(void* destination, size_t n) {
    auto* out = static_cast<char*>(destination);
    while (n > 0) {
      if (buffered_ == 0) {
        wait_for_result();
        // Large reads (voxels) go straight to their place; small ones through the buffer.
        const bool direct = n >= buffer_.size();
        const ssize_t got =
            ::read(result_fd_, direct ? out : buffer_.data(), direct ? n : buffer_.size());
        if (got < 0 && errno == EINTR) continue;
        if (got <= 0) ended_early();
        if (direct) {
          out += got;
          n -= size_t(got);
          continue;
        }
        start_ = 0;
        buffered_ = size_t(got);
      }
      const size_t take = std::min(n, buffered_);
      std::memcpy(out, buffer_.data() + start_, take);
      start_ += take;
      buffered_ -= take;
      out += take;
      n -= take;
    }
  }

  template <class T>
  T pod() {
    T value;
    read(&value, sizeof value);
    return value;
  }
  std::string text() {
    std::string s(pod<uint64_t>(), '\0');
    read(s.data(), s.size());
    return s;
  }
  template <class T>
  void array(std::vector<T>& v) {
    v.resize(pod<uint64_t>());
    read(v.data(), v.size() * sizeof(T));
  }
  // One field of a result, as Writer::field sent it.
  template <class T>
  void field(T& value) {
    if constexpr (std::is_same_v<T, std::string> || std::is_same_v<T, std::filesystem::path>) {
      value = text();
    } else if constexpr (is_vector<T>) {
      array(value);
    } else {
      value = pod<T>();
    }
  }

  // After the whole result: the child is ending on its own.
  void finish() {
    int status = 0;
    while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
    pid_ = -1;
  }

  [[noreturn]] void stop_for_memory() {
    stop();
    throw Error(concat(file_, ": ", parser_, " needed more than ", limits_.memory_bytes / kMiB,
                       " MiB of memory (stopped)"));
  }

 private:
  [[noreturn]] void fail_to_start() {
    throw Error(
        concat(file_, ": cannot start a process for ", parser_, ": ", std::strerror(errno)));
  }

  void stop() {
    kill(pid_, SIGKILL);
    finish();
  }

  // Waits until the result pipe has data or has closed, keeping the child's last messages and
  // stopping it at the deadline or at the memory limit.
  void wait_for_result() {
    for (;;) {
      const auto now = Clock::now();
      if (now >= deadline_) {
        stop();
        throw Error(concat(file_, ": ", parser_, " took more than ", seconds_text(limits_.seconds),
                           " (stopped)"));
      }
      if (now >= next_memory_check_) {
        next_memory_check_ = now + std::chrono::milliseconds(50);
        const uint64_t resident = statm_bytes(std::to_string(pid_), 1);
        if (resident > baseline_ + limits_.memory_bytes) stop_for_memory();
      }
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline_ - now).count() + 1;
      pollfd fds[2] = {{result_fd_, POLLIN, 0}, {message_fd_, POLLIN, 0}};
      const int ready = poll(fds, message_fd_ >= 0 ? 2 : 1, int(std::min<int64_t>(left, 50)));
      if (ready < 0 && errno != EINTR) ended_early();
      if (ready <= 0) continue;
      if (fds[1].revents) keep_message();
      if (fds[0].revents) return;
    }
  }

  void keep_message() {
    char chunk[4096];
    const ssize_t got = ::read(message_fd_, chunk, sizeof chunk);
    if (got <= 0) {
      if (got < 0 && errno == EINTR) return;
      close(message_fd_);
      message_fd_ = -1;
      return;
    }
    messages_.append(chunk, size_t(got));
    if (messages_.size() > 8192) messages_.erase(0, messages_.size() - 4096);
  }

  // The child's last line on stderr, as a hint of where it went down.
  std::string last_words() {
    while (message_fd_ >= 0) keep_message();  // the child has ended: the rest is there
    std::string_view text = messages_;
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' '))
      text.remove_suffix(1);
    const size_t line = text.find_last_of('\n');
    if (line != std::string_view::npos) text.remove_prefix(line + 1);
    std::string shown(text.substr(0, 200));
    for (char& c : shown)
      if (c < 32 || c > 126) c = '?';
    return shown.empty() ? "" : ": \"" + shown + "\"";
  }

  // The result pipe closed before the whole result came: the child's end says why.
  [[noreturn]] void ended_early() {
    int status = 0;
    rusage usage{};
    while (wait4(pid_, &status, 0, &usage) < 0 && errno == EINTR) {
    }
    pid_ = -1;
    const std::string head = concat(file_, ": ", parser_);
    if (WIFSIGNALED(status)) {
      const int signal = WTERMSIG(status);
      const double cpu = double(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
                         double(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) * 1e-6;
      // SIGXCPU at the soft CPU limit, SIGKILL at the hard one; the kernel's OOM killer also
      // sends SIGKILL, but early.
      if (signal == SIGXCPU || (signal == SIGKILL && cpu >= std::ceil(limits_.seconds)))
        throw Error(concat(head, " took more than ", seconds_text(std::ceil(limits_.seconds)),
                           " of CPU time (stopped)"));
      const char* name = sigabbrev_np(signal);
      throw Error(concat(head, " crashed (SIG", name ? name : std::to_string(signal).c_str(),
                         last_words(), ")"));
    }
    if (WIFEXITED(status) && WEXITSTATUS(status) != 0)
      throw Error(concat(head, " failed (exit status ", WEXITSTATUS(status), last_words(), ")"));
    throw Error(concat(head, " ended without a result"));
  }

  std::string file_, parser_;
  ParserLimits limits_;
  pid_t pid_ = -1;
  int result_fd_ = -1, message_fd_ = -1;
  uint64_t baseline_ = 0;  // strata's resident memory when the child started
  Clock::time_point deadline_, next_memory_check_;
  std::vector<char> buffer_ = std::vector<char>(1 << 16);
  size_t start_ = 0, buffered_ = 0;
  std::string messages_;  // the tail of the child's stderr
};

// Runs produce() in a child; consume() reads the value it sent.
void run_isolated(const fs::path& file, std::string_view parser, const ParserLimits& requested,
                  const std::function<void(Writer&)>& produce,
                  const std::function<void(Child&)>& consume) {
  Child child(file, parser, resolved_parser_limits(file, requested), produce);
  switch (child.pod<Outcome>()) {
    case Outcome::value:
      consume(child);
      child.finish();
      return;
    case Outcome::error: {
      const std::string message = child.text();
      child.finish();
      throw Error(message);
    }
    case Outcome::out_of_memory:
      child.stop_for_memory();
  }
  throw Error(file.string() + ": " + std::string(parser) + " sent an unreadable result");
}

// Every field of a result, in one order for both ends: Writer::field in the child, Child::field
// in strata.
template <class Io, class M>
void mesh_fields(Io& io, M& mesh) {
  io.field(mesh.name);
  io.field(mesh.source);
  io.field(mesh.positions);
  io.field(mesh.normals);
  io.field(mesh.indices);
  io.field(mesh.color);
  io.field(mesh.transform);
}

template <class Io, class V>
void volume_fields(Io& io, V& volume) {
  io.field(volume.name);
  io.field(volume.source);
  io.field(volume.type);
  io.field(volume.dims);
  io.field(volume.spacing);
  io.field(volume.origin);
  io.field(volume.direction);
  io.field(volume.transform);
  io.field(volume.voxels);
  io.field(volume.value_range);
  io.field(volume.transfer_function);
  io.field(volume.preset);
  io.field(volume.window);
  io.field(volume.look_edited);
  io.field(volume.series);
  io.field(volume.cut);
}

template <class Io, class R>
void region_fields(Io& io, R& region) {
  io.field(region.number);
  io.field(region.layer);
  io.field(region.value);
  io.field(region.name);
  io.field(region.colour);
}

}  // namespace

ParserLimits resolved_parser_limits(const std::filesystem::path& input, ParserLimits limits) {
  const uint64_t bytes = input_bytes(input);
  if (limits.seconds <= 0.0) limits.seconds = 120.0 + double(bytes / (16 * kMiB));
  if (limits.memory_bytes == 0) {
    limits.memory_bytes = std::max(2 * kGiB, 16 * bytes);
    // More than the machine has would end in swapping or the kernel's OOM killer instead.
    const uint64_t available = available_memory();
    if (available > 0)
      limits.memory_bytes = std::min(limits.memory_bytes, std::max(available, kGiB / 2));
  }
  return limits;
}

std::vector<Mesh> read_meshes_isolated(const std::filesystem::path& file, std::string_view parser,
                                       const ParserLimits& limits,
                                       const std::function<std::vector<Mesh>()>& read) {
  std::vector<Mesh> meshes;
  run_isolated(
      file, parser, limits,
      [&](Writer& w) {
        const std::vector<Mesh> result = read();
        w.outcome(Outcome::value);
        w.pod(uint64_t{result.size()});
        for (const Mesh& mesh : result) mesh_fields(w, mesh);
      },
      [&](Child& child) {
        meshes.resize(child.pod<uint64_t>());
        for (Mesh& mesh : meshes) mesh_fields(child, mesh);
      });
  return meshes;
}

std::vector<std::string> read_texts_isolated(
    const std::filesystem::path& file, std::string_view parser, const ParserLimits& limits,
    const std::function<std::vector<std::string>()>& read) {
  std::vector<std::string> texts;
  run_isolated(
      file, parser, limits,
      [&](Writer& w) {
        const std::vector<std::string> result = read();
        w.outcome(Outcome::value);
        w.pod(uint64_t{result.size()});
        for (const std::string& text : result) w.text(text);
      },
      [&](Child& child) {
        texts.resize(child.pod<uint64_t>());
        for (std::string& text : texts) text = child.text();
      });
  return texts;
}

Volume read_volume_isolated(const std::filesystem::path& file, std::string_view parser,
                            const ParserLimits& limits, std::vector<std::string>& warnings,
                            const std::function<Volume(std::vector<std::string>&)>& read) {
  Volume volume;
  run_isolated(
      file, parser, limits,
      [&](Writer& w) {
        std::vector<std::string> child_warnings;
        const Volume result = read(child_warnings);
        w.outcome(Outcome::value);
        volume_fields(w, result);
        w.pod(uint64_t{child_warnings.size()});
        for (const std::string& warning : child_warnings) w.text(warning);
      },
      [&](Child& child) {
        volume_fields(child, volume);
        const auto count = child.pod<uint64_t>();
        for (uint64_t i = 0; i < count; ++i) warnings.push_back(child.text());
      });
  return volume;
}

Segmentation read_segmentation_isolated(
    const std::filesystem::path& file, std::string_view parser, const ParserLimits& limits,
    std::vector<std::string>& warnings,
    const std::function<Segmentation(std::vector<std::string>&)>& read) {
  Segmentation segmentation;
  run_isolated(
      file, parser, limits,
      [&](Writer& w) {
        std::vector<std::string> child_warnings;
        const Segmentation result = read(child_warnings);
        w.outcome(Outcome::value);
        w.field(result.source);
        w.field(result.format);
        w.pod(uint64_t{result.layers.size()});
        for (const Volume& layer : result.layers) volume_fields(w, layer);
        w.pod(uint64_t{result.regions.size()});
        for (const SegmentRegion& region : result.regions) region_fields(w, region);
        w.pod(uint64_t{child_warnings.size()});
        for (const std::string& warning : child_warnings) w.text(warning);
      },
      [&](Child& child) {
        child.field(segmentation.source);
        child.field(segmentation.format);
        segmentation.layers.resize(child.pod<uint64_t>());
        for (Volume& layer : segmentation.layers) volume_fields(child, layer);
        segmentation.regions.resize(child.pod<uint64_t>());
        for (SegmentRegion& region : segmentation.regions) region_fields(child, region);
        const auto count = child.pod<uint64_t>();
        for (uint64_t i = 0; i < count; ++i) warnings.push_back(child.text());
      });
  return segmentation;
}

}  // namespace strata

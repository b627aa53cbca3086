// Files written whole or not at all (engine/core/atomic_file.h): a write that fails (a full disk,
// here a file-size limit; an exception on the way) leaves the old file as it was and no
// temporary beside it.
#include <doctest/doctest.h>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <functional>
#include <string>

#include "engine/core/atomic_file.h"
#include "engine/core/png.h"
#include "engine/core/text_file.h"
#include "test_files.h"

namespace fs = std::filesystem;

namespace strata {
namespace {

// Runs `write` in a child whose files may grow to `limit` bytes (write() then fails with EFBIG,
// as on a full disk); the child's exit status: 0 when write threw strata::Error, 1 when it did
// not, 2 for any other exception.
int with_file_size_limit(rlim_t limit, const std::function<void()>& write) {
  const pid_t pid = fork();
  if (pid == 0) {
    std::signal(SIGXFSZ, SIG_IGN);
    const rlimit small{limit, limit};
    if (setrlimit(RLIMIT_FSIZE, &small) != 0) _exit(3);
    try {
      write();
    } catch (const Error&) {
      _exit(0);
    } catch (...) {
      _exit(2);
    }
    _exit(1);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace

TEST_SUITE("loaders") {
  TEST_CASE("a_write_past_the_file_size_limit_fails_and_leaves_the_old_file_and_no_temporary") {
    const fs::path folder = test::fresh_folder("atomic_file", "limit");
    const fs::path file = test::write_file(folder / "out.json", "the old file\n");
    const auto before = test::folder_bytes(folder);
    const std::string big(64 * 1024, 'x');
    CHECK(with_file_size_limit(4096, [&] { write_text_file(file, big); }) == 0);
    CHECK(test::folder_bytes(folder) == before);
    // A PNG (write_png) and a file that was not there before: nothing is left either.
    std::vector<uint8_t> noise(128 * 128 * 4);  // (random: no PNG of it is small)
    uint32_t state = 2463534242u;
    for (uint8_t& byte : noise) {
      state ^= state << 13;
      state ^= state >> 17;
      state ^= state << 5;
      byte = uint8_t(state >> 24);
    }
    CHECK(with_file_size_limit(
              4096, [&] { write_png((folder / "new.png").string(), 128, 128, noise); }) == 0);
    CHECK(test::folder_bytes(folder) == before);
    // Without the limit the same writes succeed (the limit is what failed them).
    write_text_file(file, big);
    CHECK(test::read_file(file) == big);
  }

  TEST_CASE("an_atomic_file_left_uncommitted_removes_its_temporary_and_keeps_the_old_file") {
    const fs::path folder = test::fresh_folder("atomic_file", "uncommitted");
    const fs::path file = test::write_file(folder / "out.txt", "old");
    const auto before = test::folder_bytes(folder);
    {
      AtomicFile atomic(file);
      atomic.write(std::string_view("new, but cut short"));
      CHECK(fs::exists(atomic.temporary()));
      CHECK(test::folder_bytes(folder) == before);  // the temporary has no name in the folder
      CHECK(test::read_file(file) == "old");
    }  // (as when an exception leaves the writer)
    CHECK(test::folder_bytes(folder) == before);
    {
      AtomicFile atomic(file);
      atomic.write(std::string_view("new"));
      atomic.commit();
    }
    CHECK(test::read_file(file) == "new");
    CHECK(test::folder_bytes(folder).size() == 1);
  }

  TEST_CASE("an_atomic_file_killed_before_it_is_done_leaves_the_old_file_and_nothing_else") {
    const fs::path folder = test::fresh_folder("atomic_file", "killed");
    const fs::path file = test::write_file(folder / "out.png", "the old picture");
    const auto before = test::folder_bytes(folder);
    const pid_t pid = fork();
    if (pid == 0) {
      AtomicFile atomic(file, "PNG");
      atomic.write(std::string(1 << 20, 'x'));
      ::kill(::getpid(), SIGKILL);  // (as a user's kill -9 or the OOM killer)
      _exit(1);
    }
    int status = 0;
    waitpid(pid, &status, 0);
    CHECK(WIFSIGNALED(status));
    CHECK(test::folder_bytes(folder) == before);
  }

  TEST_CASE("an_atomic_file_that_must_not_replace_fails_on_an_existing_file") {
    const fs::path folder = test::fresh_folder("atomic_file", "no_replace");
    const fs::path file = test::write_file(folder / "scan.json", "a transfer function");
    CHECK(test::error_of([&] {
            write_file_atomically(file, "a scene", "the scene", AtomicFile::Replace::no);
          }).find("scan.json: cannot write the scene: it exists") != std::string::npos);
    CHECK(test::read_file(file) == "a transfer function");
    CHECK(test::folder_bytes(folder).size() == 1);
    write_file_atomically(folder / "new.json", "a scene", "the scene", AtomicFile::Replace::no);
    CHECK(test::read_file(folder / "new.json") == "a scene");
  }

  TEST_CASE("an_atomic_file_writes_devices_directly_and_names_a_missing_folder") {
    write_file_atomically("/dev/null", "nothing to keep");  // no temporary in /dev
    CHECK(test::error_of([] {
            write_file_atomically("/nonexistent-dir/x.png", "x", "PNG");
          }).starts_with("/nonexistent-dir/x.png: cannot write PNG: No such file or directory"));
  }
}

}  // namespace strata

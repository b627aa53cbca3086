#include "gpu_fixture.h"

#include <cstdio>
#include <filesystem>
#include <memory>

#include <doctest/doctest.h>
#include <sys/wait.h>

namespace strata::test {

Context& gpu() {
  static Context ctx([] {
    ContextOptions options;
    options.validation = true;
    options.quiet = true;
    return options;
  }());
  return ctx;
}

GpuTest::GpuTest() {
  ctx.validation_log().take();
}

GpuTest::~GpuTest() {
  for (const std::string& message : ctx.validation_log().take()) {
    FAIL_CHECK("validation layer: " << message);
  }
}

CommandResult run_strata(const std::string& args, const std::string& env) {
  const std::string command = env + (env.empty() ? "" : " ") + STRATA_BINARY + " " + args + " 2>&1";
  CommandResult result;
  FILE* pipe = popen(command.c_str(), "r");
  REQUIRE_MESSAGE(pipe != nullptr, "cannot run " << command);
  char buffer[4096];
  size_t n = 0;
  while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0) result.output.append(buffer, n);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

std::string output_dir() {
  const std::string dir = STRATA_TEST_OUTPUT;
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace strata::test

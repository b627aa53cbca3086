// What every fuzz target shares. strata's parsers take paths, so each input is written to a file
// in a folder of this process's own and the real entry point reads it, as it reads a user's file
// (docs/fuzzing.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <string>

#include "engine/core/error.h"

namespace strata::fuzz {

// $TMPDIR/strata-fuzz-<pid> ($TMPDIR defaults to /dev/shm: memory, not disk), made on first use.
const std::filesystem::path& sandbox();

// Writes the input to sandbox()/name (replacing it) and returns that path.
std::filesystem::path write_input(const uint8_t* data, size_t size, const std::string& name);

// Files a scene may reference, written once into the sandbox so that fuzzed scenes get past
// "no such file" into the volume, atlas, transfer-function, label and picture readers:
// vol.mha (8x8x4 uint8, region ids 0..3), names.txt (3 regions), tf.json, tf.gra, labels.csv,
// pic.png, and for thesis scenes datasets/dice.mha and transferfunctions/dice4.gra.
void write_scene_files();

// Runs fn. A strata::Error is what bad input must give; any other exception is a finding, so it
// is printed and the process aborts, which makes libFuzzer keep the input.
template <class Fn>
void expect_only_errors(Fn&& fn) {
  try {
    fn();
  } catch (const strata::Error&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz: an exception other than strata::Error: %s\n", e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "fuzz: an exception that is not a std::exception\n");
    std::abort();
  }
}

}  // namespace strata::fuzz

// Thesis transfer functions, Qt gradient XML .gra (transfer_function_loader.cpp).
#include "engine/scene/io/transfer_function_loader.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = strata::fuzz::write_input(data, size, "input.gra");
  strata::fuzz::expect_only_errors([&] { strata::load_transfer_function_gra(path); });
  return 0;
}

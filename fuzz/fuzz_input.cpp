#include "fuzz/fuzz_input.h"

#include <fstream>
#include <vector>

#include <unistd.h>

#include "engine/core/png.h"
#include "engine/core/text_file.h"
#include "engine/scene/io/volume_loader.h"

namespace strata::fuzz {

namespace fs = std::filesystem;

const fs::path& sandbox() {
  static const fs::path folder = [] {
    const char* tmp = std::getenv("TMPDIR");
    fs::path path =
        fs::path(tmp && *tmp ? tmp : "/dev/shm") / ("strata-fuzz-" + std::to_string(::getpid()));
    fs::create_directories(path);
    return path;
  }();
  // Removed when the process exits normally (a crash leaves it, with the input that crashed);
  // registered after `folder` is made, so it runs before `folder` is destroyed.
  [[maybe_unused]] static const int cleanup = std::atexit([] {
    std::error_code error;
    fs::remove_all(sandbox(), error);
  });
  return folder;
}

fs::path write_input(const uint8_t* data, size_t size, const std::string& name) {
  const fs::path path = sandbox() / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) {
    std::fprintf(stderr, "fuzz: cannot write %s\n", path.c_str());
    std::abort();
  }
  return path;
}

namespace {

// 8x8x4 voxels: region 1 in the low corner, 2 and 3 in the slices above, 0 around them.
Volume region_volume() {
  Volume v;
  v.dims = {8, 8, 4};
  v.spacing = {2.0f, 2.0f, 3.0f};
  v.voxels.resize(v.voxel_count());
  for (uint32_t k = 0; k < 4; ++k)
    for (uint32_t j = 0; j < 8; ++j)
      for (uint32_t i = 0; i < 8; ++i)
        v.voxels[(k * 8 + j) * 8 + i] = std::byte(i > 1 && i < 6 && j > 1 && j < 6 ? k : 0);
  return v;
}

constexpr const char* kGra = R"(<!DOCTYPE Gradient>
<gradientData spread="PadSpread" type="LinearGradient">
 <stopData position="0"><colorData r="0" g="0" b="0" a="0"/></stopData>
 <stopData position="0.5"><colorData r="200" g="120" b="40" a="30"/></stopData>
 <stopData position="1"><colorData r="255" g="255" b="255" a="255"/></stopData>
</gradientData>
)";

}  // namespace

void write_scene_files() {
  const fs::path& dir = sandbox();
  fs::create_directories(dir / "datasets");
  fs::create_directories(dir / "transferfunctions");
  const Volume volume = region_volume();
  write_metaimage(dir / "vol.mha", volume);
  write_metaimage(dir / "datasets" / "dice.mha", volume);
  write_text_file(dir / "names.txt", "1 Region_A 2001\n2 Region_B 2002\n3 Region_C 2003\n");
  write_text_file(dir / "tf.json", R"({"strata_transfer_function": 1, "name": "ramp", "stops": [)"
                                   R"({"position": 0, "color": [0, 0, 0, 0]},)"
                                   R"({"position": 1, "color": [1, 0.8, 0.6, 0.5]}]})"
                                   "\n");
  write_text_file(dir / "tf.gra", kGra);
  write_text_file(dir / "transferfunctions" / "dice4.gra", kGra);
  write_text_file(dir / "labels.csv", "l,p,s,text\n1,2,3,first\n4,5,6,\"second, quoted\"\n");
  const std::vector<uint8_t> pixels(4 * 4 * 4, 200);
  write_png((dir / "pic.png").string(), 4, 4, pixels);
}

}  // namespace strata::fuzz

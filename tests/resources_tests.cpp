// Staging uploads and readbacks of device-local buffers and images.
#include <doctest/doctest.h>

#include <numeric>

#include "engine/core/error.h"
#include "engine/gpu/resources.h"
#include "gpu_fixture.h"

namespace strata {

TEST_SUITE("gpu") {
  TEST_CASE_FIXTURE(test::GpuTest, "buffer_upload_and_readback_round_trip") {
    std::vector<uint32_t> words(1000);
    std::iota(words.begin(), words.end(), 7u);
    Buffer buffer(ctx, words.size() * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                  MemoryKind::device_local);
    upload(ctx, buffer, as_bytes(words));
    CHECK(download_as<uint32_t>(ctx, buffer) == words);
  }

  TEST_CASE_FIXTURE(test::GpuTest, "image_upload_and_readback_round_trip_in_2d_and_3d") {
    for (const VkExtent3D extent : {VkExtent3D{13, 7, 1}, VkExtent3D{9, 5, 4}}) {
      const ImageDesc desc{VK_FORMAT_R8G8B8A8_UNORM, extent,
                           extent.depth > 1 ? VK_IMAGE_TYPE_3D : VK_IMAGE_TYPE_2D,
                           VK_IMAGE_USAGE_SAMPLED_BIT};
      Image image(ctx, desc);
      std::vector<uint8_t> texels(size_t{extent.width} * extent.height * extent.depth * 4);
      for (size_t i = 0; i < texels.size(); ++i) texels[i] = static_cast<uint8_t>(i * 31 + 5);
      upload(ctx, image, as_bytes(texels), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
      const std::vector<std::byte> back =
          download(ctx, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
      REQUIRE(back.size() == texels.size());
      CHECK(std::memcmp(back.data(), texels.data(), texels.size()) == 0);
    }
  }

  TEST_CASE_FIXTURE(test::GpuTest, "an_upload_of_the_wrong_size_is_an_error") {
    Image image(
        ctx, {VK_FORMAT_R8G8B8A8_UNORM, {4, 4, 1}, VK_IMAGE_TYPE_2D, VK_IMAGE_USAGE_SAMPLED_BIT});
    const std::vector<uint8_t> short_data(10);
    CHECK_THROWS_AS(upload(ctx, image, as_bytes(short_data), VK_IMAGE_LAYOUT_GENERAL), Error);
  }
}

}  // namespace strata

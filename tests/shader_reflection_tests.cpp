// Descriptor layouts come from SPIR-V reflection of the embedded shaders.
#include <doctest/doctest.h>

#include <array>
#include <string_view>
#include <vector>

#include "engine/core/error.h"
#include "engine/gpu/context.h"
#include "engine/gpu/shader_library.h"
#include "gpu_fixture.h"
#include "shared/summed_area_table.h"
#include "shared/test_pattern.h"

namespace strata {

TEST_SUITE("cpu") {
  TEST_CASE("reflection_reads_bindings_push_constants_and_workgroup_size") {
    const ShaderReflection r =
        reflect(shader_code("summed_area_table_scan.comp"), VK_SHADER_STAGE_COMPUTE_BIT, "scan");
    REQUIRE(r.bindings.size() == 3);
    for (uint32_t i = 0; i < 3; ++i) {
      CHECK(r.bindings[i].binding == i);
      CHECK(r.bindings[i].descriptorType == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
    }
    CHECK(r.push_constant_size == sizeof(gpu::SatParams));
    CHECK(r.local_size[0] == SAT_TILE);
    CHECK(r.local_size[1] == SAT_GROUP_ROWS);
    CHECK(r.local_size[2] == 1);
  }

  TEST_CASE("reflection_tells_storage_images_from_buffers") {
    const ShaderReflection r =
        reflect(shader_code("test_pattern_blur.comp"), VK_SHADER_STAGE_COMPUTE_BIT, "blur");
    REQUIRE(r.bindings.size() == 3);
    CHECK(r.bindings[0].binding == TEST_PATTERN_BINDING_COLOR);
    CHECK(r.bindings[0].descriptorType == VK_DESCRIPTOR_TYPE_STORAGE_IMAGE);
    CHECK(r.bindings[1].binding == TEST_PATTERN_BINDING_TABLE);
    CHECK(r.bindings[1].descriptorType == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
    CHECK(r.bindings[2].binding == TEST_PATTERN_BINDING_OUTPUT);
    CHECK(r.bindings[2].descriptorType == VK_DESCRIPTOR_TYPE_STORAGE_IMAGE);
  }

  TEST_CASE("every_embedded_shader_reflects_and_unknown_names_are_errors") {
    CHECK(shader_names().size() >= 5);
    for (std::string_view name : shader_names()) {
      CHECK_NOTHROW(reflect(shader_code(name), VK_SHADER_STAGE_COMPUTE_BIT, name));
    }
    CHECK_THROWS_WITH_AS(shader_code("missing.comp"),
                         doctest::Contains("no shader named 'missing.comp'"), Error);
    const std::vector<uint32_t> garbage = {1, 2, 3, 4, 5, 6};
    CHECK_THROWS_AS(reflect(garbage, VK_SHADER_STAGE_COMPUTE_BIT, "garbage"), Error);
  }
}

TEST_SUITE("gpu") {
  TEST_CASE_FIXTURE(test::GpuTest,
                    "pipelines_created_together_come_in_order_or_as_the_first_error") {
    const std::array<std::string_view, 3> shaders{"test_pattern.comp", "place_label.comp",
                                                  "summed_area_table_scan.comp"};
    const std::vector<ComputePipeline> pipelines = create_compute_pipelines(ctx, shaders);
    REQUIRE(pipelines.size() == shaders.size());
    for (size_t k = 0; k < shaders.size(); ++k) {
      CHECK(pipelines[k].name() == shaders[k]);
      CHECK(pipelines[k].local_size() ==
            reflect(shader_code(shaders[k]), VK_SHADER_STAGE_COMPUTE_BIT, shaders[k]).local_size);
    }
    const std::array<std::string_view, 3> one_missing{"test_pattern.comp", "missing.comp",
                                                      "place_label.comp"};
    CHECK_THROWS_WITH_AS(create_compute_pipelines(ctx, one_missing),
                         doctest::Contains("no shader named 'missing.comp'"), Error);
  }
}

}  // namespace strata

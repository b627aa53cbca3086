// The render graph's compile step, from declarations alone: no device.
#include <doctest/doctest.h>

#include "engine/graph/render_graph.h"

namespace strata::graph {
namespace {

PassInfo pass(std::string name, PassKind kind, std::vector<ResourceUse> uses) {
  return {std::move(name), kind, std::move(uses), [](PassContext&) {}};
}

BufferInfo any_size() {
  return {[](Extent) { return VkDeviceSize{64}; }};
}

}  // namespace

TEST_SUITE("cpu") {
  TEST_CASE("read_after_write_gets_one_barrier_from_the_writer_to_the_reader") {
    Graph g;
    const ResourceId b = g.add_buffer("costs", any_size());
    g.add_pass(pass("write", PassKind::compute, {{b, Use::storage_write}}));
    g.add_pass(pass("read", PassKind::compute, {{b, Use::storage_read}}));
    const CompiledGraph c = compile(g);
    CHECK(c.pass_barriers[0].empty());
    REQUIRE(c.pass_barriers[1].size() == 1);
    const Barrier& barrier = c.pass_barriers[1][0];
    CHECK(barrier.resource == b);
    CHECK(barrier.src_stage == VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);
    CHECK(barrier.src_access == VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    CHECK(barrier.dst_stage == VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);
    CHECK(barrier.dst_access == VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
  }

  TEST_CASE("second_read_in_the_same_stage_needs_no_new_barrier") {
    Graph g;
    const ResourceId b = g.add_buffer("costs", any_size());
    g.add_pass(pass("write", PassKind::compute, {{b, Use::storage_write}}));
    g.add_pass(pass("read1", PassKind::compute, {{b, Use::storage_read}}));
    g.add_pass(pass("read2", PassKind::compute, {{b, Use::storage_read}}));
    g.add_pass(pass("copy", PassKind::transfer, {{b, Use::transfer_src}}));
    const CompiledGraph c = compile(g);
    CHECK(c.pass_barriers[1].size() == 1);
    CHECK(c.pass_barriers[2].empty());
    REQUIRE(c.pass_barriers[3].size() == 1);  // a new stage must still wait for the write
    CHECK(c.pass_barriers[3][0].src_access == VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    CHECK(c.pass_barriers[3][0].dst_stage == VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT);
  }

  TEST_CASE("a_read_after_a_read_write_pass_waits_for_that_pass_writes") {
    Graph g;
    const ResourceId b = g.add_buffer("carries", any_size());
    g.add_pass(pass("sums", PassKind::compute, {{b, Use::storage_write}}));
    g.add_pass(pass("scan_in_place", PassKind::compute, {{b, Use::storage_read_write}}));
    g.add_pass(pass("use", PassKind::compute, {{b, Use::storage_read}}));
    const CompiledGraph c = compile(g);
    REQUIRE(c.pass_barriers[1].size() == 1);
    REQUIRE(c.pass_barriers[2].size() == 1);
    CHECK(c.pass_barriers[2][0].src_access == VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    CHECK(c.pass_barriers[2][0].dst_access == VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
  }

  TEST_CASE("write_after_read_waits_for_the_readers_with_an_execution_dependency") {
    Graph g;
    const ResourceId b = g.add_buffer("positions", any_size());
    g.add_pass(pass("write", PassKind::compute, {{b, Use::storage_write}}));
    g.add_pass(pass("draw_reads", PassKind::graphics, {{b, Use::storage_read}}));
    g.add_pass(pass("overwrite", PassKind::compute, {{b, Use::storage_write}}));
    const CompiledGraph c = compile(g);
    REQUIRE(c.pass_barriers[2].size() == 1);
    const Barrier& war = c.pass_barriers[2][0];
    // Waits for the last write and for the readers in the graphics stages.
    CHECK((war.src_stage & VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT) != 0);
    CHECK((war.src_stage & VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT) != 0);
    CHECK(war.dst_access == VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
  }

  TEST_CASE("write_after_write_orders_the_two_writes") {
    Graph g;
    const ResourceId b = g.add_buffer("table", any_size());
    g.add_pass(pass("clear", PassKind::transfer, {{b, Use::transfer_dst}}));
    g.add_pass(pass("accumulate", PassKind::compute, {{b, Use::storage_read_write}}));
    g.add_pass(pass("overwrite", PassKind::compute, {{b, Use::storage_write}}));
    const CompiledGraph c = compile(g);
    REQUIRE(c.pass_barriers[1].size() == 1);
    CHECK(c.pass_barriers[1][0].src_stage == VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT);
    CHECK(c.pass_barriers[1][0].src_access == VK_ACCESS_2_TRANSFER_WRITE_BIT);
    REQUIRE(c.pass_barriers[2].size() == 1);
    CHECK(c.pass_barriers[2][0].src_access == VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    CHECK(c.pass_barriers[2][0].dst_access == VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
  }

  TEST_CASE("image_layouts_follow_each_use_and_the_first_write_discards") {
    Graph g;
    const ResourceId img = g.add_image("layer", {VK_FORMAT_R16G16B16A16_SFLOAT});
    g.add_pass(pass("resolve", PassKind::compute, {{img, Use::storage_write}}));
    g.add_pass(pass("composite", PassKind::compute, {{img, Use::sampled}}));
    g.add_pass(pass("readback", PassKind::transfer, {{img, Use::transfer_src}}));
    const CompiledGraph c = compile(g);
    REQUIRE(c.pass_barriers[0].size() == 1);
    CHECK(c.pass_barriers[0][0].old_layout == VK_IMAGE_LAYOUT_UNDEFINED);
    CHECK(c.pass_barriers[0][0].new_layout == VK_IMAGE_LAYOUT_GENERAL);
    REQUIRE(c.pass_barriers[1].size() == 1);
    CHECK(c.pass_barriers[1][0].old_layout == VK_IMAGE_LAYOUT_GENERAL);
    CHECK(c.pass_barriers[1][0].new_layout == VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    CHECK(c.pass_barriers[1][0].src_access == VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    REQUIRE(c.pass_barriers[2].size() == 1);
    CHECK(c.pass_barriers[2][0].old_layout == VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    CHECK(c.pass_barriers[2][0].new_layout == VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
    CHECK(c.layout[1][img] == VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    CHECK(c.usage[img] == (VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                           VK_IMAGE_USAGE_TRANSFER_SRC_BIT));
  }

  TEST_CASE("reading_what_nothing_wrote_is_an_error_naming_the_pass_and_the_resource") {
    Graph g;
    const ResourceId b = g.add_buffer("saliency", any_size());
    g.add_pass(pass("integral_costs", PassKind::compute, {{b, Use::storage_read}}));
    CHECK_THROWS_WITH_AS(compile(g), doctest::Contains("pass 'integral_costs' reads 'saliency'"),
                         GraphError);
  }

  // Predicates (Use::conditional) are read by the command processor: a pass that writes them
  // itself may read them (after its own barrier_for_predicates); otherwise an earlier pass must
  // have written them, and the graph's barrier waits for the writer before the predicate read.
  TEST_CASE("predicates_need_a_writer_the_pass_itself_or_one_before_with_a_barrier") {
    Graph own;
    const ResourceId rounds = own.add_buffer("rounds", any_size());
    own.add_pass(pass("tidy", PassKind::compute,
                      {{rounds, Use::storage_write}, {rounds, Use::conditional}}));
    const CompiledGraph c_own = compile(own);
    CHECK(c_own.pass_barriers[0].empty());
    CHECK(c_own.usage[rounds] ==
          (VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_CONDITIONAL_RENDERING_BIT_EXT));

    Graph unwritten;
    const ResourceId flag = unwritten.add_buffer("flag", any_size());
    unwritten.add_pass(pass("skip", PassKind::compute, {{flag, Use::conditional}}));
    CHECK_THROWS_WITH_AS(compile(unwritten), doctest::Contains("pass 'skip' reads 'flag'"),
                         GraphError);

    Graph before;
    const ResourceId b = before.add_buffer("flag", any_size());
    before.add_pass(pass("fill", PassKind::transfer, {{b, Use::transfer_dst}}));
    before.add_pass(pass("skip", PassKind::compute, {{b, Use::conditional}}));
    const CompiledGraph c = compile(before);
    REQUIRE(c.pass_barriers[1].size() == 1);
    CHECK(c.pass_barriers[1][0].src_stage == VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT);
    CHECK(c.pass_barriers[1][0].dst_stage == VK_PIPELINE_STAGE_2_CONDITIONAL_RENDERING_BIT_EXT);
    CHECK(c.pass_barriers[1][0].dst_access == VK_ACCESS_2_CONDITIONAL_RENDERING_READ_BIT_EXT);
  }

  TEST_CASE("an_import_with_content_can_be_read_without_a_writer") {
    Graph g;
    const ResourceId volume = g.import_image(
        "volume",
        {.has_content = true, .initial_layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL});
    g.add_pass(pass("raycast", PassKind::compute, {{volume, Use::sampled}}));
    const CompiledGraph c = compile(g);
    CHECK(c.pass_barriers[0].empty());  // already in the layout it is read in, nothing to wait for
  }

  TEST_CASE("final_uses_of_imports_get_their_barriers_after_the_last_pass") {
    Graph g;
    const ResourceId swapchain = g.import_image(
        "swapchain",
        {.final_use = Use::present, .initial_stage = VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT});
    const ResourceId readback = g.import_buffer("positions", {.final_use = Use::host_read});
    g.add_pass(pass("blit", PassKind::transfer,
                    {{swapchain, Use::transfer_dst}, {readback, Use::transfer_dst}}));
    const CompiledGraph c = compile(g);
    REQUIRE(c.pass_barriers[0].size() == 1);  // the swapchain transition chains on the acquire wait
    CHECK(c.pass_barriers[0][0].src_stage == VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT);
    REQUIRE(c.final_barriers.size() == 2);
    CHECK(c.final_barriers[0].new_layout == VK_IMAGE_LAYOUT_PRESENT_SRC_KHR);
    CHECK(c.final_barriers[0].old_layout == VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
    CHECK(c.final_barriers[1].dst_stage == VK_PIPELINE_STAGE_2_HOST_BIT);
    CHECK(c.final_barriers[1].dst_access == VK_ACCESS_2_HOST_READ_BIT);
  }

  TEST_CASE("an_import_handed_on_unwritten_is_an_error") {
    Graph g;
    g.import_image("swapchain", {.final_use = Use::present});
    CHECK_THROWS_WITH_AS(compile(g), doctest::Contains("'swapchain'"), GraphError);
  }

  TEST_CASE("one_image_in_two_layouts_in_one_pass_is_an_error") {
    Graph g;
    const ResourceId img = g.add_image("frame", {});
    g.add_pass(pass("draw", PassKind::compute, {{img, Use::storage_write}}));
    g.add_pass(pass("both", PassKind::compute, {{img, Use::sampled}, {img, Use::storage_write}}));
    CHECK_THROWS_WITH_AS(
        compile(g), doctest::Contains("pass 'both' uses image 'frame' in two layouts"), GraphError);
  }

  TEST_CASE("two_uses_of_one_buffer_in_a_pass_merge_into_one_barrier") {
    Graph g;
    const ResourceId b = g.add_buffer("hash", any_size());
    g.add_pass(pass("clear", PassKind::compute, {{b, Use::storage_write}}));
    g.add_pass(pass("insert", PassKind::graphics,
                    {{b, Use::storage_read, 0}, {b, Use::storage_write, 1}}));
    const CompiledGraph c = compile(g);
    REQUIRE(c.pass_barriers[1].size() == 1);
    CHECK(c.pass_barriers[1][0].dst_access ==
          (VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT));
  }

  TEST_CASE("uses_that_do_not_fit_the_resource_or_reuse_a_binding_are_errors") {
    Graph g;
    const ResourceId b = g.add_buffer("buffer", any_size());
    const ResourceId img = g.add_image("image", {});
    Graph g1 = g;
    g1.add_pass(pass("p", PassKind::compute, {{b, Use::sampled}}));
    CHECK_THROWS_WITH_AS(compile(g1), doctest::Contains("cannot use buffer 'buffer' as sampled"),
                         GraphError);
    Graph g2 = g;
    g2.add_pass(pass("p", PassKind::compute, {{img, Use::indirect}}));
    CHECK_THROWS_AS(compile(g2), GraphError);
    Graph g3 = g;
    g3.add_pass(
        pass("p", PassKind::compute, {{b, Use::storage_write, 2}, {img, Use::storage_write, 2}}));
    CHECK_THROWS_WITH_AS(compile(g3), doctest::Contains("binds two resources to binding 2"),
                         GraphError);
    Graph g4 = g;
    g4.add_pass(pass("p", PassKind::compute, {{ResourceId{99}, Use::storage_write}}));
    CHECK_THROWS_WITH_AS(compile(g4), doctest::Contains("resource #99"), GraphError);
  }
}

}  // namespace strata::graph

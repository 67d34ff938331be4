#include "pass.h"

#include "msm/techniques.h"

namespace msm::render {

void SatPass::prepare(const PassResources& r) { builder_ = &r.sat_builder; }

void SatPass::reflect(PassBuilder& b) const {
  for (int i = 0; i < config_.moment_images(); ++i) {
    b.read(moment_image(0, i), use::sampled(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT));
    // Two moments per texel (vssm; mssm6's second image) need only RG32_UINT.
    bool two = config_.formats()[size_t(i)] == VK_FORMAT_R32G32_SFLOAT;
    b.create(sat_table(i),
             {.format = two ? VK_FORMAT_R32G32_UINT : VK_FORMAT_R32G32B32A32_UINT,
              .width = uint32_t(config_.shadow_size),
              .height = uint32_t(config_.shadow_size * msm_technique_tiles(config_.technique->id)),
              .layers = uint32_t(config_.lights)},
             use::compute_general());
  }
}

void SatPass::execute(const PassContext& c) const {
  // Rows then columns: on lavapipe several times faster than the block scheme (docs/results.md,
  // "Integer summed-area tables"). Every layer
  // (light) of every image in one record(), so the row passes run side by side.
  std::vector<gpu::SatImage> moments, tables;
  for (int l = 0; l < config_.lights; ++l)
    for (int i = 0; i < config_.moment_images(); ++i) {
      const GraphImage& m = c.image(moment_image(0, i));
      const GraphImage& t = c.image(sat_table(i));
      moments.emplace_back(m.image, m.layer_mip0_views[size_t(l)], uint32_t(l));
      tables.emplace_back(t.image, t.layer_views[size_t(l)], uint32_t(l));
    }
  builder_->record(c.cmd, moments, tables, config_.soft_kernel * config_.soft_kernel,
                   gpu::SatBuilder::Scheme::rows_then_columns, nullptr, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
}

} // namespace msm::render

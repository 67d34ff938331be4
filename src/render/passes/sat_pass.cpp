#include "pass.h"

namespace msm::render {

const PassDecl& SatPass::decl() {
  static const PassDecl d{"sat", {"moments"}, {"sat_tables"}};
  return d;
}

SatPass::SatPass(const vk::Context& ctx) : builder_(std::make_unique<soft::SatBuilder>(ctx)) {}

void SatPass::execute(FrameContext& f, int max_kernel_texels) const {
  PassScope scope(f, decl());
  // Rows then columns: on lavapipe 3-7x faster than the block scheme (docs/results.md).
  const FrameTargets& t = f.targets;
  std::vector<const vk::Image*> moments, tables;
  for (int i = 0; i < t.config.moment_images(); ++i) {
    moments.push_back(&t.moments[size_t(i)]);
    tables.push_back(&t.sat_tables[size_t(i)]);
  }
  builder_->record(f.cmd, moments, tables, max_kernel_texels, soft::SatBuilder::Scheme::rows_then_columns, nullptr,
                   VK_IMAGE_LAYOUT_GENERAL);
  vk::pipeline_barrier(f.cmd,
                       vk::memory_barrier(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                          VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                                          VK_ACCESS_2_SHADER_SAMPLED_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_READ_BIT));
}

} // namespace msm::render

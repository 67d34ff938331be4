// The renderer's pipelines, built on first use and kept for the renderer's lifetime: every pass
// asks here, so a pipeline's identity (its cache key) is defined in one place. Building is the
// expensive part of a configuration change (lavapipe compiles each pipeline to machine code).
#pragma once

#include "msm/vk/vk.h"

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace msm::render {

class ProgramCache {
 public:
  explicit ProgramCache(const vk::Context& ctx) : ctx_(ctx) {}
  const vk::Program& compute(const std::string& shader, const std::vector<vk::Binding>& bindings,
                             uint32_t push_constant_size, const std::vector<vk::SpecConstant>& constants = {});
  const vk::Program& graphics(const vk::GraphicsDesc& desc);
  const vk::Context& context() const { return ctx_; }
  std::size_t size() const { return programs_.size(); }

 private:
  const vk::Context& ctx_;
  std::map<std::string, std::unique_ptr<vk::Program>> programs_;
};

} // namespace msm::render

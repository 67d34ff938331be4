// Integer summed-area tables of moment shadow maps on the device (JCGT 2017 §4.2, Appendix C),
// and the same tables on the CPU. The per-texel math (quantization, wrap-around, queries) is
// include/msm/sat.h, shared with the shaders; the shaders are src/gpu/shaders/sat_*.comp.
//
//   msm::gpu::SatBuilder sat(ctx);
//   sat.record(cmd, moments, table, 27 * 27, msm::gpu::SatBuilder::Scheme::Blocks, &timer);
//
// Six moments (Θ6*, sat.h's msm_sat_split6): two moment images and two tables; record each pair
// (or use the overload with two pairs, whose passes run side by side).
#pragma once

#include "msm/vk/context.h"
#include "msm/vk/program.h"
#include "msm/vk/resources.h"
#include "msm/vk/timer.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <span>
#include <vector>

namespace msm::gpu {

// One layer of an image as the builder reads (moments) or writes (a table) it: the layer's view
// (mip 0 is what counts) and what the checks and barriers need.
struct SatImage {
  VkImage handle = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;
  uint32_t width = 0, height = 0;
  VkImageUsageFlags usage = 0;
  uint32_t mips = 1;
  uint32_t layer = 0;
  SatImage() = default;
  SatImage(const vk::Image& image); // NOLINT(google-explicit-constructor): a one-layer image as it is
  SatImage(const vk::Image& image, VkImageView layer_view, uint32_t layer);
};

class SatBuilder {
 public:
  enum class Scheme {
    // Two passes, one thread per row, then one per column (Klehm et al. 2014; JCGT §4.2, App. D.4).
    // Timer scopes "sat_rows" and "sat_columns".
    rows_then_columns,
    // JCGT Appendix C: 8 × 8 workgroups walking 8 × 8 blocks, eight threads per row (then per
    // column), each writing one prefix sum per block. Timer scope "sat_blocks" (both passes).
    blocks,
    // rows_then_columns with coalesced rows: a workgroup of 64 threads per row scans it in chunks
    // of 64 neighbouring texels (shared memory), then the column pass. Every texel read and
    // written once per pass. Timer scopes "sat_rows" and "sat_columns".
    scan_rows_then_columns,
    // rows_then_columns with subgroup rows (Vulkan 1.1 subgroup arithmetic): one subgroup per row
    // walks it in chunks of subgroup-size neighbouring texels, subgroupInclusiveAdd plus a running
    // carry (the last lane's sum); no barriers, no shared memory. Every texel read and written once
    // per pass. Where the device lacks subgroup arithmetic in compute shaders
    // (subgroup_arithmetic()), record() runs scan_rows_then_columns instead. Timer scopes
    // "sat_rows" and "sat_columns".
    subgroup_rows_then_columns,
    // subgroup_rows_then_columns whose column pass is the same subgroup scan down each column (its
    // lanes a row pitch apart: no coalescing on a GPU; measured against the thread-per-column pass
    // on lavapipe, msm_sat_timing). Same fallback and timer scopes.
    subgroup_rows_and_columns,
  };

  // Creates the compute pipelines and a nearest sampler.
  explicit SatBuilder(const vk::Context& ctx);

  // Whether the device has subgroup arithmetic in compute shaders (VkPhysicalDeviceVulkan11Properties:
  // subgroupSupportedStages has COMPUTE, subgroupSupportedOperations has ARITHMETIC, BASIC and
  // SHUFFLE), i.e. whether the subgroup schemes run as themselves.
  bool subgroup_arithmetic() const noexcept { return bool(subgroup_rows_); }
  // The scheme record() runs for `scheme`: the scheme itself, or scan_rows_then_columns for a
  // subgroup scheme on a device without subgroup arithmetic.
  Scheme effective(Scheme scheme) const noexcept;

  // Records the passes that fill `table` with the summed-area table of `moments` for kernels of
  // at most max_kernel_texels texels (n_t; sat.h: quantization scale floor((2^32 - 1) / n_t)).
  //  - moments: RGBA32_SFLOAT, RG32_SFLOAT, RGBA16_UNORM or RG16_UNORM (RG images count as
  //    (r, g, 0, 0); UNORM codes are decoded as the C++ build decodes them, sat.h), SAMPLED usage, mip 0 is
  //    read, in moments_layout (GENERAL or SHADER_READ_ONLY_OPTIMAL); the caller's barrier has
  //    made its writes visible to compute-shader sampled reads.
  //  - table: RGBA32_UINT, or RG32_UINT for RG moments (half the memory and traffic; it holds the
  //    (r, g) of the RGBA table), the same width and height, STORAGE usage, one mip. Its contents and
  //    layout on entry do not matter (record() discards them: a barrier from UNDEFINED that waits
  //    for earlier writes); on exit it is in GENERAL, written by the COMPUTE_SHADER stage
  //    (SHADER_STORAGE_WRITE): the caller's barrier makes that visible to its readers.
  //  - timer: if given, scopes as listed with the schemes (reset() is the caller's).
  // Throws std::invalid_argument for other formats, mismatched sizes or max_kernel_texels < 1.
  void record(VkCommandBuffer cmd, const SatImage& moments, const SatImage& table, int max_kernel_texels, Scheme scheme,
              vk::GpuTimer* timer = nullptr, VkImageLayout moments_layout = VK_IMAGE_LAYOUT_GENERAL) const;

  // Several images (e.g. the two of six moments, or the layers of one light each) at once: each
  // pass is dispatched for every pair before the barrier that separates the passes. Preconditions
  // as above, per pair; the tables' barriers cover their own layer only.
  void record(VkCommandBuffer cmd, std::span<const SatImage> moments, std::span<const SatImage> tables,
              int max_kernel_texels, Scheme scheme, vk::GpuTimer* timer = nullptr,
              VkImageLayout moments_layout = VK_IMAGE_LAYOUT_GENERAL) const;

 private:
  vk::Program rows_, columns_, block_rows_, block_columns_;
  vk::Program rows_rg_, columns_rg_, block_rows_rg_, block_columns_rg_; // RG32_UINT tables
  vk::Program scan_rows_, scan_rows_rg_;
  // Null where the device lacks subgroup arithmetic in compute shaders.
  vk::Program subgroup_rows_, subgroup_rows_rg_, subgroup_columns_, subgroup_columns_rg_;
  uint32_t subgroup_size_ = 0; // the device's (VkPhysicalDeviceVulkan11Properties::subgroupSize)
  vk::Sampler sampler_;
};

// The table on the CPU, with sat.h's msm_sat_quantize: row-major, width × height texels of moments
// (Θ4*, or half of Θ6*) in; the same layout of uvec4 out. A table built by SatBuilder from the same
// values (a float image, or a UNORM16 image whose texels are given here as msm_unpack_unorm16x4
// decodes them) is bitwise equal. Precondition: moments.size() == width * height.
std::vector<glm::uvec4> build_sat_cpu(std::span<const glm::vec4> moments, int width, int height, int max_kernel_texels);

} // namespace msm::gpu

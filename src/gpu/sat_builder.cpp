#include "msm/gpu/sat_builder.h"

#include "msm/sat.h"
#include "msm/vk/commands.h"
#include "shaders/sat_interface.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace msm::gpu {

namespace {

bool unorm16_format(VkFormat format) {
  return format == VK_FORMAT_R16G16B16A16_UNORM || format == VK_FORMAT_R16G16_UNORM;
}
bool float_format(VkFormat format) {
  return format == VK_FORMAT_R32G32B32A32_SFLOAT || format == VK_FORMAT_R32G32_SFLOAT;
}
bool two_channels(VkFormat format) { return format == VK_FORMAT_R32G32_SFLOAT || format == VK_FORMAT_R16G16_UNORM; }

void check(const SatImage& moments, const SatImage& table, int max_kernel_texels) {
  const char* where = "msm::gpu::SatBuilder::record: ";
  if (!moments.handle || !table.handle || !moments.view || !table.view)
    throw std::invalid_argument(std::string(where) + "null image");
  if (!unorm16_format(moments.format) && !float_format(moments.format))
    throw std::invalid_argument(std::string(where) +
                                "moments must be RGBA32_SFLOAT, RG32_SFLOAT, RGBA16_UNORM or RG16_UNORM");
  if (!(moments.usage & VK_IMAGE_USAGE_SAMPLED_BIT))
    throw std::invalid_argument(std::string(where) + "moments need SAMPLED usage");
  if (table.format != VK_FORMAT_R32G32B32A32_UINT &&
      !(table.format == VK_FORMAT_R32G32_UINT && two_channels(moments.format)))
    throw std::invalid_argument(std::string(where) + "the table must be RGBA32_UINT (or RG32_UINT for RG moments)");
  if (!(table.usage & VK_IMAGE_USAGE_STORAGE_BIT) || table.mips != 1)
    throw std::invalid_argument(std::string(where) + "the table needs STORAGE usage and one mip");
  if (moments.width != table.width || moments.height != table.height)
    throw std::invalid_argument(std::string(where) + "moments and table differ in size");
  if (max_kernel_texels < 1) throw std::invalid_argument(std::string(where) + "max_kernel_texels < 1");
}

// Subgroup arithmetic (with the basic and shuffle operations the subgroup shaders use) in compute
// shaders; the device's subgroup size, or 0 where it lacks them.
uint32_t subgroup_size_with_arithmetic(const vk::Context& ctx) {
  VkPhysicalDeviceVulkan11Properties v11{.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_PROPERTIES};
  VkPhysicalDeviceProperties2 p2{.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, .pNext = &v11};
  vkGetPhysicalDeviceProperties2(ctx.physical_device(), &p2);
  const VkSubgroupFeatureFlags needed =
      VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_ARITHMETIC_BIT | VK_SUBGROUP_FEATURE_SHUFFLE_BIT;
  if (!(v11.subgroupSupportedStages & VK_SHADER_STAGE_COMPUTE_BIT) ||
      (v11.subgroupSupportedOperations & needed) != needed || v11.subgroupSize == 0)
    return 0;
  return v11.subgroupSize;
}

// A row pass: the moment image sampled, the table written.
vk::Program rows_program(const vk::Context& ctx, const char* name) {
  return vk::create_program(ctx, name,
                            {{MSM_BINDING_SAT_ROWS_MOMENTS, vk::Binding::sampled_image},
                             {MSM_BINDING_SAT_ROWS_TABLE, vk::Binding::storage_image}},
                            sizeof(SatPush));
}

// A column pass: the table, in place.
vk::Program columns_program(const vk::Context& ctx, const char* name) {
  return vk::create_program(ctx, name, {{MSM_BINDING_SAT_COLUMNS_TABLE, vk::Binding::storage_image}}, sizeof(SatPush));
}

vk::Program subgroup_program(const vk::Context& ctx, bool supported, const char* name, bool rows) {
  if (!supported) return {};
  return rows ? rows_program(ctx, name) : columns_program(ctx, name);
}

} // namespace

SatImage::SatImage(const vk::Image& image)
    : handle(image.handle()), view(image.view()), format(image.format()), width(image.width()), height(image.height()),
      usage(image.desc().usage), mips(image.desc().mip_levels) {
  if (image && image.desc().layers != 1)
    throw std::invalid_argument("msm::gpu::SatImage: an array image needs a layer view");
}

SatImage::SatImage(const vk::Image& image, VkImageView layer_view, uint32_t layer_index)
    : handle(image.handle()), view(layer_view), format(image.format()), width(image.width()), height(image.height()),
      usage(image.desc().usage), mips(image.desc().mip_levels), layer(layer_index) {}

SatBuilder::SatBuilder(const vk::Context& ctx)
    : rows_(rows_program(ctx, "sat_rows.comp")), columns_(columns_program(ctx, "sat_columns.comp")),
      block_rows_(rows_program(ctx, "sat_block_rows.comp")),
      block_columns_(columns_program(ctx, "sat_block_columns.comp")), rows_rg_(rows_program(ctx, "sat_rows_rg.comp")),
      columns_rg_(columns_program(ctx, "sat_columns_rg.comp")),
      block_rows_rg_(rows_program(ctx, "sat_block_rows_rg.comp")),
      block_columns_rg_(columns_program(ctx, "sat_block_columns_rg.comp")),
      scan_rows_(rows_program(ctx, "sat_scan_rows.comp")), scan_rows_rg_(rows_program(ctx, "sat_scan_rows_rg.comp")),
      sampler_(vk::create_sampler(ctx, VK_FILTER_NEAREST)) {
  subgroup_size_ = subgroup_size_with_arithmetic(ctx);
  const bool sg = subgroup_size_ != 0;
  subgroup_rows_ = subgroup_program(ctx, sg, "sat_subgroup_rows.comp", true);
  subgroup_rows_rg_ = subgroup_program(ctx, sg, "sat_subgroup_rows_rg.comp", true);
  subgroup_columns_ = subgroup_program(ctx, sg, "sat_subgroup_columns.comp", false);
  subgroup_columns_rg_ = subgroup_program(ctx, sg, "sat_subgroup_columns_rg.comp", false);
}

SatBuilder::Scheme SatBuilder::effective(Scheme scheme) const noexcept {
  bool subgroup = scheme == Scheme::subgroup_rows_then_columns || scheme == Scheme::subgroup_rows_and_columns;
  return subgroup && !subgroup_arithmetic() ? Scheme::scan_rows_then_columns : scheme;
}

void SatBuilder::record(VkCommandBuffer cmd, const SatImage& moments, const SatImage& table, int max_kernel_texels,
                        Scheme scheme, vk::GpuTimer* timer, VkImageLayout moments_layout) const {
  record(cmd, std::span(&moments, 1), std::span(&table, 1), max_kernel_texels, scheme, timer, moments_layout);
}

void SatBuilder::record(VkCommandBuffer cmd, std::span<const SatImage> moments, std::span<const SatImage> tables,
                        int max_kernel_texels, Scheme scheme, vk::GpuTimer* timer, VkImageLayout moments_layout) const {
  if (moments.size() != tables.size())
    throw std::invalid_argument("msm::gpu::SatBuilder::record: as many tables as moment images");
  for (size_t i = 0; i < moments.size(); ++i) check(moments[i], tables[i], max_kernel_texels);
  if (moments.empty()) return;
  scheme = effective(scheme);
  const uint32_t scale = msm_sat_scale(max_kernel_texels);
  const VkImageLayout general = VK_IMAGE_LAYOUT_GENERAL;
  auto push = [&](size_t i) {
    const SatImage& m = moments[i];
    bool two = two_channels(m.format);
    return SatPush{glm::ivec2(int(m.width), int(m.height)), scale,
                   (unorm16_format(m.format) ? MSM_SAT_UNORM16 : 0u) | (two ? MSM_SAT_TWO_CHANNELS : 0u)};
  };
  // The program of each pass for table i: the table's format is part of the shader.
  auto program = [&](size_t i, const vk::Program& rgba, const vk::Program& rg) -> const vk::Program& {
    return tables[i].format == VK_FORMAT_R32G32_UINT ? rg : rgba;
  };

  // Discard the tables' contents (UNDEFINED), after every earlier access to them.
  for (const SatImage& table : tables)
    vk::pipeline_barrier(cmd, vk::image_barrier(table.handle, VK_IMAGE_ASPECT_COLOR_BIT,
                                                VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                                                VK_IMAGE_LAYOUT_UNDEFINED, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                                VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, general, 0, 1, table.layer, 1));
  // Pass 1 writes every texel; pass 2 reads and rewrites them in place.
  const VkMemoryBarrier2 between =
      vk::memory_barrier(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                         VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                         VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);

  if (scheme != Scheme::blocks) {
    const bool scan = scheme == Scheme::scan_rows_then_columns;
    const bool subgroup_rows =
        scheme == Scheme::subgroup_rows_then_columns || scheme == Scheme::subgroup_rows_and_columns;
    const bool subgroup_columns = scheme == Scheme::subgroup_rows_and_columns;
    // The subgroup passes: 64 / subgroup size rows (columns) per workgroup of 64 (their loops cover
    // the rest, should the shader get other subgroups than the device reports).
    auto subgroup_groups = [&](uint32_t lines) {
      return vk::group_count(lines, std::max(1u, 64u / std::min(64u, subgroup_size_)));
    };
    if (timer) timer->begin(cmd, "sat_rows");
    for (size_t i = 0; i < moments.size(); ++i) {
      const vk::Program& p = subgroup_rows ? program(i, subgroup_rows_, subgroup_rows_rg_)
                             : scan        ? program(i, scan_rows_, scan_rows_rg_)
                                           : program(i, rows_, rows_rg_);
      uint32_t groups = subgroup_rows ? subgroup_groups(moments[i].height)
                        : scan        ? moments[i].height
                                      : vk::group_count(moments[i].height, 64);
      vk::dispatch(cmd, p, groups, 1, 1,
                   {{MSM_BINDING_SAT_ROWS_MOMENTS, vk::Descriptor(moments[i].view, moments_layout, sampler_)},
                    {MSM_BINDING_SAT_ROWS_TABLE, vk::Descriptor(tables[i].view, general)}},
                   push(i));
    }
    if (timer) timer->end(cmd);
    vk::pipeline_barrier(cmd, between);
    if (timer) timer->begin(cmd, "sat_columns");
    for (size_t i = 0; i < moments.size(); ++i)
      vk::dispatch(cmd,
                   subgroup_columns ? program(i, subgroup_columns_, subgroup_columns_rg_)
                                    : program(i, columns_, columns_rg_),
                   subgroup_columns ? subgroup_groups(moments[i].width) : vk::group_count(moments[i].width, 64), 1, 1,
                   {{MSM_BINDING_SAT_COLUMNS_TABLE, vk::Descriptor(tables[i].view, general)}}, push(i));
    if (timer) timer->end(cmd);
  } else {
    if (timer) timer->begin(cmd, "sat_blocks");
    for (size_t i = 0; i < moments.size(); ++i)
      vk::dispatch(cmd, program(i, block_rows_, block_rows_rg_), vk::group_count(moments[i].height, 8), 1, 1,
                   {{MSM_BINDING_SAT_ROWS_MOMENTS, vk::Descriptor(moments[i].view, moments_layout, sampler_)},
                    {MSM_BINDING_SAT_ROWS_TABLE, vk::Descriptor(tables[i].view, general)}},
                   push(i));
    vk::pipeline_barrier(cmd, between);
    for (size_t i = 0; i < moments.size(); ++i)
      vk::dispatch(cmd, program(i, block_columns_, block_columns_rg_), vk::group_count(moments[i].width, 8), 1, 1,
                   {{MSM_BINDING_SAT_COLUMNS_TABLE, vk::Descriptor(tables[i].view, general)}}, push(i));
    if (timer) timer->end(cmd);
  }
}

std::vector<glm::uvec4> build_sat_cpu(std::span<const glm::vec4> moments, int width, int height,
                                      int max_kernel_texels) {
  if (width < 0 || height < 0 || moments.size() != size_t(width) * size_t(height))
    throw std::invalid_argument("msm::gpu::build_sat_cpu: moments.size() != width * height");
  const uint32_t scale = msm_sat_scale(max_kernel_texels);
  std::vector<glm::uvec4> table(moments.size());
  for (int y = 0; y < height; ++y) {
    glm::uvec4 sum(0u);
    for (int x = 0; x < width; ++x) {
      size_t i = size_t(y) * size_t(width) + size_t(x);
      sum += msm_sat_quantize(moments[i], scale); // wraps modulo 2^32, as on the device
      table[i] = sum;
    }
  }
  for (int y = 1; y < height; ++y)
    for (int x = 0; x < width; ++x)
      table[size_t(y) * size_t(width) + size_t(x)] += table[size_t(y - 1) * size_t(width) + size_t(x)];
  return table;
}

} // namespace msm::gpu

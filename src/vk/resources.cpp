#include "msm/vk/resources.h"

#include "msm/vk/commands.h"
#include "msm/vk/context.h"

#include <fmt/format.h>

#include <cstring>

namespace msm::vk {

Buffer::Buffer(Buffer&& other) noexcept
    : memory_(std::move(other.memory_)), buffer_(std::move(other.buffer_)), size_(std::exchange(other.size_, 0)),
      data_(std::exchange(other.data_, nullptr)), memory_kind_(other.memory_kind_) {}

Buffer& Buffer::operator=(Buffer&& other) noexcept {
  if (this != &other) {
    buffer_.reset(); // the buffer before the memory bound to it
    memory_ = std::move(other.memory_);
    buffer_ = std::move(other.buffer_);
    size_ = std::exchange(other.size_, 0);
    data_ = std::exchange(other.data_, nullptr);
    memory_kind_ = other.memory_kind_;
  }
  return *this;
}

Image& Image::operator=(Image&& other) noexcept {
  if (this != &other) {
    view_.reset(); // view, image, then memory
    image_.reset();
    memory_ = std::move(other.memory_);
    image_ = std::move(other.image_);
    view_ = std::move(other.view_);
    desc_ = other.desc_;
    aspect_ = other.aspect_;
  }
  return *this;
}

uint32_t select_memory_type(const VkPhysicalDeviceMemoryProperties& properties, uint32_t type_bits,
                            VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred) {
  for (VkMemoryPropertyFlags wanted : {required | preferred, required})
    for (uint32_t i = 0; i < properties.memoryTypeCount; ++i)
      if ((type_bits & (1u << i)) && (properties.memoryTypes[i].propertyFlags & wanted) == wanted) return i;
  throw std::runtime_error(
      fmt::format("msm::vk: no memory type with flags {:#x} among types {:#x}", required, type_bits));
}

namespace {

VkDeviceMemory allocate(const Context& ctx, const VkMemoryRequirements& requirements, VkMemoryPropertyFlags required,
                        VkMemoryPropertyFlags preferred) {
  VkMemoryAllocateInfo info{
      .sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO,
      .allocationSize = requirements.size,
      .memoryTypeIndex = select_memory_type(ctx.memory_properties(), requirements.memoryTypeBits, required, preferred)};
  // Out of memory is the one failure bad input provokes (a huge image or shadow map): the message
  // names the size and the heap, and an allocation larger than the heap is refused before the
  // driver sees it (what drivers do with one differs; the validation layer calls it an error).
  const VkPhysicalDeviceMemoryProperties& props = ctx.memory_properties();
  const VkMemoryHeap& heap = props.memoryHeaps[props.memoryTypes[info.memoryTypeIndex].heapIndex];
  auto out_of_memory = [&](VkResult result) {
    return Error(
        result,
        fmt::format("{}: {:.1f} MiB asked of a heap of {:.1f} MiB on {} (lower the image or "
                    "shadow-map size, the MSAA samples or the lights)",
                    result == VK_ERROR_OUT_OF_HOST_MEMORY ? "out of host memory" : "the device is out of memory",
                    double(requirements.size) / double(1 << 20), double(heap.size) / double(1 << 20), ctx.info().name));
  };
  if (requirements.size > heap.size) throw out_of_memory(VK_ERROR_OUT_OF_DEVICE_MEMORY);
  VkDeviceMemory memory = VK_NULL_HANDLE;
  const VkResult result = vkAllocateMemory(ctx.device(), &info, nullptr, &memory);
  if (result == VK_ERROR_OUT_OF_DEVICE_MEMORY || result == VK_ERROR_OUT_OF_HOST_MEMORY) throw out_of_memory(result);
  MSM_VK_CHECK(result);
  return memory;
}

void check_range(const Buffer& buffer, VkDeviceSize offset, std::size_t size, const char* what) {
  if (offset > buffer.size() || size > buffer.size() - offset)
    throw std::out_of_range(fmt::format("msm::vk::{}: range [{}, {}) outside a buffer of {} bytes", what, offset,
                                        offset + size, buffer.size()));
}

} // namespace

Buffer create_buffer(const Context& ctx, VkDeviceSize size, VkBufferUsageFlags usage, Memory memory) {
  if (size == 0) throw std::invalid_argument("msm::vk::create_buffer: size 0");
  if (memory == Memory::device) usage |= VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  VkDevice device = ctx.device();
  VkBufferCreateInfo info{.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO,
                          .size = size,
                          .usage = usage,
                          .sharingMode = VK_SHARING_MODE_EXCLUSIVE};
  Buffer result;
  VkBuffer buffer = VK_NULL_HANDLE;
  MSM_VK_CHECK(vkCreateBuffer(device, &info, nullptr, &buffer));
  result.buffer_ = {device, buffer};
  VkMemoryRequirements requirements;
  vkGetBufferMemoryRequirements(device, buffer, &requirements);
  // Host: cached memory makes readbacks fast; uploads are memcpy'd once and do not care.
  result.memory_ = {device, memory == Memory::host
                                ? allocate(ctx, requirements,
                                           VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
                                           VK_MEMORY_PROPERTY_HOST_CACHED_BIT)
                                : allocate(ctx, requirements, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0)};
  MSM_VK_CHECK(vkBindBufferMemory(device, buffer, result.memory_, 0));
  if (memory == Memory::host) MSM_VK_CHECK(vkMapMemory(device, result.memory_, 0, VK_WHOLE_SIZE, 0, &result.data_));
  result.size_ = size;
  result.memory_kind_ = memory;
  return result;
}

void upload_buffer(const Context& ctx, const Buffer& buffer, std::span<const std::byte> bytes, VkDeviceSize offset) {
  check_range(buffer, offset, bytes.size(), "upload_buffer");
  if (bytes.empty()) return;
  if (buffer.data()) {
    std::memcpy(static_cast<std::byte*>(buffer.data()) + offset, bytes.data(), bytes.size());
    return;
  }
  Buffer staging = create_buffer(ctx, bytes.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, Memory::host);
  std::memcpy(staging.data(), bytes.data(), bytes.size());
  submit_and_wait(ctx, [&](VkCommandBuffer cmd) {
    // Earlier commands may still read or write the range: order the copy after them.
    pipeline_barrier(cmd, buffer_barrier(buffer.handle(), VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                                         VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT,
                                         VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, offset,
                                         bytes.size()));
    VkBufferCopy region{0, offset, bytes.size()};
    vkCmdCopyBuffer(cmd, staging.handle(), buffer.handle(), 1, &region);
    pipeline_barrier(cmd,
                     buffer_barrier(buffer.handle(), VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                    VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                                    VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT, offset, bytes.size()));
  });
}

void readback_buffer(const Context& ctx, const Buffer& buffer, std::span<std::byte> bytes, VkDeviceSize offset) {
  check_range(buffer, offset, bytes.size(), "readback_buffer");
  if (bytes.empty()) return;
  if (buffer.data()) {
    std::memcpy(bytes.data(), static_cast<const std::byte*>(buffer.data()) + offset, bytes.size());
    return;
  }
  Buffer staging = create_buffer(ctx, bytes.size(), VK_BUFFER_USAGE_TRANSFER_DST_BIT, Memory::host);
  submit_and_wait(ctx, [&](VkCommandBuffer cmd) {
    pipeline_barrier(cmd,
                     buffer_barrier(buffer.handle(), VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                                    VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT, offset, bytes.size()));
    VkBufferCopy region{offset, 0, bytes.size()};
    vkCmdCopyBuffer(cmd, buffer.handle(), staging.handle(), 1, &region);
  }); // submit_and_wait ends with the barrier to host reads
  std::memcpy(bytes.data(), staging.data(), bytes.size());
}

VkImageAspectFlags format_aspect(VkFormat format) {
  switch (format) {
  case VK_FORMAT_D16_UNORM:
  case VK_FORMAT_X8_D24_UNORM_PACK32:
  case VK_FORMAT_D32_SFLOAT: return VK_IMAGE_ASPECT_DEPTH_BIT;
  case VK_FORMAT_S8_UINT: return VK_IMAGE_ASPECT_STENCIL_BIT;
  case VK_FORMAT_D16_UNORM_S8_UINT:
  case VK_FORMAT_D24_UNORM_S8_UINT:
  case VK_FORMAT_D32_SFLOAT_S8_UINT: return VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT;
  default: return VK_IMAGE_ASPECT_COLOR_BIT;
  }
}

uint32_t format_size(VkFormat format) {
  switch (format) {
  case VK_FORMAT_R8_UNORM:
  case VK_FORMAT_R8_SNORM:
  case VK_FORMAT_R8_UINT:
  case VK_FORMAT_R8_SINT:
  case VK_FORMAT_S8_UINT: return 1;
  case VK_FORMAT_R8G8_UNORM:
  case VK_FORMAT_R8G8_SNORM:
  case VK_FORMAT_R8G8_UINT:
  case VK_FORMAT_R8G8_SINT:
  case VK_FORMAT_R16_UNORM:
  case VK_FORMAT_R16_SNORM:
  case VK_FORMAT_R16_UINT:
  case VK_FORMAT_R16_SINT:
  case VK_FORMAT_R16_SFLOAT:
  case VK_FORMAT_D16_UNORM: return 2;
  case VK_FORMAT_R8G8B8A8_UNORM:
  case VK_FORMAT_R8G8B8A8_SNORM:
  case VK_FORMAT_R8G8B8A8_UINT:
  case VK_FORMAT_R8G8B8A8_SINT:
  case VK_FORMAT_R8G8B8A8_SRGB:
  case VK_FORMAT_B8G8R8A8_UNORM:
  case VK_FORMAT_B8G8R8A8_SRGB:
  case VK_FORMAT_A2B10G10R10_UNORM_PACK32:
  case VK_FORMAT_A2R10G10B10_UNORM_PACK32:
  case VK_FORMAT_A2B10G10R10_UINT_PACK32:
  case VK_FORMAT_B10G11R11_UFLOAT_PACK32:
  case VK_FORMAT_R16G16_UNORM:
  case VK_FORMAT_R16G16_SNORM:
  case VK_FORMAT_R16G16_UINT:
  case VK_FORMAT_R16G16_SINT:
  case VK_FORMAT_R16G16_SFLOAT:
  case VK_FORMAT_R32_UINT:
  case VK_FORMAT_R32_SINT:
  case VK_FORMAT_R32_SFLOAT:
  case VK_FORMAT_D32_SFLOAT:
  case VK_FORMAT_X8_D24_UNORM_PACK32: return 4;
  case VK_FORMAT_R16G16B16A16_UNORM:
  case VK_FORMAT_R16G16B16A16_SNORM:
  case VK_FORMAT_R16G16B16A16_UINT:
  case VK_FORMAT_R16G16B16A16_SINT:
  case VK_FORMAT_R16G16B16A16_SFLOAT:
  case VK_FORMAT_R32G32_UINT:
  case VK_FORMAT_R32G32_SINT:
  case VK_FORMAT_R32G32_SFLOAT: return 8;
  case VK_FORMAT_R32G32B32A32_UINT:
  case VK_FORMAT_R32G32B32A32_SINT:
  case VK_FORMAT_R32G32B32A32_SFLOAT: return 16;
  default: throw std::invalid_argument(fmt::format("msm::vk::format_size: format {} not in the table", int(format)));
  }
}

Image create_image(const Context& ctx, const ImageDesc& desc) {
  if (!desc.width || !desc.height || !desc.mip_levels || !desc.layers)
    throw std::invalid_argument("msm::vk::create_image: zero extent, mip count or layer count");
  VkDevice device = ctx.device();
  VkImageCreateInfo info{.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO,
                         .imageType = VK_IMAGE_TYPE_2D,
                         .format = desc.format,
                         .extent = {desc.width, desc.height, 1},
                         .mipLevels = desc.mip_levels,
                         .arrayLayers = desc.layers,
                         .samples = desc.samples,
                         .tiling = VK_IMAGE_TILING_OPTIMAL,
                         .usage = desc.usage,
                         .sharingMode = VK_SHARING_MODE_EXCLUSIVE,
                         .initialLayout = VK_IMAGE_LAYOUT_UNDEFINED};
  // An image beyond the device's largest resource (lavapipe: 4 GiB) is refused as out of memory
  // before vkCreateImage, which would be invalid usage (mips counted as a third more).
  uint32_t texel_bytes = 0;
  try {
    texel_bytes = format_size(desc.format);
  } catch (const std::invalid_argument&) {
    // a format outside the table: left to the driver
  }
  VkImageFormatProperties limits{};
  if (texel_bytes &&
      vkGetPhysicalDeviceImageFormatProperties(ctx.physical_device(), desc.format, VK_IMAGE_TYPE_2D,
                                               VK_IMAGE_TILING_OPTIMAL, desc.usage, 0, &limits) == VK_SUCCESS) {
    const double bytes = double(desc.width) * desc.height * desc.layers * double(desc.samples) * texel_bytes *
                         (desc.mip_levels > 1 ? 4.0 / 3.0 : 1.0);
    if (bytes > double(limits.maxResourceSize))
      throw Error(VK_ERROR_OUT_OF_DEVICE_MEMORY,
                  fmt::format("the device is out of memory: a {}x{} image of {} layers needs {:.1f} MiB, {} allows "
                              "{:.1f} MiB per image (lower the image or shadow-map size, the MSAA samples or the "
                              "lights)",
                              desc.width, desc.height, desc.layers, bytes / double(1 << 20), ctx.info().name,
                              double(limits.maxResourceSize) / double(1 << 20)));
  }
  Image result;
  VkImage image = VK_NULL_HANDLE;
  MSM_VK_CHECK(vkCreateImage(device, &info, nullptr, &image));
  result.image_ = {device, image};
  VkMemoryRequirements requirements;
  vkGetImageMemoryRequirements(device, image, &requirements);
  result.memory_ = {device, allocate(ctx, requirements, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0)};
  MSM_VK_CHECK(vkBindImageMemory(device, image, result.memory_, 0));
  result.desc_ = desc;
  result.aspect_ = format_aspect(desc.format);

  // A view needs one of these usages (VUID-VkImageViewCreateInfo-image-04441).
  constexpr VkImageUsageFlags viewable = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT |
                                         VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT |
                                         VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT |
                                         VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSIENT_ATTACHMENT_BIT;
  if (desc.usage & viewable) {
    // Sampling a depth/stencil image reads one aspect: depth, which is what shadow maps hold.
    VkImageAspectFlags view_aspect =
        (result.aspect_ & VK_IMAGE_ASPECT_DEPTH_BIT) ? VkImageAspectFlags(VK_IMAGE_ASPECT_DEPTH_BIT) : result.aspect_;
    result.view_ = create_image_view(ctx, image, desc.format, view_aspect,
                                     desc.layers > 1 ? VK_IMAGE_VIEW_TYPE_2D_ARRAY : VK_IMAGE_VIEW_TYPE_2D, 0,
                                     desc.mip_levels, 0, desc.layers);
  }
  return result;
}

ImageView create_image_view(const Context& ctx, VkImage image, VkFormat format, VkImageAspectFlags aspect,
                            VkImageViewType type, uint32_t base_mip, uint32_t mip_count, uint32_t base_layer,
                            uint32_t layer_count) {
  VkImageViewCreateInfo info{.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO,
                             .image = image,
                             .viewType = type,
                             .format = format,
                             .subresourceRange = {aspect, base_mip, mip_count, base_layer, layer_count}};
  VkImageView view = VK_NULL_HANDLE;
  MSM_VK_CHECK(vkCreateImageView(ctx.device(), &info, nullptr, &view));
  return {ctx.device(), view};
}

Sampler create_sampler(const Context& ctx, VkFilter filter, VkSamplerAddressMode address_mode,
                       std::optional<VkCompareOp> compare) {
  VkSamplerCreateInfo info{.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO,
                           .magFilter = filter,
                           .minFilter = filter,
                           .mipmapMode = filter == VK_FILTER_LINEAR ? VK_SAMPLER_MIPMAP_MODE_LINEAR
                                                                    : VK_SAMPLER_MIPMAP_MODE_NEAREST,
                           .addressModeU = address_mode,
                           .addressModeV = address_mode,
                           .addressModeW = address_mode,
                           .compareEnable = compare.has_value(),
                           .compareOp = compare.value_or(VK_COMPARE_OP_NEVER),
                           .maxLod = VK_LOD_CLAMP_NONE,
                           .borderColor = VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE}; // white: outside a shadow map is lit
  VkSampler sampler = VK_NULL_HANDLE;
  MSM_VK_CHECK(vkCreateSampler(ctx.device(), &info, nullptr, &sampler));
  return {ctx.device(), sampler};
}

namespace {

std::size_t image_bytes(const Image& image) {
  return std::size_t(image.width()) * image.height() * image.desc().layers * format_size(image.format());
}

VkBufferImageCopy mip0_copy(const Image& image) {
  VkImageAspectFlags aspect = image.aspect();
  if (aspect == (VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT))
    throw std::invalid_argument("msm::vk: copies of combined depth/stencil images are not supported");
  return {.imageSubresource = {aspect, 0, 0, image.desc().layers}, .imageExtent = {image.width(), image.height(), 1}};
}

} // namespace

void upload_image(const Context& ctx, const Image& image, std::span<const std::byte> bytes, VkImageLayout old_layout,
                  VkImageLayout new_layout) {
  VkBufferImageCopy region = mip0_copy(image);
  if (bytes.size() != image_bytes(image))
    throw std::invalid_argument(
        fmt::format("msm::vk::upload_image: {} bytes given, the image holds {}", bytes.size(), image_bytes(image)));
  Buffer staging = create_buffer(ctx, bytes.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, Memory::host);
  std::memcpy(staging.data(), bytes.data(), bytes.size());
  submit_and_wait(ctx, [&](VkCommandBuffer cmd) {
    pipeline_barrier(cmd, image_barrier(image.handle(), image.aspect(), VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                                        VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT, old_layout,
                                        VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                        VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL));
    vkCmdCopyBufferToImage(cmd, staging.handle(), image.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    pipeline_barrier(cmd, image_barrier(image.handle(), image.aspect(), VK_PIPELINE_STAGE_2_COPY_BIT,
                                        VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                        VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                                        VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT, new_layout));
  });
}

std::vector<std::byte> readback_image(const Context& ctx, const Image& image, VkImageLayout layout) {
  if (layout == VK_IMAGE_LAYOUT_UNDEFINED)
    throw std::invalid_argument("msm::vk::readback_image: an image in UNDEFINED layout has no contents to read");
  VkBufferImageCopy region = mip0_copy(image);
  std::vector<std::byte> bytes(image_bytes(image));
  Buffer staging = create_buffer(ctx, bytes.size(), VK_BUFFER_USAGE_TRANSFER_DST_BIT, Memory::host);
  submit_and_wait(ctx, [&](VkCommandBuffer cmd) {
    pipeline_barrier(cmd, image_barrier(image.handle(), image.aspect(), VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                                        VK_ACCESS_2_MEMORY_WRITE_BIT, layout, VK_PIPELINE_STAGE_2_COPY_BIT,
                                        VK_ACCESS_2_TRANSFER_READ_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, 0, 1));
    vkCmdCopyImageToBuffer(cmd, image.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, staging.handle(), 1, &region);
    pipeline_barrier(cmd, image_barrier(image.handle(), image.aspect(), VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_NONE,
                                        VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                                        VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT, layout, 0, 1));
  });
  std::memcpy(bytes.data(), staging.data(), bytes.size());
  return bytes;
}

} // namespace msm::vk

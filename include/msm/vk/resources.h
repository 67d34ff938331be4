// Buffers, images and samplers: one VkDeviceMemory per resource (no sub-allocation; the layer is for
// tests and a small renderer, not for thousands of objects), move-only RAII wrappers.
#pragma once

#include "msm/vk/common.h"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace msm::vk {

class Context;

enum class Memory {
  device, // device-local; transfer src/dst usage is added so that upload/readback work
  host,   // host-visible and coherent (cached where possible), persistently mapped
};

class Buffer {
 public:
  Buffer() = default;
  Buffer(Buffer&& other) noexcept;
  Buffer& operator=(Buffer&& other) noexcept;
  ~Buffer() = default; // members go in reverse order: the buffer, then its memory

  VkBuffer handle() const noexcept { return buffer_; }
  VkDeviceSize size() const noexcept { return size_; }
  Memory memory() const noexcept { return memory_kind_; }
  void* data() const noexcept { return data_; } // mapped pointer of a Host buffer, else null
  // The mapped memory as T[size / sizeof(T)]; empty for a Device buffer.
  template <class T>
  std::span<T> mapped() const noexcept {
    return data_ ? std::span<T>(static_cast<T*>(data_), size_ / sizeof(T)) : std::span<T>();
  }
  explicit operator bool() const noexcept { return bool(buffer_); }

 private:
  friend Buffer create_buffer(const Context&, VkDeviceSize, VkBufferUsageFlags, Memory);
  Unique<VkDeviceMemory, vkFreeMemory> memory_;
  Unique<VkBuffer, vkDestroyBuffer> buffer_;
  VkDeviceSize size_ = 0;
  void* data_ = nullptr;
  Memory memory_kind_ = Memory::device;
};

struct ImageDesc {
  uint32_t width = 0, height = 0;
  VkFormat format = VK_FORMAT_UNDEFINED;
  VkImageUsageFlags usage = 0;
  uint32_t mip_levels = 1;
  uint32_t layers = 1; // > 1: a 2D array (e.g. cascades); the view is then VK_IMAGE_VIEW_TYPE_2D_ARRAY
  VkSampleCountFlagBits samples = VK_SAMPLE_COUNT_1_BIT; // > 1 requires mip_levels == 1
};

// A device-local 2D (array) image with optimal tiling, created in VK_IMAGE_LAYOUT_UNDEFINED, and a
// view over all its mips and layers (depth aspect only for depth/stencil formats, as sampling wants).
// The view is null when the usage allows none (transfer-only images).
class Image {
 public:
  Image() = default;
  Image(Image&& other) noexcept = default;
  Image& operator=(Image&& other) noexcept;
  ~Image() = default; // view, image, memory

  VkImage handle() const noexcept { return image_; }
  VkImageView view() const noexcept { return view_; }
  const ImageDesc& desc() const noexcept { return desc_; }
  VkFormat format() const noexcept { return desc_.format; }
  uint32_t width() const noexcept { return desc_.width; }
  uint32_t height() const noexcept { return desc_.height; }
  VkImageAspectFlags aspect() const noexcept { return aspect_; } // all aspects, for barriers and copies
  explicit operator bool() const noexcept { return bool(image_); }

 private:
  friend Image create_image(const Context&, const ImageDesc&);
  Unique<VkDeviceMemory, vkFreeMemory> memory_;
  Unique<VkImage, vkDestroyImage> image_;
  ImageView view_;
  ImageDesc desc_;
  VkImageAspectFlags aspect_ = 0;
};

// First memory type in type_bits with all of `required`, preferring one that also has `preferred`.
// Throws if none has `required`.
uint32_t select_memory_type(const VkPhysicalDeviceMemoryProperties& properties, uint32_t type_bits,
                            VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred = 0);

// Precondition: size > 0.
Buffer create_buffer(const Context& ctx, VkDeviceSize size, VkBufferUsageFlags usage, Memory memory = Memory::device);

// Copies bytes into buffer[offset, offset + bytes.size()): a memcpy for a Host buffer; for a Device
// buffer a staging copy that is submitted and waited for, followed by a barrier that makes it
// visible to every later command. Precondition: the range lies inside the buffer; no pending GPU
// work uses the range.
void upload_buffer(const Context& ctx, const Buffer& buffer, std::span<const std::byte> bytes, VkDeviceSize offset = 0);

// Copies buffer[offset, offset + bytes.size()) to the host; a Device buffer goes through a staging
// copy, after a barrier that waits for every earlier write. Precondition: earlier GPU writes to a
// Host buffer have completed (submit_and_wait makes them host-visible).
void readback_buffer(const Context& ctx, const Buffer& buffer, std::span<std::byte> bytes, VkDeviceSize offset = 0);

template <class T>
std::vector<T> readback_buffer(const Context& ctx, const Buffer& buffer, std::size_t count, VkDeviceSize offset = 0) {
  std::vector<T> out(count);
  readback_buffer(ctx, buffer, std::as_writable_bytes(std::span(out)), offset);
  return out;
}

// Precondition: width, height, mip_levels, layers > 0; the format supports the usage and samples.
Image create_image(const Context& ctx, const ImageDesc& desc);

// A view of some mips/layers of an image (e.g. one mip as a storage image while building a chain).
ImageView create_image_view(const Context& ctx, VkImage image, VkFormat format, VkImageAspectFlags aspect,
                            VkImageViewType type, uint32_t base_mip, uint32_t mip_count, uint32_t base_layer = 0,
                            uint32_t layer_count = 1);

// Mipmaps use the same filter; maxLod is unclamped. With `compare` it is a depth-comparison sampler
// (hardware PCF for shadow maps).
Sampler create_sampler(const Context& ctx, VkFilter filter = VK_FILTER_LINEAR,
                       VkSamplerAddressMode address_mode = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
                       std::optional<VkCompareOp> compare = std::nullopt);

// Writes mip 0 of every layer from tightly packed texels (layer after layer) and leaves the whole
// image in new_layout; submitted and waited for. Other mips have undefined contents afterwards when
// old_layout is UNDEFINED. Precondition: bytes.size() == width * height * layers * format_size(format);
// the image has TRANSFER_DST usage, one sample, and is in old_layout.
void upload_image(const Context& ctx, const Image& image, std::span<const std::byte> bytes, VkImageLayout old_layout,
                  VkImageLayout new_layout);

// Mip 0 of every layer, tightly packed; mip 0 is back in `layout` afterwards (other mips are not
// touched). Waits for every earlier write. Precondition: TRANSFER_SRC usage, one sample, a color or
// depth-only format, mip 0 in `layout` (not UNDEFINED).
std::vector<std::byte> readback_image(const Context& ctx, const Image& image, VkImageLayout layout);

// Bytes per texel of common uncompressed formats; throws std::invalid_argument for the others.
uint32_t format_size(VkFormat format);
// DEPTH and/or STENCIL for depth/stencil formats, COLOR for the others.
VkImageAspectFlags format_aspect(VkFormat format);

} // namespace msm::vk

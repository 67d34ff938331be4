#include "frame_graph.h"

#include "frame_config.h"

#include <fmt/format.h>

#include <algorithm>
#include <queue>
#include <set>
#include <stdexcept>

namespace msm::render {
namespace {

constexpr VkAccessFlags2 kWriteAccess =
    VK_ACCESS_2_SHADER_WRITE_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT |
    VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT;

constexpr VkPipelineStageFlags2 kFragmentTests =
    VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;

VkImageUsageFlags usage_of(const ImageState& s) {
  VkImageUsageFlags u = 0;
  if (s.layout == VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL) u |= VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
  if (s.access & (VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT))
    u |= VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
  if (s.access & VK_ACCESS_2_SHADER_SAMPLED_READ_BIT) u |= VK_IMAGE_USAGE_SAMPLED_BIT;
  if (s.access & (VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT))
    u |= VK_IMAGE_USAGE_STORAGE_BIT;
  if (s.access & VK_ACCESS_2_TRANSFER_READ_BIT) u |= VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  if (s.access & VK_ACCESS_2_TRANSFER_WRITE_BIT) u |= VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  return u;
}

// The format features the usage needs (blending for colour attachments that are read: the
// translucent pass blends into the moment images).
VkFormatFeatureFlags features_of(VkImageUsageFlags u, bool blend) {
  VkFormatFeatureFlags f = 0;
  if (u & VK_IMAGE_USAGE_SAMPLED_BIT) f |= VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT;
  if (u & VK_IMAGE_USAGE_STORAGE_BIT) f |= VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT;
  if (u & VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT) f |= VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT;
  if (blend) f |= VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT;
  if (u & VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT) f |= VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT;
  if (u & VK_IMAGE_USAGE_TRANSFER_SRC_BIT) f |= VK_FORMAT_FEATURE_TRANSFER_SRC_BIT;
  if (u & VK_IMAGE_USAGE_TRANSFER_DST_BIT) f |= VK_FORMAT_FEATURE_TRANSFER_DST_BIT;
  return f;
}

// What the graph knows of an image between passes: its layout, the last write (stages, accesses),
// the stages that read it since, and the stages/accesses the last write is already visible to.
struct Track {
  VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkPipelineStageFlags2 write_stages = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT; // the previous frame, at first
  VkAccessFlags2 write_access = VK_ACCESS_2_NONE;
  VkPipelineStageFlags2 read_stages = VK_PIPELINE_STAGE_2_NONE;
  VkPipelineStageFlags2 visible_stages = VK_PIPELINE_STAGE_2_NONE;
  VkAccessFlags2 visible_access = VK_ACCESS_2_NONE;
};

// The barrier (if any) that makes `image` ready for a use in `state`, and the new track.
std::optional<VkImageMemoryBarrier2> transition(Track& t, const vk::Image& image, const ImageState& state,
                                                bool discard) {
  bool writes = state.writes();
  if (t.layout != state.layout || writes || discard) {
    // Writes wait for earlier reads and writes (and a layout transition is a write).
    VkImageMemoryBarrier2 b =
        vk::image_barrier(image.handle(), image.aspect(), t.write_stages | t.read_stages, t.write_access,
                          discard ? VK_IMAGE_LAYOUT_UNDEFINED : t.layout, state.stages, state.access, state.layout);
    t.layout = state.layout;
    // Later users order after this barrier's second scope; its writes (or the transition) are
    // visible to `state` only.
    t.write_stages = state.stages;
    t.write_access = writes ? (state.access & kWriteAccess) : VK_ACCESS_2_NONE;
    t.read_stages = writes ? VK_PIPELINE_STAGE_2_NONE : state.stages;
    t.visible_stages = writes ? VK_PIPELINE_STAGE_2_NONE : state.stages;
    t.visible_access = writes ? VK_ACCESS_2_NONE : state.access;
    return b;
  }
  t.read_stages |= state.stages;
  if ((state.stages & ~t.visible_stages) == 0 && (state.access & ~t.visible_access) == 0) return std::nullopt;
  VkImageMemoryBarrier2 b = vk::image_barrier(image.handle(), image.aspect(), t.write_stages, t.write_access, t.layout,
                                              state.stages, state.access, t.layout);
  t.visible_stages |= state.stages;
  t.visible_access |= state.access;
  return b;
}

} // namespace

bool ImageState::writes() const { return (access & kWriteAccess) != 0; }

namespace use {
ImageState depth_attachment() {
  return {VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, kFragmentTests,
          VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT};
}
ImageState color_attachment() {
  return {VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
          VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT};
}
ImageState color_attachment_general() {
  ImageState s = color_attachment();
  s.layout = VK_IMAGE_LAYOUT_GENERAL;
  return s;
}
ImageState sampled(VkPipelineStageFlags2 stages) {
  return {VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, stages, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT};
}
ImageState compute_general() {
  return {VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
          VK_ACCESS_2_SHADER_SAMPLED_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_READ_BIT |
              VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT};
}
ImageState transfer_source() {
  return {VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_READ_BIT};
}
ImageState transfer_destination() {
  return {VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT};
}
} // namespace use

void PassBuilder::create(std::string name, const ImageSpec& spec, ImageState state) {
  uses_.push_back({std::move(name), Kind::create, state, std::nullopt, spec});
}
void PassBuilder::read(std::string name, ImageState state) {
  uses_.push_back({std::move(name), Kind::read, state, std::nullopt, {}});
}
void PassBuilder::modify(std::string name, ImageState state) {
  uses_.push_back({std::move(name), Kind::modify, state, std::nullopt, {}});
}
void PassBuilder::scratch(std::string name, const ImageSpec& spec) {
  uses_.push_back({std::move(name), Kind::scratch, use::compute_general(), std::nullopt, spec});
}
void PassBuilder::internally(std::string name, ImageState state) {
  uses_.push_back({std::move(name), Kind::internal, state, std::nullopt, {}});
}
void PassBuilder::leaves(std::string name, ImageState state) {
  for (Use& u : uses_)
    if (u.name == name) u.end = state;
}

const GraphImage& PassContext::image(std::string_view name) const { return graph.image(name); }

void PassContext::begin_light(std::string_view pass, int light) const {
  if (config.lights > 1) timer.begin(cmd, fmt::format("{}#{}", pass, light));
}
void PassContext::end_light() const {
  if (config.lights > 1) timer.end(cmd);
}

struct FrameGraph::Node {
  std::unique_ptr<Pass> pass;
  PassBuilder decl;
};

std::vector<size_t> order_passes(const std::vector<std::unique_ptr<Pass>>& passes,
                                 const std::vector<std::string>& imported, const std::vector<std::string>& outputs) {
  const size_t n = passes.size();
  std::vector<PassBuilder> decls(n);
  for (size_t i = 0; i < n; ++i) passes[i]->reflect(decls[i]);
  auto is_imported = [&](const std::string& name) {
    return std::find(imported.begin(), imported.end(), name) != imported.end();
  };
  // Who creates, modifies and reads every image, in recipe order.
  std::map<std::string, size_t> creator;
  std::map<std::string, std::vector<size_t>> modifiers, readers;
  for (size_t i = 0; i < n; ++i)
    for (const PassBuilder::Use& u : decls[i].uses()) {
      if (u.kind == PassBuilder::Kind::create || u.kind == PassBuilder::Kind::scratch) {
        if (creator.count(u.name) || is_imported(u.name))
          throw RenderError(fmt::format("pass '{}' creates '{}', which {} already provides", passes[i]->name(), u.name,
                                        creator.count(u.name) ? passes[creator[u.name]]->name() : "the renderer"));
        creator[u.name] = i;
      }
      if (u.kind == PassBuilder::Kind::modify) modifiers[u.name].push_back(i);
      if (u.kind == PassBuilder::Kind::read) readers[u.name].push_back(i);
    }
  for (size_t i = 0; i < n; ++i)
    for (const PassBuilder::Use& u : decls[i].uses())
      if ((u.kind == PassBuilder::Kind::read || u.kind == PassBuilder::Kind::modify) && !creator.count(u.name) &&
          !is_imported(u.name))
        throw RenderError(fmt::format("pass '{}' {} '{}', which no pass of the frame creates", passes[i]->name(),
                                      u.kind == PassBuilder::Kind::read ? "reads" : "modifies", u.name));
  for (const std::string& o : outputs)
    if (!creator.count(o)) throw RenderError(fmt::format("frame output '{}' is created by no pass", o));

  // Dependencies: the creator first, then the modifiers in recipe order, then the readers (they see
  // the final image). Kahn's algorithm, ties in recipe order.
  std::vector<std::set<size_t>> after(n); // after[i]: passes that must follow i
  for (const auto& [name, c] : creator) {
    size_t last = c;
    for (size_t m : modifiers[name]) {
      if (m != last) after[last].insert(m);
      last = m;
    }
    for (size_t r : readers[name])
      if (r != last) after[last].insert(r);
  }
  std::vector<int> pending(n, 0);
  for (size_t i = 0; i < n; ++i)
    for (size_t j : after[i]) ++pending[j];
  std::priority_queue<size_t, std::vector<size_t>, std::greater<>> ready;
  for (size_t i = 0; i < n; ++i)
    if (pending[i] == 0) ready.push(i);
  std::vector<size_t> order;
  while (!ready.empty()) {
    size_t i = ready.top();
    ready.pop();
    order.push_back(i);
    for (size_t j : after[i])
      if (--pending[j] == 0) ready.push(j);
  }
  if (order.size() != n) throw RenderError("the frame's passes depend on each other in a cycle");
  return order;
}

FrameGraph::FrameGraph(const vk::Context& ctx, std::vector<std::unique_ptr<Pass>> passes,
                       std::vector<std::string> imported, std::vector<std::string> outputs,
                       const PassResources& resources)
    : ctx_(ctx), imported_(std::move(imported)), outputs_(std::move(outputs)) {
  for (size_t i : order_passes(passes, imported_, outputs_)) {
    Node node;
    node.pass = std::move(passes[i]);
    node.pass->reflect(node.decl);
    node.pass->prepare(resources);
    nodes_.push_back(std::move(node));
  }

  // Allocation: the usage of every image from all its uses.
  std::map<std::string, VkImageUsageFlags> usage;
  std::map<std::string, bool> blend;
  for (const Node& node : nodes_)
    for (const PassBuilder::Use& u : node.decl.uses()) {
      usage[u.name] |= usage_of(u.state) | (u.end ? usage_of(*u.end) : 0);
      if ((u.state.access & VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT) && u.kind != PassBuilder::Kind::create)
        blend[u.name] = true;
    }
  for (const std::string& o : outputs_) usage[o] |= VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  for (const Node& node : nodes_)
    for (const PassBuilder::Use& u : node.decl.uses()) {
      if (u.kind != PassBuilder::Kind::create && u.kind != PassBuilder::Kind::scratch) continue;
      const ImageSpec& s = u.spec;
      VkImageUsageFlags flags = usage[u.name] | s.extra_usage;
      VkFormatProperties props{};
      vkGetPhysicalDeviceFormatProperties(ctx.physical_device(), s.format, &props);
      VkFormatFeatureFlags need = features_of(flags, blend[u.name]);
      if ((props.optimalTilingFeatures & need) != need)
        throw RenderError(fmt::format("{} does not support format {} for '{}' (features {:#x} needed, {:#x} present)",
                                      ctx.info().name, int(s.format), u.name, need, props.optimalTilingFeatures));
      GraphImage g;
      g.spec = s;
      g.image = vk::create_image(ctx, {.width = s.width,
                                       .height = s.height,
                                       .format = s.format,
                                       .usage = flags,
                                       .mip_levels = s.mips,
                                       .layers = s.layers,
                                       .samples = s.samples});
      VkImageAspectFlags aspect = g.image.aspect() & ~VK_IMAGE_ASPECT_STENCIL_BIT;
      if (flags & (VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT |
                   VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT)) {
        g.array_view = vk::create_image_view(ctx, g.image.handle(), s.format, aspect, VK_IMAGE_VIEW_TYPE_2D_ARRAY, 0,
                                             s.mips, 0, s.layers);
        if (s.mips > 1)
          g.array_mip0_view = vk::create_image_view(ctx, g.image.handle(), s.format, aspect,
                                                    VK_IMAGE_VIEW_TYPE_2D_ARRAY, 0, 1, 0, s.layers);
        for (uint32_t l = 0; l < s.layers; ++l) {
          g.layer_views.push_back(
              vk::create_image_view(ctx, g.image.handle(), s.format, aspect, VK_IMAGE_VIEW_TYPE_2D, 0, s.mips, l, 1));
          g.layer_mip0_views.push_back(
              vk::create_image_view(ctx, g.image.handle(), s.format, aspect, VK_IMAGE_VIEW_TYPE_2D, 0, 1, l, 1));
          if (s.mips > 1)
            g.layer_mip1_views.push_back(
                vk::create_image_view(ctx, g.image.handle(), s.format, aspect, VK_IMAGE_VIEW_TYPE_2D, 1, 1, l, 1));
        }
      }
      images_.emplace(u.name, std::move(g));
    }
}

FrameGraph::~FrameGraph() = default;

void FrameGraph::record(VkCommandBuffer cmd, vk::GpuTimer& timer, const FrameResources& frame,
                        const FrameConfig& config, std::optional<std::string_view> stop_after) const {
  std::map<std::string, Track, std::less<>> tracks;
  PassContext context{ctx_, cmd, timer, *this, frame, config};
  bool stopped = false;
  for (const Node& node : nodes_) {
    std::vector<VkImageMemoryBarrier2> barriers;
    for (const PassBuilder::Use& u : node.decl.uses()) {
      if (u.kind == PassBuilder::Kind::scratch || u.kind == PassBuilder::Kind::internal || !images_.count(u.name))
        continue; // the pass's own barriers; imported: the renderer's
      if (auto b = transition(tracks[u.name], images_.find(u.name)->second.image, u.state,
                              u.kind == PassBuilder::Kind::create))
        barriers.push_back(*b);
    }
    if (!barriers.empty()) vk::pipeline_barrier(cmd, {}, {}, barriers);
    timer.begin(cmd, node.pass->name());
    node.pass->execute(context);
    timer.end(cmd);
    for (const PassBuilder::Use& u : node.decl.uses())
      if (u.end && images_.count(u.name)) {
        Track& t = tracks[u.name];
        t.layout = u.end->layout;
        t.write_stages = u.end->stages;
        t.write_access = u.end->access & kWriteAccess;
        t.read_stages = t.visible_stages = VK_PIPELINE_STAGE_2_NONE;
        t.visible_access = VK_ACCESS_2_NONE;
      }
    if (stop_after && node.pass->name() == *stop_after) {
      stopped = true;
      break;
    }
  }
  if (!stopped) {
    std::vector<VkImageMemoryBarrier2> barriers;
    for (const std::string& o : outputs_)
      if (auto b = transition(tracks[o], images_.find(o)->second.image, use::transfer_source(), false))
        barriers.push_back(*b);
    if (!barriers.empty()) vk::pipeline_barrier(cmd, {}, {}, barriers);
  }
  final_layouts_.clear();
  for (const auto& [name, t] : tracks) final_layouts_[name] = t.layout;
}

std::vector<std::string_view> FrameGraph::pass_names() const {
  std::vector<std::string_view> out;
  for (const Node& n : nodes_) out.push_back(n.pass->name());
  return out;
}

bool FrameGraph::has_image(std::string_view name) const { return images_.find(name) != images_.end(); }

const GraphImage& FrameGraph::image(std::string_view name) const {
  auto it = images_.find(name);
  if (it == images_.end()) throw std::out_of_range(fmt::format("the frame has no image '{}'", name));
  return it->second;
}

VkImageLayout FrameGraph::layout_after_record(std::string_view name) const {
  auto it = final_layouts_.find(name);
  return it == final_layouts_.end() ? VK_IMAGE_LAYOUT_UNDEFINED : it->second;
}

} // namespace msm::render

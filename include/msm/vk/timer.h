// GPU timestamps with named scopes:
//
//   timer.reset(cmd);                        // once per recording, outside a render pass
//   timer.begin(cmd, "shadow_depth"); ... timer.end(cmd);
//   timer.begin(cmd, "filter"); ... timer.end(cmd);
//   (submit, wait)
//   TimerResults r = timer.read();           // r.total("shadow_depth") in milliseconds
//
// Scopes may nest and may repeat a name; results keep every scope in begin() order, and sum per name.
// One GpuTimer per command buffer in flight (e.g. one per frame in flight).
#pragma once

#include "msm/vk/common.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace msm::vk {

class Context;

struct TimerScope {
  std::string name;
  uint32_t depth = 0;  // nesting level: 0 for outermost scopes
  double start_ms = 0; // from the first timestamp of the recording
  double end_ms = 0;
  double ms() const { return end_ms - start_ms; }
};

struct TimerResults {
  std::vector<TimerScope> scopes;                             // in begin() order
  double total(std::string_view name) const;                  // sum over the scopes with this name; 0 if none
  std::size_t count(std::string_view name) const;             // how many scopes had this name
  std::vector<std::pair<std::string, double>> totals() const; // per name, in order of first begin()
};

class GpuTimer {
 public:
  // Room for reserve_scopes scopes per recording; more grow the query storage (new pools).
  explicit GpuTimer(const Context& ctx, uint32_t reserve_scopes = 32);
  GpuTimer(GpuTimer&&) noexcept = default;
  GpuTimer& operator=(GpuTimer&&) noexcept = default;

  // False when the queue family has no timestamps (timestamp_valid_bits == 0): then begin/end record
  // nothing and read() returns no scopes.
  bool supported() const noexcept { return supported_; }

  // Starts a recording: forgets the previous scopes and resets the queries in cmd.
  // Precondition: cmd is outside a render pass; no earlier submission using this timer is pending.
  void reset(VkCommandBuffer cmd);
  // Precondition: reset(cmd) was called since the last read(). A begin() beyond the reserved scopes
  // creates a query pool; without hostQueryReset it is reset in cmd, so that begin() must then be
  // outside a render pass too.
  void begin(VkCommandBuffer cmd, std::string_view name,
             VkPipelineStageFlags2 stage = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT);
  // Ends the innermost open scope (std::logic_error if none is open).
  void end(VkCommandBuffer cmd, VkPipelineStageFlags2 stage = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT);
  // Precondition: every scope ended (std::logic_error otherwise) and the command buffer completed
  // (std::runtime_error if its timestamps are not available: it was not submitted or waited for).
  TimerResults read();

 private:
  struct Record {
    std::string name;
    uint32_t depth, begin_query, end_query;
  };
  uint32_t next_query(VkCommandBuffer cmd);
  void add_pool(VkCommandBuffer cmd);

  VkDevice device_ = VK_NULL_HANDLE;
  bool supported_ = false;
  bool host_query_reset_ = false;
  double ms_per_tick_ = 0;
  uint64_t mask_ = 0; // timestamp_valid_bits low bits
  uint32_t pool_size_ = 0;
  std::vector<Unique<VkQueryPool, vkDestroyQueryPool>> pools_;
  uint32_t used_ = 0;
  bool recording_ = false;
  std::vector<Record> records_;
  std::vector<std::size_t> open_; // indices into records_
};

} // namespace msm::vk

#include "msm/vk/timer.h"

#include "msm/vk/context.h"

#include <fmt/format.h>

#include <algorithm>

namespace msm::vk {

double TimerResults::total(std::string_view name) const {
  double sum = 0;
  for (const TimerScope& s : scopes)
    if (s.name == name) sum += s.ms();
  return sum;
}

std::size_t TimerResults::count(std::string_view name) const {
  std::size_t n = 0;
  for (const TimerScope& s : scopes) n += s.name == name;
  return n;
}

std::vector<std::pair<std::string, double>> TimerResults::totals() const {
  std::vector<std::pair<std::string, double>> out;
  for (const TimerScope& s : scopes) {
    auto it = std::find_if(out.begin(), out.end(), [&](const auto& t) { return t.first == s.name; });
    if (it == out.end())
      out.emplace_back(s.name, s.ms());
    else
      it->second += s.ms();
  }
  return out;
}

GpuTimer::GpuTimer(const Context& ctx, uint32_t reserve_scopes)
    : device_(ctx.device()), supported_(ctx.timestamp_valid_bits() > 0),
      host_query_reset_(ctx.features().v12.hostQueryReset),
      ms_per_tick_(double(ctx.properties().limits.timestampPeriod) * 1e-6),
      mask_(ctx.timestamp_valid_bits() >= 64 ? ~0ull : (1ull << ctx.timestamp_valid_bits()) - 1),
      pool_size_(2 * std::max(reserve_scopes, 1u)) {
  if (supported_) add_pool(VK_NULL_HANDLE); // reset by reset(cmd) before first use
}

void GpuTimer::add_pool(VkCommandBuffer cmd) {
  VkQueryPoolCreateInfo info{.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO,
                             .queryType = VK_QUERY_TYPE_TIMESTAMP,
                             .queryCount = pool_size_};
  VkQueryPool pool = VK_NULL_HANDLE;
  MSM_VK_CHECK(vkCreateQueryPool(device_, &info, nullptr, &pool));
  pools_.emplace_back(device_, pool);
  // A pool added while recording must be reset before its first query; a fresh pool is not in use
  // on the device, so a host reset (no render-pass restriction) is safe.
  if (cmd == VK_NULL_HANDLE) return;
  if (host_query_reset_)
    vkResetQueryPool(device_, pool, 0, pool_size_);
  else
    vkCmdResetQueryPool(cmd, pool, 0, pool_size_);
}

void GpuTimer::reset(VkCommandBuffer cmd) {
  records_.clear();
  open_.clear();
  used_ = 0;
  recording_ = true;
  for (const auto& pool : pools_) vkCmdResetQueryPool(cmd, pool, 0, pool_size_);
}

uint32_t GpuTimer::next_query(VkCommandBuffer cmd) {
  if (used_ == pools_.size() * pool_size_) add_pool(cmd);
  return used_++;
}

void GpuTimer::begin(VkCommandBuffer cmd, std::string_view name, VkPipelineStageFlags2 stage) {
  if (!recording_) throw std::logic_error("msm::vk::GpuTimer::begin: call reset(cmd) first");
  Record record{std::string(name), uint32_t(open_.size()), 0, 0};
  if (supported_) {
    record.begin_query = next_query(cmd);
    vkCmdWriteTimestamp2(cmd, stage, pools_[record.begin_query / pool_size_], record.begin_query % pool_size_);
  }
  open_.push_back(records_.size());
  records_.push_back(std::move(record));
}

void GpuTimer::end(VkCommandBuffer cmd, VkPipelineStageFlags2 stage) {
  if (open_.empty()) throw std::logic_error("msm::vk::GpuTimer::end: no scope is open");
  Record& record = records_[open_.back()];
  open_.pop_back();
  if (supported_) {
    record.end_query = next_query(cmd);
    vkCmdWriteTimestamp2(cmd, stage, pools_[record.end_query / pool_size_], record.end_query % pool_size_);
  }
}

TimerResults GpuTimer::read() {
  if (!open_.empty())
    throw std::logic_error(
        fmt::format("msm::vk::GpuTimer::read: scope '{}' was not ended", records_[open_.back()].name));
  recording_ = false; // the queries must be reset before they are written again
  TimerResults results;
  if (!supported_ || records_.empty()) return results;

  std::vector<uint64_t> ticks(used_);
  for (uint32_t first = 0; first < used_; first += pool_size_) {
    uint32_t n = std::min(pool_size_, used_ - first);
    // No WAIT_BIT: a command buffer that was never submitted would block forever.
    VkResult r = vkGetQueryPoolResults(device_, pools_[first / pool_size_], 0, n, n * sizeof(uint64_t), &ticks[first],
                                       sizeof(uint64_t), VK_QUERY_RESULT_64_BIT);
    if (r == VK_NOT_READY)
      throw std::runtime_error("msm::vk::GpuTimer::read: timestamps not available; submit the command buffer and "
                               "wait for it first");
    MSM_VK_CHECK(r);
  }
  // Differences modulo 2^timestamp_valid_bits: the counter may wrap between two timestamps.
  uint64_t origin = ticks[records_.front().begin_query];
  auto ms = [&](uint32_t query) { return double((ticks[query] - origin) & mask_) * ms_per_tick_; };
  for (const Record& record : records_)
    results.scopes.push_back({record.name, record.depth, ms(record.begin_query), ms(record.end_query)});
  return results;
}

} // namespace msm::vk

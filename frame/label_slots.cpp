#include "frame/label_slots.h"

#include <algorithm>

namespace strata {

void LabelSlots::reset(std::span<const int> ids, uint32_t spare, uint32_t limit) {
  const auto n = static_cast<uint32_t>(ids.size());
  count_ = std::min(n + spare, std::max(limit, n));
  next_ = n;
  slot_of_.clear();
  by_id_.clear();
  for (uint32_t i = 0; i < n; ++i) {
    slot_of_.push_back(i);
    by_id_.emplace(ids[i], i);  // (a repeated id keeps its first slot: assign() then refuses)
  }
}

bool LabelSlots::assign(std::span<const int> ids) {
  std::unordered_map<int, uint32_t> by_id = by_id_;
  std::vector<uint32_t> slot_of;
  std::vector<bool> taken(count_, false);
  uint32_t next = next_;
  for (const int id : ids) {
    auto it = by_id.find(id);
    if (it == by_id.end()) {
      if (next >= count_) return false;
      it = by_id.emplace(id, next++).first;
    }
    if (taken[it->second]) return false;  // (two labels with one id)
    taken[it->second] = true;
    slot_of.push_back(it->second);
  }
  by_id_ = std::move(by_id);
  slot_of_ = std::move(slot_of);
  next_ = next;
  return true;
}

std::vector<uint32_t> LabelSlots::to_slots(std::span<const uint32_t> indices) const {
  std::vector<uint32_t> out;
  out.reserve(indices.size());
  for (const uint32_t i : indices) out.push_back(slot_of_.at(i));
  return out;
}

}  // namespace strata

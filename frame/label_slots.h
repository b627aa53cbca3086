// Where each label lives in the GPU's per-label buffers (labels, placements, the forces' state,
// the placement beside the frames). A label keeps its slot, by id, for as long as the buffers
// live, and a renderer may keep spare slots: an edit of the labels that fits them (the viewer's
// own labels: placed, renamed, moved, deleted, undone) changes no buffer size and no graph, and
// every other label keeps its state (where it is drawn, its fade) across the edit.
#pragma once

#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

namespace strata {

class LabelSlots {
 public:
  // Slots 0..n-1 for the labels with `ids`, in order, and `spare` more (at most `limit` in all).
  void reset(std::span<const int> ids, uint32_t spare, uint32_t limit);
  // The slots for the labels with `ids` now: a known id keeps its slot (a label deleted and
  // brought back by an undo gets its own again), a new one takes the next never used. False,
  // and nothing changed, when they do not fit or two labels share an id: reset() then.
  bool assign(std::span<const int> ids);

  uint32_t count() const { return count_; }  // slots in all: the per-label buffers' length
  uint32_t used() const { return next_; }    // slots ever given out: those past it are empty
  uint32_t of(size_t index) const { return slot_of_.at(index); }
  std::span<const uint32_t> slots() const { return slot_of_; }

  // Per slot: `per_label[i]` in label i's slot, `empty` in the others.
  template <typename T>
  std::vector<T> scatter(std::span<const T> per_label, const T& empty) const {
    std::vector<T> out(count_, empty);
    for (size_t i = 0; i < per_label.size() && i < slot_of_.size(); ++i)
      out[slot_of_[i]] = per_label[i];
    return out;
  }
  // Per label: what its slot holds in `per_slot`.
  template <typename T>
  std::vector<T> gather(std::span<const T> per_slot) const {
    std::vector<T> out;
    out.reserve(slot_of_.size());
    for (const uint32_t s : slot_of_) out.push_back(s < per_slot.size() ? per_slot[s] : T{});
    return out;
  }
  // Label indices as slots.
  std::vector<uint32_t> to_slots(std::span<const uint32_t> indices) const;

 private:
  uint32_t count_ = 0;
  uint32_t next_ = 0;  // the first slot never used
  std::vector<uint32_t> slot_of_;
  std::unordered_map<int, uint32_t> by_id_;
};

}  // namespace strata

// Undo and redo of the viewer's label edits: the scene's labels before each edit.
#pragma once

#include <utility>
#include <vector>

#include "engine/scene/scene.h"

namespace strata::app {

class LabelHistory {
 public:
  // An edit made: `before` is what undo brings back; what was undone cannot be redone now.
  void edited(std::vector<Label> before) {
    undo_.push_back(std::move(before));
    redo_.clear();
  }
  // The labels before the last edit (redo: after the last undone one) replace `labels`, which
  // go onto the other stack; false when there is nothing to.
  bool undo(std::vector<Label>& labels) { return restore(undo_, redo_, labels); }
  bool redo(std::vector<Label>& labels) { return restore(redo_, undo_, labels); }
  bool can_undo() const { return !undo_.empty(); }
  bool can_redo() const { return !redo_.empty(); }

 private:
  static bool restore(std::vector<std::vector<Label>>& from, std::vector<std::vector<Label>>& to,
                      std::vector<Label>& labels) {
    if (from.empty()) return false;
    to.push_back(std::move(labels));
    labels = std::move(from.back());
    from.pop_back();
    return true;
  }
  std::vector<std::vector<Label>> undo_, redo_;
};

}  // namespace strata::app

#include "app/viewer/idle_optimisation.h"

#include <algorithm>
#include <cmath>

#include "labeling/insertion_order.h"

namespace strata::app {

int IdleOptimisation::next(uint32_t labels, uint32_t tries, uint64_t serial) {
  if (orders_.empty()) {
    for (uint32_t t = 0; t < tries; ++t)
      orders_.push_back(random_order(labels, serial * 131 + t + 1));
    costs_.assign(orders_.size(), std::nan(""));
  }
  if (submitted_ >= orders_.size()) return -1;
  return int(submitted_++);
}

std::optional<IdleOptimisation::Better> IdleOptimisation::back(int trial, double cost) {
  if (trial < 0 || size_t(trial) >= costs_.size()) return {};  // (one of an earlier serial)
  costs_[size_t(trial)] = cost;
  const bool all =
      std::none_of(costs_.begin(), costs_.end(), [](double c) { return std::isnan(c); });
  if (!all || done_) return {};
  const size_t best = size_t(std::min_element(costs_.begin(), costs_.end()) - costs_.begin());
  done_ = true;
  if (!(costs_[best] < baseline_ * (1.0 - 1e-4))) return {};
  return Better{&orders_[best], baseline_, costs_[best]};
}

size_t IdleOptimisation::trials_back() const {
  return size_t(
      std::count_if(costs_.begin(), costs_.end(), [](double c) { return !std::isnan(c); }));
}

}  // namespace strata::app

// The optimisation on idle (the thesis program's option): once the view has rested after a
// change, random insertion orders are tried and the cheapest is kept where it beats the order
// kept now. The viewer runs the trials (trial frames, or beside the frames one trial placement at
// a time) and hands their costs back; this keeps the orders, their costs and what is due.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

namespace strata::app {

class IdleOptimisation {
 public:
  // A change: whatever was tried is forgotten (trials of before are ignored when they come back).
  void restart() { *this = IdleOptimisation(); }
  // Every trial came back (and the cheapest order was kept or not).
  bool done() const { return done_; }
  // The kept order's cost, a settled normal frame's; nothing is due before it.
  bool has_baseline() const { return baseline_ >= 0.0; }
  void settled(double cost) {
    if (orders_.empty()) baseline_ = cost;
  }
  // The next trial: `tries` random orders of `labels` labels made on the first (seeded by the
  // change serial); -1 once each was handed out.
  int next(uint32_t labels, uint32_t tries, uint64_t serial);
  const std::vector<uint32_t>& order(int trial) const { return orders_[size_t(trial)]; }
  struct Better {
    const std::vector<uint32_t>* order;
    double from, to;  // the costs
  };
  // Trial `trial`'s cost came back; after the last one, the cheapest order if it beats the
  // baseline.
  std::optional<Better> back(int trial, double cost);
  size_t trials_back() const;
  // Beside the frames: the trial whose placement runs (-1: none).
  int in_flight = -1;

 private:
  std::vector<std::vector<uint32_t>> orders_;
  std::vector<double> costs_;  // NaN until read back
  uint32_t submitted_ = 0;
  double baseline_ = -1.0;
  bool done_ = false;
};

}  // namespace strata::app

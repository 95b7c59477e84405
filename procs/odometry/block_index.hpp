// An open-addressing hash from a block's integer key to its slot in a contiguous block array:
// the lookup the local map does ~20 times per nearest-neighbour query, so it must cost a few
// nanoseconds (std::unordered_map costs a modulo and a pointer chase per lookup).
// Linear probing, power-of-two capacity, load <= 1/2, deletion by backward shift (no tombstones).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace dlslot::odometry {

class BlockIndex {
 public:
  static constexpr int kMissing = -1;

  int find(int64_t key) const {
    if (keys_.empty()) return kMissing;
    for (size_t i = home(key);; i = (i + 1) & mask_) {
      if (keys_[i] == key) return values_[i];
      if (keys_[i] == kEmpty) return kMissing;
    }
  }
  // Sets key's value (inserting the key when new).
  void set(int64_t key, int value) {
    if (2 * (size_ + 1) > keys_.size()) grow();
    size_t i = home(key);
    while (keys_[i] != kEmpty && keys_[i] != key) i = (i + 1) & mask_;
    if (keys_[i] == kEmpty) ++size_;
    keys_[i] = key;
    values_[i] = value;
  }
  void erase(int64_t key) {
    if (keys_.empty()) return;
    size_t i = home(key);
    while (keys_[i] != key) {
      if (keys_[i] == kEmpty) return;
      i = (i + 1) & mask_;
    }
    // Backward shift: move later entries of the probe run into the hole when their home allows.
    for (size_t j = (i + 1) & mask_; keys_[j] != kEmpty; j = (j + 1) & mask_) {
      const size_t h = home(keys_[j]);
      // j's entry may move to i when its home is not cyclically in (i, j].
      if (((j - h) & mask_) >= ((j - i) & mask_)) {
        keys_[i] = keys_[j];
        values_[i] = values_[j];
        i = j;
      }
    }
    keys_[i] = kEmpty;
    --size_;
  }
  void clear() {
    keys_.clear();
    values_.clear();
    size_ = 0;
    mask_ = 0;
  }
  size_t size() const { return size_; }

 private:
  static constexpr int64_t kEmpty = INT64_MIN;
  size_t home(int64_t key) const {
    // Fibonacci hashing: the top bits of key times 2^64 / golden ratio. One multiply (the
    // splitmix64 finalizer it replaces took three and cost 1 % of the odometry); neighbouring
    // blocks still land far apart.
    return static_cast<size_t>((static_cast<uint64_t>(key) * 0x9e3779b97f4a7c15ULL) >> shift_);
  }
  void grow() {
    std::vector<int64_t> old_keys = std::move(keys_);
    std::vector<int> old_values = std::move(values_);
    const size_t cap = old_keys.empty() ? 1024 : 2 * old_keys.size();
    keys_.assign(cap, kEmpty);
    values_.assign(cap, kMissing);
    mask_ = cap - 1;
    shift_ = 64;
    for (size_t c = cap; c > 1; c >>= 1) --shift_;
    size_ = 0;
    for (size_t i = 0; i < old_keys.size(); ++i)
      if (old_keys[i] != kEmpty) set(old_keys[i], old_values[i]);
  }

  std::vector<int64_t> keys_;
  std::vector<int> values_;
  size_t size_ = 0, mask_ = 0;
  int shift_ = 63;  // 64 - log2(capacity)
};

}  // namespace dlslot::odometry

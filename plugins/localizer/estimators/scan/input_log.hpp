#pragma once
// Seed 003 Sec. 3.6 runs the algorithm again over the saved measurements, backwards: the inputs
// an estimator was pushed, kept in a log that a copy shares. The localizer copies an estimator at
// every checkpoint of its out-of-sequence fusion (a few odometry samples apart), and a copy must
// not copy minutes of inputs: sealed chunks are immutable and shared between copies, each
// pointing to the older one, and only the open chunk (at most kChunkItems) is copied.
#include <cstddef>
#include <memory>
#include <utility>
#include <vector>

namespace beaconloc::scan {

template <class T>
class InputLog {
 public:
  // 128 items: a copy copies at most 128 of them.
  static constexpr std::size_t kChunkItems = 128;

  InputLog() = default;
  InputLog(const InputLog&) = default;
  InputLog& operator=(const InputLog& other) {
    if (this != &other) {
      clear();
      sealed_ = other.sealed_;
      open_ = other.open_;
      size_ = other.size_;
    }
    return *this;
  }
  InputLog(InputLog&&) = default;
  InputLog& operator=(InputLog&&) = delete;
  ~InputLog() { clear(); }

  void push_back(T item) {
    open_.push_back(std::move(item));
    ++size_;
    if (open_.size() == kChunkItems) {
      sealed_ = std::make_shared<const Chunk>(Chunk{std::move(sealed_), std::move(open_)});
      open_.clear();
      open_.reserve(kChunkItems);
    }
  }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  // The chunks no copy shares are freed one by one, not by a recursion as deep as the chain.
  void clear() {
    while (sealed_ && sealed_.use_count() == 1) {
      std::shared_ptr<const Chunk> older = sealed_->older;
      sealed_ = std::move(older);  // frees the newest chunk; its link to the older one is not the last
    }
    sealed_.reset();
    open_.clear();
    size_ = 0;
  }
  // f(item) from the newest item to the oldest.
  template <class F>
  void newest_first(F&& f) const {
    for (auto it = open_.rbegin(); it != open_.rend(); ++it) f(*it);
    for (const Chunk* c = sealed_.get(); c != nullptr; c = c->older.get()) {
      for (auto it = c->items.rbegin(); it != c->items.rend(); ++it) f(*it);
    }
  }

 private:
  struct Chunk {
    std::shared_ptr<const Chunk> older;
    std::vector<T> items;
  };
  std::shared_ptr<const Chunk> sealed_;  // the newest sealed chunk
  std::vector<T> open_;
  std::size_t size_ = 0;
};

}  // namespace beaconloc::scan

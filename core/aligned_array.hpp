// Cache-line aligned, staggered storage for the hot structure-of-arrays columns.
//
// Why staggered: equal-sized arrays allocated back to back start at the same offset modulo
// 4 KiB. A loop that streams px[i], py[i], pz[i], vx[i]... then hits 4K aliasing (loads
// falsely depend on earlier stores to a different array at the same low 12 address bits);
// measured on this project's machine it made a node update 6x slower. Each column of a
// group therefore gets a distinct "slot" and starts slot * 320 bytes past a page boundary.
#pragma once
#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <new>
#include <span>
#include <type_traits>
#include <utility>

namespace papertear {

template <class T>
class AlignedArray {
  static_assert(std::is_trivially_copyable_v<T>, "SoA columns hold plain values");

 public:
  static constexpr std::size_t kPage = 4096;
  static constexpr std::size_t kStaggerBytes = 320;  // 5 cache lines: spreads 12 columns over a page

  AlignedArray() = default;
  explicit AlignedArray(unsigned slot) : slot_(slot) {}
  AlignedArray(const AlignedArray& o) : slot_(o.slot_) { assign_from(o); }
  AlignedArray& operator=(const AlignedArray& o) {
    if (this != &o) { slot_ = o.slot_; assign_from(o); }
    return *this;
  }
  AlignedArray(AlignedArray&& o) noexcept { swap(o); }
  AlignedArray& operator=(AlignedArray&& o) noexcept { swap(o); return *this; }
  ~AlignedArray() { std::free(raw_); }

  void set_slot(unsigned slot) { slot_ = slot; }
  // Grows capacity to at least n elements, keeping the first size() values.
  void reserve(std::size_t n) {
    if (n <= capacity_) return;
    std::size_t cap = std::max<std::size_t>(n, capacity_ + capacity_ / 2);
    std::size_t offset = (slot_ * kStaggerBytes) % kPage;
    std::size_t bytes = ((offset + cap * sizeof(T) + 64 + kPage - 1) / kPage) * kPage;
    void* raw = std::aligned_alloc(kPage, bytes);
    if (!raw) throw std::bad_alloc();
    T* data = reinterpret_cast<T*>(static_cast<char*>(raw) + offset);
    if (size_) std::memcpy(static_cast<void*>(data), data_, size_ * sizeof(T));
    std::free(raw_);
    raw_ = raw;
    data_ = data;
    capacity_ = cap;
  }
  void resize(std::size_t n, T fill = T{}) {
    reserve(n);
    for (std::size_t i = size_; i < n; ++i) data_[i] = fill;
    size_ = n;
  }
  void push_back(T v) {
    if (size_ == capacity_) reserve(size_ + 1);
    data_[size_++] = v;
  }
  void clear() { size_ = 0; }

  T* data() { return data_; }
  const T* data() const { return data_; }
  std::size_t size() const { return size_; }
  std::size_t capacity() const { return capacity_; }
  T& operator[](std::size_t i) { return data_[i]; }
  const T& operator[](std::size_t i) const { return data_[i]; }
  std::span<T> span() { return {data_, size_}; }
  std::span<const T> span() const { return {data_, size_}; }
  T* begin() { return data_; }
  T* end() { return data_ + size_; }
  const T* begin() const { return data_; }
  const T* end() const { return data_ + size_; }

 private:
  void assign_from(const AlignedArray& o) {
    size_ = 0;
    reserve(o.size_);
    if (o.size_) std::memcpy(static_cast<void*>(data_), o.data_, o.size_ * sizeof(T));
    size_ = o.size_;
  }
  void swap(AlignedArray& o) noexcept {
    std::swap(raw_, o.raw_);
    std::swap(data_, o.data_);
    std::swap(size_, o.size_);
    std::swap(capacity_, o.capacity_);
    std::swap(slot_, o.slot_);
  }

  void* raw_ = nullptr;
  T* data_ = nullptr;
  std::size_t size_ = 0;
  std::size_t capacity_ = 0;
  unsigned slot_ = 0;
};

}  // namespace papertear

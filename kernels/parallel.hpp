// The only place that talks to TBB. Work is cut into fixed-size chunks [c*chunk, (c+1)*chunk)
// whose boundaries depend on the problem size alone, never on the number of threads, and
// chunks are handed out with tbb::simple_partitioner (grain 1 chunk), so which thread runs a
// chunk may vary but what each chunk computes does not. Kernels write disjoint outputs per
// element; nothing is accumulated across chunks except through per-chunk slots that a serial
// pass then combines in chunk order. Hence the bits never depend on the thread count.
#pragma once
#include <cstddef>
#include <vector>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>

#ifdef PAPERTEAR_STD_THREAD_BACKEND
#include <algorithm>
#include <atomic>
#include <thread>

#include <oneapi/tbb/task_arena.h>
#endif

namespace papertear {

inline std::size_t chunk_count(std::size_t n, std::size_t chunk) { return (n + chunk - 1) / chunk; }

// Calls body(begin, end, chunk_index) for every chunk of [0, n); chunks may run in parallel.
template <class Body>
void parallel_chunks(std::size_t n, std::size_t chunk, const Body& body) {
  const std::size_t chunks = chunk_count(n, chunk);
  if (chunks == 0) return;
  if (chunks == 1) {
    body(std::size_t(0), n, std::size_t(0));
    return;
  }
#ifdef PAPERTEAR_STD_THREAD_BACKEND
  // ThreadSanitizer builds only (CMakePresets.json, preset tsan): Debian's libtbb is not
  // instrumented, so TSan cannot see the hand-offs inside its scheduler and reports races on
  // every parallel_for. Here plain std::threads, as many as the current arena allows, take
  // the same chunks from an atomic counter; TSan sees their start and join.
  const std::size_t workers =
      std::min<std::size_t>(chunks, std::size_t(tbb::this_task_arena::max_concurrency()));
  std::atomic<std::size_t> next{0};
  auto drain = [&] {
    for (std::size_t c = next.fetch_add(1); c < chunks; c = next.fetch_add(1)) {
      const std::size_t b = c * chunk;
      body(b, b + chunk < n ? b + chunk : n, c);
    }
  };
  std::vector<std::thread> helpers;
  for (std::size_t t = 1; t < workers; ++t) helpers.emplace_back(drain);
  drain();
  for (std::thread& t : helpers) t.join();
#else
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, chunks, 1),
      [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t c = r.begin(); c != r.end(); ++c) {
          const std::size_t b = c * chunk;
          const std::size_t e = b + chunk < n ? b + chunk : n;
          body(b, e, c);
        }
      },
      tbb::simple_partitioner());
#endif
}

// A sum whose bits do not depend on the thread count: partial sums per fixed chunk, then a
// serial sum in chunk order.
template <class T, class Body>
T deterministic_sum(std::size_t n, std::size_t chunk, const Body& partial) {
  std::vector<T> parts(chunk_count(n, chunk), T{});
  parallel_chunks(n, chunk, [&](std::size_t b, std::size_t e, std::size_t c) { parts[c] = partial(b, e); });
  T total{};
  for (const T& p : parts) total += p;
  return total;
}

// Where each fixed chunk's items go in one list: count(begin, end) says how many items chunk
// [begin, end) of [0, n) produces (chunks counted in parallel); result[c] is the number before
// chunk c, result.back() the total. A second pass over the same chunks writes each chunk's
// items from result[c] on, so the list has the same order on any number of threads.
template <class Count>
std::vector<std::size_t> chunk_offsets(std::size_t n, std::size_t chunk, const Count& count) {
  std::vector<std::size_t> first(chunk_count(n, chunk) + 1, 0);
  parallel_chunks(n, chunk, [&](std::size_t b, std::size_t e, std::size_t c) { first[c + 1] = count(b, e); });
  for (std::size_t c = 1; c < first.size(); ++c) first[c] += first[c - 1];
  return first;
}

}  // namespace papertear

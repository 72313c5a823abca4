// The only place that talks to TBB. Work is cut into fixed-size chunks [c*chunk, (c+1)*chunk)
// whose boundaries depend on the problem size alone, never on the number of threads, and
// chunks are handed out with tbb::simple_partitioner (grain 1 chunk), so which thread runs a
// chunk may vary but what each chunk computes does not. Kernels write disjoint outputs per
// element; nothing is accumulated across chunks except through per-chunk slots that a serial
// pass then combines in chunk order. Hence the bits never depend on the thread count. A
// graph of tasks (run_task_graph) lets a task start when its own predecessors are done
// rather than at a barrier; what each task computes is fixed in the same way.
#pragma once
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>
#include <oneapi/tbb/task_arena.h>
#include <oneapi/tbb/task_group.h>

#ifdef PAPERTEAR_STD_THREAD_BACKEND
#include <algorithm>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <thread>
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

// Runs a graph of tasks 0..n-1, each once: first the tasks listed in `roots` (those whose
// count in `waits` is 0), in that order, then every other task u as soon as its predecessors
// have between them called release(u) waits[u] times. body(t, release) runs task t and, as
// it ends, calls release(u) for each of t's successors. The thread whose release brings a
// count to 0 queues that task on its own deque, so it runs it next unless an idle thread
// takes it first. Returns when all n tasks have run; the counts are then all 0. The results
// do not depend on the thread count as long as no two tasks that may run at the same time
// (neither a predecessor of the other) write what the other reads or writes.
template <class Body>
void run_task_graph(std::size_t n, const std::vector<std::size_t>& roots, std::atomic<std::uint32_t>* waits,
                    const Body& body) {
  if (n == 0) return;
  if (tbb::this_task_arena::max_concurrency() == 1) {
    // One thread: no tasks to spawn; a ready task runs next, as a thread's own tasks do below.
    std::vector<std::size_t> ready(roots.rbegin(), roots.rend());
    auto release = [&](std::size_t u) {
      if (waits[u].fetch_sub(1, std::memory_order_relaxed) == 1) ready.push_back(u);
    };
    while (!ready.empty()) {
      const std::size_t t = ready.back();
      ready.pop_back();
      body(t, release);
    }
    return;
  }
#ifdef PAPERTEAR_STD_THREAD_BACKEND
  // See parallel_chunks: std::threads that TSan can follow, taking ready tasks from a queue.
  std::mutex m;
  std::condition_variable cv;
  std::deque<std::size_t> ready(roots.begin(), roots.end());
  std::size_t done = 0;
  auto release = [&](std::size_t u) {
    if (waits[u].fetch_sub(1, std::memory_order_acq_rel) != 1) return;
    std::lock_guard<std::mutex> lock(m);
    ready.push_back(u);
    cv.notify_one();
  };
  auto drain = [&] {
    std::unique_lock<std::mutex> lock(m);
    for (;;) {
      cv.wait(lock, [&] { return !ready.empty() || done == n; });
      if (ready.empty()) return;
      const std::size_t t = ready.front();
      ready.pop_front();
      lock.unlock();
      body(t, release);
      lock.lock();
      if (++done == n) cv.notify_all();
    }
  };
  const std::size_t workers = std::min<std::size_t>(n, std::size_t(tbb::this_task_arena::max_concurrency()));
  std::vector<std::thread> helpers;
  for (std::size_t t = 1; t < workers; ++t) helpers.emplace_back(drain);
  drain();
  for (std::thread& t : helpers) t.join();
#else
  struct Graph {
    tbb::task_group& group;
    std::atomic<std::uint32_t>* waits;
    const Body& body;
    void run(std::size_t t) const {
      body(t, [this](std::size_t u) {
        // acq_rel: the thread that runs u sees what every predecessor of u wrote.
        if (waits[u].fetch_sub(1, std::memory_order_acq_rel) == 1) group.run([this, u] { run(u); });
      });
    }
  };
  tbb::task_group group;
  const Graph graph{group, waits, body};
  for (std::size_t t : roots) group.run([&graph, t] { graph.run(t); });
  group.wait();
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

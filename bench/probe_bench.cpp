// Machine-ceiling probes: what the hardware can do at best, to put the solver's numbers in
// proportion (bench/README.md, "measured vs floor").
//  * probe/triad: STREAM-like a[i] = b[i] + s c[i] over arrays far larger than the caches;
//    counter bytes_per_s counts 12 bytes per element (two loads, one store; the store's
//    write-allocate read is not counted, as in STREAM).
//  * probe/fma: independent fused multiply-add chains on the widest vectors; flops_per_s.
//  * probe/sqrt_div: one square root and one division per element, the two long-latency
//    operations every spring needs (kernels/spring.hpp); pairs_per_s gives the compute floor.
//  * probe/spring: the fine-spring kernel's whole work per spring where nothing else can
//    slow it: its own arithmetic (kernels/spring_lanes.hpp) on 12 end values and a count
//    loaded as aligned unit-stride vectors, and the 6 read-modify-writes of the ends' force
//    sums, over a block of springs that stays in L1; springs_per_s. Where it is far under
//    pairs_per_s, what a spring needs besides its square root and division (28 other
//    operations a lane; 19 loads and 6 stores a vector) bounds the step before the sqrt+div
//    floor does.
// Each runs one task per thread inside a task arena of the case's thread count.
#include <cstddef>
#include <vector>

#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>
// GCC 12 warns inside its own avx512fintrin.h where xsimd inlines _mm512_undefined_*
// (uninitialised by design); see kernels/lanes.hpp.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <xsimd/xsimd.hpp>

#include "bench_cases.hpp"
#include "kernels/spring_lanes.hpp"

namespace papertear::bench {
namespace {

using Batch = xsimd::batch<float>;
constexpr std::size_t kTriadElements = std::size_t(1) << 24;  // 64 MiB per array
constexpr int kChains = 8;
constexpr int kRounds = 1 << 16;

template <class Body>
double on_threads(tbb::task_arena& arena, int threads, const Body& body) {
  return timed([&] {
    arena.execute([&] {
      tbb::parallel_for(0, threads, [&](int t) { body(t); }, tbb::static_partitioner());
    });
  });
}

void probe_triad(benchmark::State& state, int threads) {
  std::vector<float> a(kTriadElements, 0.0f), b(kTriadElements, 1.0f), c(kTriadElements, 2.0f);
  tbb::task_arena arena(threads);
  const float s = 3.0f;
  for (auto _ : state) {
    const double t = timed([&] {
      arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, kTriadElements, 1 << 16),
                          [&](const tbb::blocked_range<std::size_t>& r) {
                            for (std::size_t i = r.begin(); i < r.end(); ++i) a[i] = b[i] + s * c[i];
                          },
                          tbb::static_partitioner());
      });
    });
    benchmark::DoNotOptimize(a.data());
    benchmark::ClobberMemory();
    state.SetIterationTime(t);
  }
  state.counters["bytes_per_s"] = benchmark::Counter(12.0 * double(kTriadElements), benchmark::Counter::kIsIterationInvariantRate);
}

void probe_fma(benchmark::State& state, int threads) {
  tbb::task_arena arena(threads);
  std::vector<float> sink(std::size_t(threads) * Batch::size);
  for (auto _ : state) {
    state.SetIterationTime(on_threads(arena, threads, [&](int t) {
      Batch acc[kChains];
      for (int j = 0; j < kChains; ++j) acc[j] = Batch(1.0f + float(j) * 1e-3f);
      const Batch m(0.999999f), add(1e-6f);
      for (int r = 0; r < kRounds; ++r)
        for (int j = 0; j < kChains; ++j) acc[j] = xsimd::fma(acc[j], m, add);
      Batch total = acc[0];
      for (int j = 1; j < kChains; ++j) total += acc[j];
      total.store_unaligned(sink.data() + std::size_t(t) * Batch::size);
    }));
    benchmark::DoNotOptimize(sink.data());
  }
  const double flops = 2.0 * double(Batch::size) * kChains * kRounds * threads;
  state.counters["flops_per_s"] = benchmark::Counter(flops, benchmark::Counter::kIsIterationInvariantRate);
}

void probe_sqrt_div(benchmark::State& state, int threads) {
  tbb::task_arena arena(threads);
  double pairs = 0.0;
  for (auto _ : state) {
    const SqrtDivRun run = sqrt_div_run(arena, threads);
    state.SetIterationTime(run.seconds);
    pairs = run.pairs;
  }
  state.counters["pairs_per_s"] = benchmark::Counter(pairs, benchmark::Counter::kIsIterationInvariantRate);
}

// probe/spring's block: springs a -> b, kSpringLanes of them, as columns.
constexpr std::size_t kSpringLanes = 256;  // 19 columns of 1 KiB: in any L1 data cache
constexpr int kSpringRounds = 1 << 12;
struct alignas(64) SpringBlock {
  float end[12][kSpringLanes];  // a's x, y, z, vx, vy, vz, then b's
  float count[kSpringLanes];
  float fa[3][kSpringLanes], fb[3][kSpringLanes];  // force sums of the a and b ends
};

void fill_springs(SpringBlock& blk) {
  for (std::size_t l = 0; l < kSpringLanes; ++l) {
    const float t = float(l) / float(kSpringLanes);
    const float a[6] = {t, 0.5f * t, 0.0f, 0.01f, -0.02f, 0.005f};
    const float d[6] = {1.0f + 0.1f * t, 0.2f, 0.1f - 0.05f * t, 0.03f * t, 0.01f, -0.02f};
    for (int q = 0; q < 6; ++q) {
      blk.end[q][l] = a[q];
      blk.end[6 + q][l] = a[q] + d[q];
    }
    blk.count[l] = float(1 + l % 3);
    for (int q = 0; q < 3; ++q) blk.fa[q][l] = blk.fb[q][l] = 0.0f;
  }
}

// The sweep's body (kernels/cell_forces.cpp, SlotPass::springs) for one vector of springs.
void spring_vector(SpringBlock& blk, std::size_t i, const Batch& vk, const Batch& vc, const Batch& rest) {
  Batch pa[6], pb[6], f[3];
  for (int q = 0; q < 6; ++q) {
    pa[q] = Batch::load_aligned(&blk.end[q][i]);
    pb[q] = Batch::load_aligned(&blk.end[6 + q][i]);
  }
  spring_force<Batch, false>(pa, pb, Batch::load_aligned(&blk.count[i]), vk, vk, vc, rest, f);
  for (int q = 0; q < 3; ++q) {
    (Batch::load_aligned(&blk.fa[q][i]) + f[q]).store_aligned(&blk.fa[q][i]);
    (Batch::load_aligned(&blk.fb[q][i]) - f[q]).store_aligned(&blk.fb[q][i]);
  }
}

void probe_spring(benchmark::State& state, int threads) {
  tbb::task_arena arena(threads);
  std::vector<SpringBlock> blocks(static_cast<std::size_t>(threads));
  for (SpringBlock& blk : blocks) fill_springs(blk);
  for (auto _ : state) {
    state.SetIterationTime(on_threads(arena, threads, [&](int t) {
      SpringBlock& blk = blocks[std::size_t(t)];
      const Batch vk(2.0f), vc(0.01f), rest(1.0f);
      for (int r = 0; r < kSpringRounds; ++r) {
        for (std::size_t i = 0; i < kSpringLanes; i += Batch::size) spring_vector(blk, i, vk, vc, rest);
        benchmark::ClobberMemory();  // every round loads its springs again, as the sweep does
      }
    }));
    benchmark::DoNotOptimize(blocks.data());
  }
  const double springs = double(kSpringLanes) * kSpringRounds * threads;
  state.counters["springs_per_s"] = benchmark::Counter(springs, benchmark::Counter::kIsIterationInvariantRate);
}

}  // namespace

SqrtDivRun sqrt_div_run(tbb::task_arena& arena, int threads) {
  std::vector<float> sink(std::size_t(threads) * Batch::size);
  const double seconds = on_threads(arena, threads, [&](int t) {
    Batch acc[kChains], x[kChains];
    for (int j = 0; j < kChains; ++j) {
      acc[j] = Batch(0.0f);
      x[j] = Batch(2.0f + float(j));
    }
    const Batch one(1.0f);
    for (int r = 0; r < kRounds / 4; ++r)
      for (int j = 0; j < kChains; ++j) acc[j] += one / xsimd::sqrt(x[j] + acc[j] * Batch(1e-30f));
    Batch total = acc[0];
    for (int j = 1; j < kChains; ++j) total += acc[j];
    total.store_unaligned(sink.data() + std::size_t(t) * Batch::size);
  });
  benchmark::DoNotOptimize(sink.data());
  return {seconds, double(Batch::size) * kChains * (kRounds / 4) * threads};
}

void register_probe_benchmarks() {
  for (int threads : {1, 2}) {
    const std::string suffix = "/threads:" + std::to_string(threads);
    register_timed("probe/triad" + suffix, benchmark::kMillisecond, probe_triad, threads);
    register_timed("probe/fma" + suffix, benchmark::kMicrosecond, probe_fma, threads);
    register_timed("probe/sqrt_div" + suffix, benchmark::kMicrosecond, probe_sqrt_div, threads);
    register_timed("probe/spring" + suffix, benchmark::kMicrosecond, probe_spring, threads);
  }
}

}  // namespace papertear::bench

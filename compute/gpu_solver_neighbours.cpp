// GpuSolver: the rest-state neighbour search on the GPU and the precompute pass.
//
//   1 nbr_cells    cell of every phyxel (hash grid per object, cell just above h), its slot in
//                  its bucket (integer atomic count)
//   2 scan         bucket counts -> bucket starts (exclusive prefix sum)
//   3 nbr_scatter  phyxel indices grouped by bucket (counting sort)
//   4 nbr_pairs    count the pairs of every phyxel (27 cells, same object, CPU's distance rule)
//   5 scan         counts -> CSR offsets (N + 1); the total is read back to size the arrays
//   6 nbr_pairs    fill every row, sort it by index, store its poly6 weights
//   7 precompute   A_i, regularised A_i^-1, residual, kappa_i, regularised flag
// The CSR is then downloaded once for neighbours(). Steps 1, 3, 4, 6 and 7 run in chunks of
// phyxels, a submission each (run_in_chunks), polling the setup's stop between them: a large
// scene's setup on a slow device stops within a chunk's time, as the CPU's does.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <string>

#include "compute/gpu_solver.h"
#include "compute/gpu_solver_kernels.h"
#include "compute/gpu_solver_setup.h"
#include "engine/solver/neighbours.h"

namespace phyxel::gpu {

using namespace layout;

namespace {

// Wall seconds a setup chunk aims at once the rate is known, and the first chunk's phyxels.
constexpr double kSetupChunkSeconds = 0.02;
constexpr uint64_t kFirstSetupChunk = 4096;

}  // namespace

void GpuSolver::run_in_chunks(Recorder& rec, const char* phase, const ChunkRecorder& record) {
  const bool adaptive = options_.setup_chunk == 0;
  uint64_t chunk = adaptive ? kFirstSetupChunk : options_.setup_chunk;
  for (uint32_t first = 0; first < count_;) {
    if (search_stop_requested()) throw SearchStopped(phase);
    const uint32_t n = static_cast<uint32_t>(std::min<uint64_t>(chunk, count_ - first));
    const auto t0 = std::chrono::steady_clock::now();
    rec.barrier();  // after the previous chunk's or pass's writes
    record(rec, first, n);
    rec.submit_and_wait();
    first += n;
    if (!adaptive) continue;
    const double took =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    chunk = std::clamp<uint64_t>(
        static_cast<uint64_t>(double(n) * kSetupChunkSeconds / std::max(took, 1e-6)), 256,
        4 * uint64_t{n});
  }
}

void GpuSolver::build_neighbours(const std::vector<vec4>& rest_lo_host) {
  Context& ctx = *ctx_;
  const uint64_t n = count_;
  const uint32_t buckets = hash_buckets(count_);
  auto device = [&](uint64_t bytes, const char* name) {
    return Buffer(ctx, bytes, MemoryIntent::Device, name);
  };
  Buffer rest_lo = device(n * sizeof(vec4), "search: rest lo");
  Buffer cell_of = device(n * sizeof(ivec4), "search: cell of phyxel");
  Buffer slot = device(n * sizeof(uint32_t), "search: slot in bucket");
  Buffer sorted = device(n * sizeof(uint32_t), "search: phyxels by bucket");
  Buffer pair_count = device(n * sizeof(uint32_t), "search: pairs per phyxel");
  Buffer bucket_count = device(uint64_t{buckets} * sizeof(uint32_t), "search: bucket count");
  Buffer bucket_start = device((uint64_t{buckets} + 1) * sizeof(uint32_t), "search: bucket start");
  upload(ctx, rest_lo, rest_lo_host);
  const PrefixScan bucket_scan(ctx, *kernels_, buckets + 1);
  const PrefixScan row_scan(ctx, *kernels_, count_ + 1);

  using SupportTest = GpuSolverOptions::SupportTest;
  if (options_.support_test == SupportTest::Float64 && !ctx.float64())
    throw VulkanError(ctx.info().name + " has no shaderFloat64 for the double support test",
                      VK_ERROR_FEATURE_NOT_PRESENT);
  const Pipeline& pairs = options_.support_test != SupportTest::Float32 && ctx.float64()
                              ? kernels_->nbr_pairs_f64
                              : kernels_->nbr_pairs;
  // A chunk's dispatch rounds up to whole workgroups: `end` bounds it.
  const auto push = [&](uint32_t mode, uint32_t first, uint32_t count) {
    return NbrPush{first + count, buckets - 1, mode, first};
  };
  // The support test over the candidates: counting, then filling the index and weights.
  const auto record_pairs = [&](Recorder& rec, const NbrPush& pc, uint32_t phyxels,
                                const BufferRef& index_lo, const BufferRef& weight_lo,
                                const BufferRef& index_hi, const BufferRef& weight_hi) {
    dispatch(rec, pairs, pc,
             {{"Local", local_},
              {"RestLo", rest_lo},
              {"Flags", flags_},
              {"Classes", classes_},
              {"CellOf", cell_of},
              {"Start", bucket_start},
              {"Sorted", sorted},
              {"Count", pair_count},
              {"Offset", nbr_offset_},
              {"IndexLo", index_lo},
              {"WeightLo", weight_lo},
              {"IndexHi", index_hi},
              {"WeightHi", weight_hi}},
             phyxels);
  };
  const char* search = "the neighbour search";
  Recorder rec(ctx, "neighbour search");
  rec.fill(bucket_count, 0);
  run_in_chunks(rec, search, [&](Recorder& r, uint32_t first, uint32_t count) {
    dispatch(r, kernels_->nbr_cells, push(kNbrCount, first, count),
             {{"Local", local_},
              {"Flags", flags_},
              {"Classes", classes_},
              {"CellOf", cell_of},
              {"Slot", slot},
              {"BucketCount", bucket_count}},
             count);
  });
  rec.barrier();
  bucket_scan.record(rec, bucket_count, buckets, bucket_start);
  run_in_chunks(rec, search, [&](Recorder& r, uint32_t first, uint32_t count) {
    dispatch(r, kernels_->nbr_scatter, push(kNbrCount, first, count),
             {{"CellOf", cell_of}, {"Slot", slot}, {"Start", bucket_start}, {"Sorted", sorted}},
             count);
  });
  // Index and weight are not touched when counting; the offsets stand in for them.
  run_in_chunks(rec, search, [&](Recorder& r, uint32_t first, uint32_t count) {
    record_pairs(r, push(kNbrCount, first, count), count, nbr_offset_, nbr_offset_, nbr_offset_,
                 nbr_offset_);
  });
  rec.barrier();
  row_scan.record(rec, pair_count, count_, nbr_offset_);
  rec.submit_and_wait();
  pairs_ = download<uint32_t>(ctx, nbr_offset_, 1, n * sizeof(uint32_t))[0];
  const uint64_t per_part = pairs_per_part(ctx, options_.pair_part_bytes);
  if (pairs_ > per_part && !kernels_->pairs_split())
    kernels_->split_pairs(ctx, static_cast<uint32_t>(per_part));
  nbr_index_ = PairBuffer(ctx, pairs_, per_part, "neighbour index");
  weight_ = PairBuffer(ctx, pairs_, per_part, "pair weight");
  run_in_chunks(rec, search, [&](Recorder& r, uint32_t first, uint32_t count) {
    record_pairs(r, push(kNbrFill, first, count), count, nbr_index_.lo(), weight_.lo(),
                 nbr_index_.hi(), weight_.hi());
  });
  run_in_chunks(rec, "the MLS precompute", [&](Recorder& r, uint32_t first, uint32_t count) {
    record_precompute(r, PrecomputePush{count, 0, first, 0}, list_, count);
  });
  neighbours_.offset = download<uint32_t>(ctx, nbr_offset_, n + 1);
  neighbours_.index = nbr_index_.download<uint32_t>(ctx);
  count_flags();
}

void GpuSolver::count_flags() {
  const std::vector<uint32_t> flags = download<uint32_t>(*ctx_, flags_, count_);
  count_flags(flags.data());
}

void GpuSolver::count_flags(const uint32_t* flags) {
  regularised_ = 0;
  edited_ = 0;
  for (uint32_t i = 0; i < count_; ++i) {
    if (flags[i] & kFlagRegularised) ++regularised_;
    if (flags[i] & kFlagPairsEdited) ++edited_;
  }
}

}  // namespace phyxel::gpu

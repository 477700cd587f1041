// Micro-benchmarks of the N-buffer core (build, query, incremental update) for `nbsim bench
// nbuffer`. Times with Google Benchmark's library and returns one JSON object per result line.
//
// Every time is thread CPU time per iteration, the median over `repetitions` runs of the whole
// section (the runs of one section are interleaved, so a burst of machine noise hits every
// benchmark of the section alike). Absolute times vary from machine to machine and from minute
// to minute on a shared one; the ratios against baselines measured in the same run are the point.
//
// Lines (nlohmann::ordered_json, in this key order):
// - {"bench":"build","size":"WxH","levels":L,"build_ms":t,"copy_ms":c,"ratio":t/c}, one per size
//   256x256, 512x512, 640x480, 1024x1024, depth = scenes::city_depth(W, H, 1).
//   build_ms: NBuffer::build() of every level (F32, max) into an NBuffer allocated beforehand (its
//   levels in the N-buffer's own storage: 64-byte aligned, huge pages advised on Linux).
//   copy_ms: the streaming-copy baseline, i.e. exactly the bytes a naive level-by-level build reads
//   and writes: L - 1 memcpy's of a W*H float plane, plane i to plane i + 1 (i = 0 .. L-2), in one
//   buffer of L planes allocated as the levels are (LevelAllocator: the same alignment and pages,
//   so that the ratio measures the build, not the memory). ratio < 1 means the build costs less
//   than streaming its levels once.
// - {"bench":"build_rect","size":"WxH","levels":P,"bytes":b,"square_levels":L,"square_bytes":s,
//   "build_ms":t,"square_build_ms":u,"ratio_vs_square":t/u}, one per size: the rectangle levels
//   (LevelShape::Rect, every one) built likewise; bytes in the storage format.
// - {"bench":"query","size":"1024x1024","method":m,"queries_per_s":q,"ratio_vs_corners":r} for m in
//   paper, corners, one (NBuffer coverings, covering.h), rect (the rectangle levels, exact), hiz (HiZPyramid), brute (scan
//   every level-0 pixel of the rectangle: the reference). 4096 pre-generated random rectangles,
//   fixed seed, each side log-uniform in 1..512 px, placed uniformly inside the image.
// - {"bench":"update","size":"1024x1024","dirty":"SxS","update_ms":u,"rebuild_ms":b,"ratio":u/b,
//   "texels_recomputed":n,"texels_per_s":n/u} for S in 1, 8, 64, 256: NBuffer::update(depth, rect)
//   for an S x S rect centred in the image whose depths are halved (nearer), alternating with the
//   original depths so that every iteration changes the rect; rebuild_ms is a full NBuffer::build()
//   in the same run; n is UpdateStats::total_recomputed() of one such update (all levels, level 0
//   included) and texels_per_s is n divided by update_ms in seconds (a full build recomputes
//   L * W * H texels in rebuild_ms, for comparison).
#pragma once

#include <nlohmann/json.hpp>

#include <functional>

namespace nbsim::bench {

struct NBufferBenchOptions {
  bool build = true;   // Table 1 lines
  bool query = true;   // query throughput lines
  bool update = true;  // incremental update lines
  double min_time_s = 0.05;  // Google Benchmark's minimum time per benchmark and repetition. Tunable.
  int repetitions = 3;       // runs of each section; the median is reported. Tunable.
  bool progress = false;     // one progress line on stderr, rewritten after each benchmark
};

// Runs the selected sections in the order build, query, update and hands each result line to
// `emit` as soon as its section is done.
void run_nbuffer_bench(const NBufferBenchOptions& options,
                       const std::function<void(const nlohmann::ordered_json&)>& emit);

}  // namespace nbsim::bench

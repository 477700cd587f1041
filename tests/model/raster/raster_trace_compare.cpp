// raster_trace_compare: a developer tool beside the raster tests. Replays a captured trace through
// the raster path and prints the comparison against GL's counters and depth snapshots as one JSON
// line, then the first mismatching draws. Exit 0 within the comparison's thresholds
// (trace_compare.h), 1 outside, 2 on a bad trace or argument.
//   raster_trace_compare TRACE [--unfused-viewport] [--unfused-interpolation] [--batch N] [--list N]
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>

#include "model/common/error.h"
#include "tests/model/raster/trace_compare.h"

int main(int argc, char** argv) {
  using namespace nbsim::raster_compare;
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s TRACE [--unfused-viewport] [--unfused-interpolation] [--batch N] [--list N]\n",
                 argv[0]);
    return 2;
  }
  CompareOptions o;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--unfused-viewport")
      o.fused_viewport = false;
    else if (a == "--unfused-interpolation")
      o.fused_interpolation = false;
    else if (a == "--batch" && i + 1 < argc)
      o.batch_triangles = std::atoi(argv[++i]);
    else if (a == "--list" && i + 1 < argc)
      o.max_mismatches = std::atoi(argv[++i]);
    else {
      std::fprintf(stderr, "unknown argument '%s'\n", a.c_str());
      return 2;
    }
  }
  try {
    const CompareSummary s = compare_trace(argv[1], o);
    std::printf("%s\n", to_json(s).c_str());
    for (const DrawMismatch& m : s.mismatches)
      std::printf(
          "frame %u draw %u role %d object %d tris %llu: fragments gl %llu model %llu, passed gl %llu model %llu, "
          "clip out gl %llu model %llu\n",
          m.frame, m.draw, static_cast<int>(m.role), m.object, static_cast<unsigned long long>(m.triangles),
          static_cast<unsigned long long>(m.gl_fragments), static_cast<unsigned long long>(m.model_fragments),
          static_cast<unsigned long long>(m.gl_passed), static_cast<unsigned long long>(m.model_passed),
          static_cast<unsigned long long>(m.gl_clip_out), static_cast<unsigned long long>(m.model_clip_out));
    return s.within_thresholds() ? 0 : 1;
  } catch (const nbsim::InputError& e) {
    std::fprintf(stderr, "raster_trace_compare: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "raster_trace_compare: %s\n", e.what());
    return 2;
  }
}

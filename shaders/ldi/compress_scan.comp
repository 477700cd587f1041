// Compression, step 2 (traces/capture/ldi/build.cpp): the exclusive prefix sum of the range counts
// in index order, in one work group: each of its threads sums a contiguous chunk, thread 0 scans the
// chunk sums, then each thread writes its chunk's offsets. Integer sums: exact in any order.
#version 450 core
layout(local_size_x = 1024) in;
uniform uint entries;  // I
layout(std430, binding = 1) readonly buffer Ranges { uint range_count[]; };
layout(std430, binding = 2) writeonly buffer Offsets { uint offset[]; };
layout(std430, binding = 3) writeonly buffer Total { uint total; };
shared uint chunk_base[1024];
void main() {
  uint t = gl_LocalInvocationID.x;
  uint chunk = (entries + 1023u) / 1024u;
  uint first = min(t * chunk, entries), last = min(first + chunk, entries);
  uint sum = 0u;
  for (uint i = first; i < last; ++i) sum += range_count[i];
  chunk_base[t] = sum;
  barrier();
  if (t == 0u) {
    uint running = 0u;
    for (uint j = 0u; j < 1024u; ++j) {
      uint s = chunk_base[j];
      chunk_base[j] = running;
      running += s;
    }
    total = running;
  }
  barrier();
  uint running = chunk_base[t];
  for (uint i = first; i < last; ++i) {
    offset[i] = running;
    running += range_count[i];
  }
}

// See relief_chunk.h.
#include "traces/format/relief_chunk.h"

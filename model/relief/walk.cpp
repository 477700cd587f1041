// See walk.h.
#include "model/relief/walk.h"

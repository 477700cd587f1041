// See reference.h.
#include "model/relief/reference.h"

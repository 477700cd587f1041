// See heightfield.h.
#include "model/relief/heightfield.h"

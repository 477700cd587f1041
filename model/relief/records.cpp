// See records.h.
#include "model/relief/records.h"

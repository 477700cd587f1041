// See radius.h.
#include "model/relief/radius.h"

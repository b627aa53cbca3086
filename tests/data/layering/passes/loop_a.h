// A cycle for tests/layering_check.sh, with passes/loop_b.h.
#include "passes/loop_b.h"

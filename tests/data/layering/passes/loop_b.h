// A cycle for tests/layering_check.sh, with passes/loop_a.h.
#include "passes/loop_a.h"

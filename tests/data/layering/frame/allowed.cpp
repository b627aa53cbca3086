// Allowed: frame/ over labeling/ and passes/, and shaders/shared everywhere.
#include "labeling/layering.h"
#include "passes/loop_a.h"
#include "shared/labels.h"

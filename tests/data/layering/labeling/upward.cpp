// A fault for tests/layering_check.sh: labeling/ may not include frame/.
#include "frame/labelled_render.h"

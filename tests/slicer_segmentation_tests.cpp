#include <doctest/doctest.h>

#include "engine/scene/segmentation.h"

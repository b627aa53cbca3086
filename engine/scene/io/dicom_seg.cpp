#include "engine/scene/segmentation.h"

// What the tidy-up's steps and its search share, once the states' accessors are defined.
#include "shared/tidy_search.h"

bool movable(uint k) {
  return (tidy_state(k).flags & (TIDY_PLACED | TIDY_MOVABLE)) == (TIDY_PLACED | TIDY_MOVABLE);
}

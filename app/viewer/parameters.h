// The viewer's parameters (`set NAME VALUE` in scripts, the panel's sliders and boxes): numbers
// with their ranges and flags of the labelling, rendering and viewer settings, declared in one
// table (app/viewer/parameters.cpp); Viewer::set_parameter sets them.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace strata::app {

// The names set_parameter() takes, with what each sets.
std::vector<std::pair<std::string, std::string>> viewer_parameters();
// An Error unless `name` is a parameter and `value` is on or off for a flag, a number in the
// parameter's range otherwise (what set_parameter checks, without a viewer; render.step's lower
// bound from the volumes is checked by set_number alone).
void check_viewer_parameter(const std::string& name, const std::string& value);

}  // namespace strata::app

// Transfer-function files: strata's JSON (docs/scene-format.md) and the thesis program's .gra
// (Qt gradient XML). Every failure is one strata::Error "<file>: <field>: <reason>".
#pragma once

#include <filesystem>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "engine/scene/scene.h"

namespace strata {

// Picks the reader by extension: .json (strata) or .gra (thesis).
TransferFunction load_transfer_function(const std::filesystem::path& path);

TransferFunction load_transfer_function_json(const std::filesystem::path& path);
TransferFunction load_transfer_function_gra(const std::filesystem::path& path);

void write_transfer_function_json(const std::filesystem::path& path, const TransferFunction& tf);

// True for a .gra file or a JSON file whose top level has "strata_transfer_function", so one
// command can take either a scene or a transfer function.
bool is_transfer_function_file(const std::filesystem::path& path);

// For scene files that hold a transfer function inline. Errors read "<file>: <field>.stops[2]...".
TransferFunction transfer_function_from_json(const nlohmann::json& object, const std::string& file,
                                             const std::string& field);
// Keys in the documented order (ordered_json), for files people read.
nlohmann::ordered_json transfer_function_to_json(const TransferFunction& tf);

}  // namespace strata

// Reading and writing ClothParams, and exporting a trial for pictures.
//
// Params file: one "name value" per line (also "name = value", "name: value", or a flat JSON
// object {"name": value, ...}); names are the ClothParams fields; '#' starts a comment; fields
// not given keep their defaults. Commas separate records as newlines do, so a decimal comma
// ("friction 0,3") is refused with a word on it; '.' is the decimal point. A value may carry a
// leading '+'; a UTF-8 byte-order mark at the file's start is skipped. Unknown names, a name
// given twice, bad numbers and values out of range are errors naming file and line.
#pragma once

#include <filesystem>
#include <string>

#include "trial.h"

namespace dressguard::sim {

ClothParams parse_params(const std::string& text, const std::filesystem::path& file_for_errors);
ClothParams read_params(const std::filesystem::path& file);
std::string format_params(const ClothParams& p);  // "name value" lines, readable by parse_params
std::string params_json(const ClothParams& p);    // a flat JSON object

// The trial's scene for the picture script (tools/plot/sim_scene.py), as JSON: triangles,
// arm round cones at the trial's height (with the params' fist_shift), gripper start, grasped and sleeve-opening vertices,
// the frames' positions, gripper travel per frame, and the haptic samples.
std::string scene_json(const Scene& scene, const ClothParams& params, const TrialSpec& spec, const TrialResult& r);

}  // namespace dressguard::sim

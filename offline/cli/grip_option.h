// --grip-depth and --rim-ahead, shared by `dressguard gown` and `dressguard simulate`.
#pragma once

#include <optional>

#include "args.h"
#include "files.h"
#include "gown.h"

namespace dressguard::cli {

inline constexpr const char* kGripHelp =
    "  --grip-depth M    [m] how far below the top of the opening's rim the lower jaw's face is\n"
    "                    (default 0.015 for the measured gown, 0.03 for the parametric one):\n"
    "                    deeper holds the opening wider and shallower (offline/gown/placement.h,\n"
    "                    OpeningGrip)\n"
    "  --rim-ahead M     [m] the opening's rim ahead of the jaws (default 0.04; parametric 0.01).\n"
    "                    The measured sleeve's top falls away behind its rim: the further ahead,\n"
    "                    the less the jaws hold (14 vertices at 0.04, 5 and one whole triangle at\n"
    "                    0.065, no triangle from 0.070, which is refused: a point or a line of cloth\n"
    "                    is no clamp); below 0.13, where the rim reaches the fist's back\n";

// The grip the options ask for, starting from `base` (a calibration's grasp) or else the gown's
// own; nullopt when neither option is given and there is no base.
inline std::optional<gown::OpeningGrip> grip_option(const Args& args, bool parametric_gown,
                                                    std::optional<gown::OpeningGrip> base = std::nullopt) {
  if (!args.has("grip-depth") && !args.has("rim-ahead")) return base;
  gown::OpeningGrip g = base ? *base : gown::own_grip(parametric_gown);
  g.depth = args.number("grip-depth", g.depth);
  g.rim_ahead = args.number("rim-ahead", g.rim_ahead);
  if (!(g.depth > 0 && g.depth < 0.15)) throw UsageError("--grip-depth must be in (0, 0.15) m, the grasp box's depth");
  // Short of the fist's back: further ahead the hand would start inside the sleeve.
  const double limit = gown::rim_ahead_limit(gown::PaperScene{});
  if (!(g.rim_ahead >= 0 && g.rim_ahead < limit))
    throw UsageError(format_string("--rim-ahead must be in [0, %g) m: from %g m the opening's rim starts level with or "
                                   "past the fist's back, the hand inside the sleeve (offline/gown/placement.h, "
                                   "rim_ahead_limit)",
                                   limit, limit));
  return g;
}

}  // namespace dressguard::cli

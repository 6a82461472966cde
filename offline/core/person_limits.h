// Limits of the gown's weight and the arm's give that both a simulator params file
// (sim/params.cpp) and a calibration file (calib/calibration.h, which cannot include the
// simulator) are held to: one definition, so that the two readers refuse the same values.
#pragma once

namespace dressguard {

// [kg/m^2] areal density: a light nonwoven to beyond a heavy canvas (about 0.5).
inline constexpr double kMinArealDensity = 0.01, kMaxArealDensity = 1.0;
inline constexpr const char* kArealDensityRange = "must be within 0.01 and 1 kg/m^2 (a heavy canvas is about 0.5)";
// [m/N] arm compliance (sim/arm_spring.h): 0 is a fixed arm.
inline constexpr double kMaxArmCompliance = 1.0;
inline constexpr const char* kArmComplianceRange = "cannot be negative (0 is a fixed arm) nor above 1 m/N";

}  // namespace dressguard

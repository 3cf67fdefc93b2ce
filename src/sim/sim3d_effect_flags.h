// simulate's flags for the 3-D simulator's one-off effects (--payload_change,
// --flexible_mount, --periodic_force, --estimator_glitch) and --rate_hz:
// parsed from their text and held to the ranges --help and
// docs/simulator-3d.md state, with messages that name the flag, the value
// and the range. The ranges are the ones Simulator3dOptions::Validate
// enforces (sim3d_options.cc uses the constants below), plus the rule that a
// flag given must change the flight: a zero amplitude, mass or glitch would
// be accepted and do nothing. Internal (src/cli uses it).

#ifndef IMUSYSID_SRC_SIM_SIM3D_EFFECT_FLAGS_H_
#define IMUSYSID_SRC_SIM_SIM3D_EFFECT_FLAGS_H_

#include <string>

#include "imusysid/simulate3d.h"
#include "imusysid/status.h"

namespace imusysid {
namespace sim3d_flags {

// The 3-D simulator's raw IMU rate, Hz.
inline constexpr double kMinRateHz = 100.0;
inline constexpr double kMaxRateHz = 1000.0;
// Effects oscillate below this fraction of the rate (the Nyquist margin).
inline constexpr double kMaxEffectFreqPerRate = 0.45;
inline constexpr double kMaxMountAmplitudeM = 0.01;
inline constexpr double kMinForceFreqHz = 0.01;
inline constexpr double kMaxForceAmplitudeMps2 = 5.0;
inline constexpr double kMaxGlitchYawDeg = 180.0;
inline constexpr double kMaxGlitchVelocityMps = 20.0;
inline constexpr double kMaxGlitchDurationS = 10.0;
inline constexpr double kMaxPayloadOffsetM = 0.5;

// --rate_hz=R for a 3-D scenario: R in [100, 1000].
Status CheckRateFlag(double rate_hz);

// --payload_change=T,DM,DX,DY,DZ into o->payload_change: 0 <= T < the
// flight's duration, DM != 0 in [-M/2, M] (M = o->mass_kg), each offset in
// [-0.5, 0.5] m.
Status ApplyPayloadChangeFlag(const std::string& text, Simulator3dOptions* o);

// --flexible_mount=F_HZ,AMPLITUDE_M[,DX,DY,DZ] into o->flexible_mount:
// 0 < F_HZ <= 0.45 o->rate_hz, 0 < AMPLITUDE_M <= 0.01, (DX, DY, DZ) not
// zero.
Status ApplyFlexibleMountFlag(const std::string& text, Simulator3dOptions* o);

// --periodic_force=F_HZ,AMPLITUDE_MPS2[,DX,DY,DZ] into o->periodic_force:
// 0.01 <= F_HZ <= 0.45 o->rate_hz, 0 < AMPLITUDE_MPS2 <= 5, (DX, DY, DZ) not
// zero.
Status ApplyPeriodicForceFlag(const std::string& text, Simulator3dOptions* o);

// --estimator_glitch=T_S,YAW_DEG,VEL_MPS[,VEL_DURATION_S] into
// o->estimator_glitch: 0 <= T_S < the flight's duration, |YAW_DEG| <= 180,
// |VEL_MPS| <= 20, 0 <= VEL_DURATION_S <= 10, and a yaw or a velocity
// glitch that lasts.
Status ApplyEstimatorGlitchFlag(const std::string& text, Simulator3dOptions* o);

}  // namespace sim3d_flags
}  // namespace imusysid

#endif  // IMUSYSID_SRC_SIM_SIM3D_EFFECT_FLAGS_H_

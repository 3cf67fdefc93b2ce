// sysid_3d's excitation (docs/simulator-3d.md, "sysid_3d"): a flight plan's
// chirps, each as ArduCopter's System ID flight mode injects it, one after
// the other with hover between them.

#include <cmath>

#include "imusysid/flight_plan.h"
#include "imusysid/parameters.h"
#include "src/sim/sim3d_internal.h"

namespace imusysid {
namespace internal {
namespace {

// Step of the central difference that gives an attitude injection's rate,
// s: the chirp is smooth on this scale up to the plans' 100 Hz.
constexpr double kSysIdRateStepS = 1e-5;

// 0 roll, 1 pitch, 2 yaw (validated names).
int SysIdAxisIndex(const std::string& axis) {
  if (axis == "roll") return 0;
  if (axis == "pitch") return 1;
  return 2;
}

}  // namespace

double SysIdChirp(const ExcitationSegment3d& s, double tau) {
  const double record = s.t_rec_s;
  if (!(tau > 0.0) || tau > record) return 0.0;
  // The window: a half cosine up over the fade-in, one down over the
  // fade-out, 1 between.
  double window = 1.0;
  if (tau < s.t_fade_in_s) {
    window = 0.5 - 0.5 * std::cos(kPi * tau / s.t_fade_in_s);
  } else if (tau > record - s.t_fade_out_s) {
    window = 0.5 + 0.5 * std::cos(kPi * (tau - (record - s.t_fade_out_s)) /
                                  s.t_fade_out_s);
  }
  // Two cycles at the start frequency (their phase ends at 0, where the
  // sweep's starts), then the frequency ω₀ e^{B u / span} with
  // B = ln(ω₁/ω₀), u the time into the sweep and span its length; its
  // phase is the frequency's integral, ω₀ span / B (e^{B u / span} − 1).
  const double w0 = 2.0 * kPi * s.f_start_hz;
  const double dwell = 2.0 / s.f_start_hz;
  double phase = w0 * (tau - dwell);
  if (tau > dwell && s.f_stop_hz > s.f_start_hz) {
    const double b = std::log(s.f_stop_hz / s.f_start_hz);
    const double span = record - dwell;
    phase = w0 * span / b * std::expm1(b * (tau - dwell) / span);
  }
  return window * s.magnitude * std::sin(phase);
}

void SysIdExcitationAt(const Simulator3dOptions& o,
                       double tau,
                       Reference3d* ref) {
  double start = o.sysid_gap_s;
  for (const ExcitationSegment3d& s : o.sysid_segments) {
    if (tau < start) return;  // hovering before this segment
    if (tau > start + s.t_rec_s) {
      start += s.t_rec_s + o.sysid_gap_s;
      continue;
    }
    const double u = tau - start;
    const double value = SysIdChirp(s, u) * kDegToRad;
    const int axis = SysIdAxisIndex(s.axis);
    ref->excited = true;
    if (s.injection == "rate") {
      // SID_AXIS 7/8/9: onto the rate target.
      ref->rate_offset(axis) = value;
    } else if (axis < 2) {
      // SID_AXIS 1/2: onto the roll or pitch angle target, its rate fed
      // forward as ArduCopter's attitude controller does.
      ref->tilt_offset(axis) = value;
      ref->rate_offset(axis) = (SysIdChirp(s, u + kSysIdRateStepS) -
                                SysIdChirp(s, u - kSysIdRateStepS)) *
                               kDegToRad / (2.0 * kSysIdRateStepS);
    } else {
      // SID_AXIS 3: onto the pilot's yaw-rate input, which the attitude
      // controller integrates into the heading target and feeds forward.
      ref->heading_rate = value;
      ref->rate_offset(2) = value;
    }
    return;
  }
}

}  // namespace internal
}  // namespace imusysid

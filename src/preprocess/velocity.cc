// The horizontal velocity the paper model needs: from the gyro alone
// (equation 7) or from the autopilot's NED velocity and yaw, projected on the
// body axis of the plane and filtered like the IMU signals.

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "imusysid/parameters.h"
#include "src/numerics/butterworth.h"
#include "src/numerics/trapezoid.h"
#include "src/preprocess/preprocess_internal.h"

namespace imusysid {
namespace internal {
namespace {

// Equation 7: v = g ∫ sin θ dt over the segment, θ = v = 0 at its start.
void GyroVelocity(ProblemData* data, std::vector<std::string>* notes) {
  const std::size_t count = data->t_s.size();
  std::vector<double> sin_theta(count);
  for (std::size_t i = 0; i < count; ++i) {
    sin_theta[i] = std::sin(data->planar.theta[i]);
  }
  data->planar.v = CumulativeTrapezoid(data->t_s, sin_theta);
  for (double& v : data->planar.v) v *= kGravity;
  notes->push_back("v from the gyro (equation 7): θ0 = v0 = 0 at " +
                   FormatFixed(data->t_s.front(), 3) + " s");
}

// The log's vel_n, vel_e and yaw channels.
struct VelocityChannels {
  const Channel* vel_n = nullptr;
  const Channel* vel_e = nullptr;
  const Channel* yaw = nullptr;

  bool FiniteAt(std::size_t i) const {
    return std::isfinite(vel_n->values[i]) && std::isfinite(vel_e->values[i]) &&
           std::isfinite(yaw->values[i]);
  }
};

// The three channels, each as long as the log. FailedPrecondition names the
// missing ones.
StatusOr<VelocityChannels> FindVelocityChannels(const FlightLog& log) {
  const std::size_t n = log.t_s.size();
  VelocityChannels c;
  c.vel_n = log.FindChannel(kChannelVelN);
  c.vel_e = log.FindChannel(kChannelVelE);
  c.yaw = log.FindChannel(kChannelYaw);
  std::string missing;
  for (const auto& [name, channel] :
       {std::pair<const char*, const Channel*>{kChannelVelN, c.vel_n},
        {kChannelVelE, c.vel_e},
        {kChannelYaw, c.yaw}}) {
    if (channel == nullptr) {
      missing += (missing.empty() ? "" : ", ") + std::string(name);
    } else if (channel->values.size() != n) {
      return InvalidArgumentError(log.source + ": channel '" + name + "' has " +
                                  std::to_string(channel->values.size()) +
                                  " samples, t has " + std::to_string(n));
    }
  }
  if (!missing.empty()) {
    return FailedPreconditionError(
        log.source +
        ": velocity_source = log needs the channels vel_n, "
        "vel_e and yaw; missing: " +
        missing);
  }
  return c;
}

// The log's velocity along the plane's body axis over the segment, filtered
// over the segment plus whatever finite margin the log has, so it is smoothed
// exactly like the IMU signals.
Status LogVelocity(const FlightLog& log,
                   const PreprocessOptions& options,
                   const SampleRange& segment,
                   double fs,
                   ProblemData* data,
                   std::vector<std::string>* notes) {
  const std::vector<double>& t = log.t_s;
  const std::size_t n = t.size();
  const std::size_t i0 = segment.begin;
  const std::size_t i1 = segment.end;
  StatusOr<VelocityChannels> channels = FindVelocityChannels(log);
  if (!channels.ok()) return channels.status();
  const VelocityChannels& c = *channels;
  for (std::size_t i = i0; i < i1; ++i) {
    if (!c.FiniteAt(i)) {
      return FailedPreconditionError(
          log.source +
          ": velocity_source = log: vel_n/vel_e/yaw are not "
          "finite at t = " +
          FormatFixed(t[i], 3) + " s inside the fit segment");
    }
  }
  const std::size_t pad =
      options.cutoff_hz > 0.0 ? ButterworthPadLength(options.cutoff_hz, fs) : 0;
  std::size_t v0 = i0;
  while (v0 > 0 && i0 - v0 < pad && c.FiniteAt(v0 - 1)) --v0;
  std::size_t v1 = i1;
  while (v1 < n && v1 - i1 < pad && c.FiniteAt(v1)) ++v1;
  std::vector<double> v(v1 - v0);
  for (std::size_t i = v0; i < v1; ++i) {
    const double cos_yaw = std::cos(c.yaw->values[i]);
    const double sin_yaw = std::sin(c.yaw->values[i]);
    v[i - v0] =
        options.plane == Plane::kPitch
            ? c.vel_n->values[i] * cos_yaw + c.vel_e->values[i] * sin_yaw
            : -c.vel_n->values[i] * sin_yaw + c.vel_e->values[i] * cos_yaw;
  }
  const std::vector<double> t_v(t.begin() + static_cast<std::ptrdiff_t>(v0),
                                t.begin() + static_cast<std::ptrdiff_t>(v1));
  IMUSYSID_RETURN_IF_ERROR(LowPass(options, t_v, &v));
  data->planar.v.assign(v.begin() + static_cast<std::ptrdiff_t>(i0 - v0),
                        v.begin() + static_cast<std::ptrdiff_t>(i1 - v0));
  notes->push_back(
      std::string("v from the log's vel_n, vel_e, yaw along "
                  "body ") +
      (options.plane == Plane::kPitch ? "x (forward)" : "y (right, FRD +y)"));
  return Status::Ok();
}

}  // namespace

Status AddVelocity(const FlightLog& log,
                   const PreprocessOptions& options,
                   const SampleRange& segment,
                   double sample_rate_hz,
                   ProblemData* data,
                   std::vector<std::string>* notes) {
  if (options.velocity_source == VelocitySource::kGyro) {
    GyroVelocity(data, notes);
    return Status::Ok();
  }
  return LogVelocity(log, options, segment, sample_rate_hz, data, notes);
}

}  // namespace internal
}  // namespace imusysid

// IdentifyFlights (pool3d.h): several flights of one vehicle, each
// identified on its own by Identify, then pooled by PoolFlights (the analyse
// stage) and mapped to the autopilot's terms. Orchestration only.

#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "imusysid/identify.h"
#include "imusysid/log.h"
#include "imusysid/pool3d.h"
#include "imusysid/rigid3d.h"

namespace imusysid {

bool FlightsSummary::usable() const {
  for (const IdentifySummary& f : flights) {
    if (!f.usable()) return false;
  }
  return !flights.empty();
}
namespace {

// FNV-1a, 64 bits: a cheap fingerprint of a log's bytes, so that only two
// inputs of the same size and fingerprint are compared byte for byte.
std::uint64_t PoolContentFingerprint(std::string_view bytes) {
  std::uint64_t h = 14695981039346656037ull;
  for (const char c : bytes) {
    h ^= static_cast<unsigned char>(c);
    h *= 1099511628211ull;
  }
  return h;
}

// What an input is, for telling one flight given twice: its bytes' size
// and fingerprint, or (preprocessed data) the data's address.
struct PoolInputIdentity {
  std::size_t size = 0;
  std::uint64_t fingerprint = 0;
  const ProblemData* data = nullptr;
};

// The input's bytes (a log or problem file), seen where they are (given
// bytes; `kept`, standard input's, which can be read only once) or read
// into `holder`.
StatusOr<std::string_view> PoolInputBytes(
    const IdentifyInput& input,
    const std::optional<std::string>& kept,
    std::string* holder) {
  if (kept.has_value()) return std::string_view(*kept);
  if (input.kind() == IdentifyInput::Kind::kLogBytes) {
    return std::string_view(input.bytes());
  }
  StatusOr<std::string> read = ReadFileToString(input.source());
  if (!read.ok()) return read.status();
  *holder = std::move(read).value();
  return std::string_view(*holder);
}

std::string PoolFlightName(std::size_t i, const IdentifyInput& input) {
  return "flight " + std::to_string(i + 1) + " (" + input.source() + ")";
}

}  // namespace

StatusOr<FlightsSummary> IdentifyFlights(
    const std::vector<IdentifyInput>& inputs,
    const IdentifyOptions& options,
    const PoolOptions& pool_options) {
  if (inputs.size() < 2) {
    return InvalidArgumentError("pooling needs two flights or more, not " +
                                std::to_string(inputs.size()));
  }
  // One flight given twice (the same path, another spelling of it, a
  // symbolic or hard link, a copy) would be counted twice: its evidence
  // doubled, the pooled σ̂ shrunk by √2 with no sign of it. It is refused,
  // not counted once with a warning: the command names flights the answer
  // would not rest on, and a repeated name is most often a slip that left
  // the flight meant out (a glob, a completion), which only the caller can
  // put right. Equal bytes are the test (whatever the names), checked
  // before any fitting; standard input is read here once and kept.
  std::vector<PoolInputIdentity> identity(inputs.size());
  std::vector<std::optional<std::string>> kept_stdin(inputs.size());
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const IdentifyInput& in = inputs[i];
    if (in.kind() == IdentifyInput::Kind::kProblemData) {
      identity[i].data = in.data().get();
    } else {
      std::string holder;
      StatusOr<std::string_view> bytes =
          PoolInputBytes(in, std::nullopt, &holder);
      if (!bytes.ok()) {
        return bytes.status().WithPrefix(PoolFlightName(i, in));
      }
      identity[i].size = bytes->size();
      identity[i].fingerprint = PoolContentFingerprint(*bytes);
      if (in.kind() == IdentifyInput::Kind::kLogFile && in.source() == "-") {
        kept_stdin[i] = std::move(holder);
      }
    }
    for (std::size_t j = 0; j < i; ++j) {
      bool same = false;
      if (identity[i].data != nullptr || identity[j].data != nullptr) {
        same = identity[i].data == identity[j].data;
      } else if (identity[i].size == identity[j].size &&
                 identity[i].fingerprint == identity[j].fingerprint) {
        std::string holder_a, holder_b;
        StatusOr<std::string_view> a =
            PoolInputBytes(inputs[i], kept_stdin[i], &holder_a);
        StatusOr<std::string_view> b =
            PoolInputBytes(inputs[j], kept_stdin[j], &holder_b);
        same = a.ok() && b.ok() && *a == *b;
      }
      if (same) {
        return InvalidArgumentError(
            PoolFlightName(i, inputs[i]) + " is " +
            PoolFlightName(j, inputs[j]) + " again (" +
            (identity[i].data != nullptr
                 ? std::string("the same data")
                 : "the same " + std::to_string(identity[i].size) +
                       " bytes: one file under two names, a link or a copy") +
            "); one flight pooled twice is counted twice (its standard "
            "error shrunk by sqrt(2)): give each flight once");
      }
    }
  }
  // Each flight's own parameter file would be of one flight: the pooled one
  // is made below.
  IdentifyOptions one = options;
  one.emit = EmitFormat::kNone;
  // Nor is a plan for one flight's withheld axes: the pool may give them.
  one.plan_withheld = false;
  FlightsSummary out;
  std::vector<FlightImus> imus;
  Status first_refusal = Status::Ok();
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    std::optional<IdentifyInput> from_stdin;
    if (kept_stdin[i].has_value()) {
      from_stdin = IdentifyInput::LogBytes(std::move(*kept_stdin[i]),
                                           inputs[i].source());
      kept_stdin[i].reset();
    }
    const IdentifyInput& input = from_stdin ? *from_stdin : inputs[i];
    StatusOr<IdentifySummary> s = Identify(input, one);
    if (!s.ok()) {
      Status named = s.status().WithPrefix(PoolFlightName(i, inputs[i]));
      // What the data cannot support leaves the other flights to pool;
      // anything else (a missing file, damage, options) is the answer.
      if (s.status().code() != StatusCode::kFailedPrecondition) return named;
      if (first_refusal.ok()) first_refusal = named;
      out.refused.push_back({i, inputs[i].source(), s.status().message()});
      continue;
    }
    if (!s->three_d) {
      return InvalidArgumentError(
          "several flights are pooled for the 3-D models only (rigid3d, "
          "rigid3d_imu); model " +
          s->model + " is planar");
    }
    imus.push_back({s->source, s->imus, s->skipped_imus});
    out.flights.push_back(std::move(s).value());
    out.flight_inputs.push_back(i);
  }
  // One model for the pool: a flight whose log cannot give the model's data
  // (rigid3d without the estimator's attitude and velocity: a planar CSV)
  // is fitted alone with another model, whose position rests on other data
  // and other nuisance terms; pooled, it would move the pool's axes (even
  // those it withholds, through the shared tilt). It is named "not pooled"
  // and the pool is that of the other flights, exactly. The model is the
  // one asked for where any flight gives it, else the one they all fell
  // back to.
  std::string pool_model;
  for (const IdentifySummary& f : out.flights) {
    if (f.model == options.model) pool_model = f.model;
  }
  if (pool_model.empty() && !out.flights.empty()) {
    pool_model = out.flights.front().model;
  }
  {
    FlightsSummary kept;
    kept.refused = std::move(out.refused);
    std::vector<FlightImus> kept_imus;
    for (std::size_t f = 0; f < out.flights.size(); ++f) {
      if (out.flights[f].model == pool_model) {
        kept.flights.push_back(std::move(out.flights[f]));
        kept.flight_inputs.push_back(out.flight_inputs[f]);
        kept_imus.push_back(std::move(imus[f]));
        continue;
      }
      const std::size_t i = out.flight_inputs[f];
      const std::string reason =
          "the log cannot give model " + pool_model + "'s data" +
          (pool_model == kRigid3dModelName
               ? " (it has no attitude and velocity estimate)"
               : "") +
          "; fitted alone it is model " + out.flights[f].model +
          ", which is not pooled with " + pool_model;
      kept.refused.push_back({i, inputs[i].source(), reason});
    }
    std::sort(kept.refused.begin(),
              kept.refused.end(),
              [](const FlightsSummary::RefusedFlight& a,
                 const FlightsSummary::RefusedFlight& b) {
                return a.input < b.input;
              });
    out = std::move(kept);
    imus = std::move(kept_imus);
  }
  if (out.flights.empty()) return first_refusal;
  out.imus = PoolFlights(imus, pool_options);
  if (options.emit != EmitFormat::kNone) {
    StatusOr<AutopilotParameters> emitted = Rigid3dAutopilotParameters(
        PooledAsImuPositions(out.imus, imus), options.emit);
    if (!emitted.ok()) return emitted.status();
    out.emit = std::move(emitted).value();
  }
  return out;
}

}  // namespace imusysid

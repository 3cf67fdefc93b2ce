// The paper's two tests as one log: two simulated flights joined end to end
// (SimulateBatteryMove), and their truth.

#include <cmath>
#include <string>
#include <utility>

#include "imusysid/parameters.h"
#include "imusysid/simulate.h"
#include "nlohmann/json.hpp"

namespace imusysid {
namespace {

// Appends `tail` to `head` with its times shifted by `offset`: the columns
// the two logs share by name (a simulated log's channels are the same for
// every flight).
Status AppendLog(const FlightLog& tail, double offset, FlightLog* head) {
  for (const Channel& c : tail.extra) {
    if (head->FindChannel(c.name) == nullptr) {
      return InvalidArgumentError("the second half has channel '" + c.name +
                                  "' the first lacks");
    }
  }
  auto append = [](const std::vector<double>& values,
                   std::vector<double>* onto) {
    onto->insert(onto->end(), values.begin(), values.end());
  };
  const auto tail_columns = tail.Columns();
  const auto head_columns = head->Columns();
  const std::size_t first = head->size();
  for (std::size_t k = 0; k < tail_columns.size(); ++k) {
    append(*tail_columns[k].second, head_columns[k].second);
  }
  for (std::size_t i = first; i < head->t_s.size(); ++i) {
    head->t_s[i] += offset;
  }
  for (Channel& c : head->extra) {
    const Channel* from = tail.FindChannel(c.name);
    if (from == nullptr) {
      return InvalidArgumentError("the first half has channel '" + c.name +
                                  "' the second lacks");
    }
    append(from->values, &c.values);
  }
  return Status::Ok();
}

}  // namespace

StatusOr<BatteryMoveFlight> SimulateBatteryMove(const SimulatorOptions& before,
                                                const SimulatorOptions& after) {
  if (before.rate_hz != after.rate_hz) {
    return InvalidArgumentError(
        "the two halves of one log are sampled at one rate, not " +
        std::to_string(before.rate_hz) + " and " +
        std::to_string(after.rate_hz) + " Hz");
  }
  BatteryMoveFlight out;
  StatusOr<SimulatedFlight> first = Simulate(before);
  if (!first.ok()) return first.status().WithPrefix("the first half");
  StatusOr<SimulatedFlight> second = Simulate(after);
  if (!second.ok()) return second.status().WithPrefix("the second half");
  out.before = std::move(first).value();
  out.after = std::move(second).value();
  out.log = out.before.log;
  // The second flight's first sample one interval after the first's last:
  // the recording never stops while the battery is moved.
  out.second_start_t_s =
      out.log.t_s.empty() ? 0.0 : out.log.t_s.back() + 1.0 / before.rate_hz;
  IMUSYSID_RETURN_IF_ERROR(
      AppendLog(out.after.log, out.second_start_t_s, &out.log));
  for (auto& [key, value] : out.log.metadata) {
    if (key == "scenario") value = "paper_battery_move";
  }
  return out;
}

std::string BatteryMoveTruthJson(const SimulatorOptions& before,
                                 const SimulatorOptions& after,
                                 const BatteryMoveFlight& flight) {
  using Json = nlohmann::ordered_json;
  Json j;
  j["scenario"] = "paper_battery_move";
  j["frame"] = "flu";
  j["second_half_start_t_s"] = flight.second_start_t_s;
  Json first = Json::parse(TruthJson(before, flight.before));
  Json second = Json::parse(TruthJson(after, flight.after));
  for (auto& [name, t] : second["instants_s"].items()) {
    (void)name;
    t = t.get<double>() + flight.second_start_t_s;
  }
  j["halves"] = Json::array({first, second});
  // Equation 11: the IMU is fixed to the frame, so the CoM moves by the
  // IMU's apparent opposite motion, d = p_before − p_after.
  const double b0 = before.beta_deg * kDegToRad;
  const double b1 = after.beta_deg * kDegToRad;
  const double dx = before.r_m * std::cos(b0) - after.r_m * std::cos(b1);
  const double dz = before.r_m * std::sin(b0) - after.r_m * std::sin(b1);
  double delta = std::atan2(dz, dx) * kRadToDeg;
  if (delta < 0) delta += 360.0;
  j["com_shift_flu_m"] = Json{{"x", dx}, {"z", dz}};
  j["com_shift_l_m"] = std::hypot(dx, dz);
  j["com_shift_delta_deg"] = delta;
  return j.dump(2) + "\n";
}

}  // namespace imusysid

#include "imusysid/log_reader.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>

#include "imusysid/format.h"

namespace imusysid {
namespace {

constexpr double kPi = 3.14159265358979323846;
// sensor_combined's RELATIVE_TIMESTAMP_INVALID: the accelerometer values of
// that sample are not valid.
constexpr std::int64_t kRelativeTimestampInvalid = 0x7FFFFFFF;
// PX4 vehicle_status.arming_state value for "armed".
constexpr double kPx4ArmingStateArmed = 2;
// ArduPilot EV ids for arming and disarming.
constexpr double kArduEventArmed = 10;
constexpr double kArduEventDisarmed = 11;
// A source channel may start or end this many of its own median intervals
// inside the IMU span and still count as covering it (its end value is held):
// estimator topics start a sample or two after the first IMU sample.
constexpr double kCoverageIntervals = 2.0;
// Metadata values longer than this (crash dumps, boot logs) are left out.
constexpr std::size_t kMaxMetadataValueChars = 200;

double Median(std::vector<double> values) {
  if (values.empty()) return 0;
  const std::size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  return values[mid];
}

double MedianInterval(const std::vector<double>& t) {
  if (t.size() < 2) return 0;
  std::vector<double> dt;
  dt.reserve(t.size() - 1);
  for (std::size_t i = 1; i < t.size(); ++i) dt.push_back(t[i] - t[i - 1]);
  return Median(std::move(dt));
}

// IMU samples in the autopilot's FRD frame before the common checks.
struct ImuSeries {
  std::vector<double> t, ax, ay, az, gx, gy, gz;
  std::vector<std::uint64_t> offsets;  // byte offset of each sample's record
  void Add(double time,
           double acc_x,
           double acc_y,
           double acc_z,
           double gyr_x,
           double gyr_y,
           double gyr_z,
           std::uint64_t offset) {
    t.push_back(time);
    ax.push_back(acc_x);
    ay.push_back(acc_y);
    az.push_back(acc_z);
    gx.push_back(gyr_x);
    gy.push_back(gyr_y);
    gz.push_back(gyr_z);
    offsets.push_back(offset);
  }
  std::size_t size() const { return t.size(); }
};

// A scalar signal to be interpolated onto the IMU times.
struct Signal {
  std::string name;
  std::vector<double> t, v;
  bool is_angle = false;
};

// Linear interpolation of `signal` onto `times` (clamped at the ends).
// Angles are unwrapped first and wrapped back to (-pi, pi].
std::vector<double> Interpolate(const Signal& signal,
                                const std::vector<double>& times) {
  std::vector<double> v = signal.v;
  if (signal.is_angle) {
    for (std::size_t i = 1; i < v.size(); ++i) {
      const double step = v[i] - v[i - 1];
      v[i] -= 2 * kPi * std::round(step / (2 * kPi));
    }
  }
  std::vector<double> out;
  out.reserve(times.size());
  std::size_t j = 0;
  for (double t : times) {
    while (j + 1 < signal.t.size() && signal.t[j + 1] <= t) ++j;
    double value;
    if (t <= signal.t.front()) {
      value = v.front();
    } else if (j + 1 >= signal.t.size()) {
      value = v.back();
    } else {
      const double w = (t - signal.t[j]) / (signal.t[j + 1] - signal.t[j]);
      value = v[j] + w * (v[j + 1] - v[j]);
    }
    if (signal.is_angle) value = std::remainder(value, 2 * kPi);
    out.push_back(value);
  }
  return out;
}

// Drops non-finite and non-increasing samples of a source signal, returning
// how many were dropped.
std::size_t CleanSignal(Signal* signal) {
  std::size_t kept = 0, dropped = 0;
  for (std::size_t i = 0; i < signal->t.size(); ++i) {
    const bool ok = std::isfinite(signal->t[i]) &&
                    std::isfinite(signal->v[i]) &&
                    (kept == 0 || signal->t[i] > signal->t[kept - 1]);
    if (!ok) {
      ++dropped;
      continue;
    }
    signal->t[kept] = signal->t[i];
    signal->v[kept] = signal->v[i];
    ++kept;
  }
  signal->t.resize(kept);
  signal->v.resize(kept);
  return dropped;
}

// Adds the canonical channels whose source covers the IMU span; notes the
// others in metadata.
void AddChannels(std::vector<Signal> signals, FlightLog* log) {
  if (log->t_s.empty()) return;
  const double first = log->t_s.front();
  const double last = log->t_s.back();
  for (Signal& signal : signals) {
    const std::size_t dropped = CleanSignal(&signal);
    if (dropped > 0) {
      log->metadata.emplace_back("channel_" + signal.name + "_dropped_samples",
                                 std::to_string(dropped) +
                                     " non-finite or non-increasing source "
                                     "samples ignored");
    }
    if (signal.t.size() < 2) {
      log->metadata.emplace_back("channel_" + signal.name + "_missing",
                                 "source has fewer than 2 valid samples");
      continue;
    }
    const double tolerance = kCoverageIntervals * MedianInterval(signal.t);
    if (signal.t.front() > first + tolerance ||
        signal.t.back() < last - tolerance) {
      log->metadata.emplace_back(
          "channel_" + signal.name + "_missing",
          "source covers " + FormatNumber(signal.t.front(), 8) + ".." +
              FormatNumber(signal.t.back(), 8) + " s, IMU " +
              FormatNumber(first, 8) + ".." + FormatNumber(last, 8) + " s");
      continue;
    }
    log->extra.push_back({signal.name, Interpolate(signal, log->t_s)});
  }
}

// The checks every binary log gets, then FRD → FLU.
StatusOr<FlightLog> FinishImu(ImuSeries imu,
                              const std::string& source,
                              const std::string& what,
                              const LogReadOptions& options,
                              FlightLog log) {
  const std::string prefix = source + ": ";
  std::size_t duplicates = 0;
  ImuSeries clean;
  for (std::size_t i = 0; i < imu.size(); ++i) {
    const double values[] = {imu.t[i],
                             imu.ax[i],
                             imu.ay[i],
                             imu.az[i],
                             imu.gx[i],
                             imu.gy[i],
                             imu.gz[i]};
    for (double value : values) {
      if (!std::isfinite(value)) {
        return InvalidArgumentError(
            prefix + "byte " + std::to_string(imu.offsets[i]) + ": " + what +
            " sample " + std::to_string(i) + " has a non-finite value");
      }
    }
    if (!clean.t.empty()) {
      const double previous = clean.t.back();
      if (imu.t[i] == previous) {
        // Same time stamp twice: the later sample is dropped and counted.
        ++duplicates;
        continue;
      }
      if (imu.t[i] < previous) {
        return InvalidArgumentError(
            prefix + "byte " + std::to_string(imu.offsets[i]) + ": " + what +
            " time " + FormatNumber(imu.t[i], 12) +
            " s is before the previous sample's " + FormatNumber(previous, 12) +
            " s");
      }
    }
    clean.Add(imu.t[i],
              imu.ax[i],
              imu.ay[i],
              imu.az[i],
              imu.gx[i],
              imu.gy[i],
              imu.gz[i],
              imu.offsets[i]);
  }
  log.metadata.emplace_back("imu_duplicate_times_dropped",
                            std::to_string(duplicates));
  if (clean.size() < options.min_samples) {
    return InvalidArgumentError(
        prefix + what + " has " + std::to_string(clean.size()) +
        " usable samples, fewer than the " +
        std::to_string(options.min_samples) + " the fit needs");
  }
  if (options.max_gap_factor > 0 && clean.size() >= 2) {
    const double median = MedianInterval(clean.t);
    const double limit = options.max_gap_factor * median;
    for (std::size_t i = 1; i < clean.size(); ++i) {
      const double gap = clean.t[i] - clean.t[i - 1];
      if (gap <= limit) continue;
      return InvalidArgumentError(
          prefix + "byte " + std::to_string(clean.offsets[i]) + ": " + what +
          " gap of " + FormatNumber(gap, 6) +
          " s from t=" + FormatNumber(clean.t[i - 1], 12) +
          " to t=" + FormatNumber(clean.t[i], 12) + " exceeds " +
          FormatNumber(options.max_gap_factor, 6) + " x the median interval " +
          FormatNumber(median, 6) +
          " s; the log has a hole (raise max_gap_factor, or 0 to accept it)");
    }
  }
  log.source = source;
  log.source_frame = Frame::kFrd;
  log.t_s = std::move(clean.t);
  log.ax = std::move(clean.ax);
  log.gx = std::move(clean.gx);
  log.ay.resize(clean.ay.size());
  log.az.resize(clean.az.size());
  log.gy.resize(clean.gy.size());
  log.gz.resize(clean.gz.size());
  for (std::size_t i = 0; i < log.t_s.size(); ++i) {
    log.ay[i] = -clean.ay[i];
    log.az[i] = -clean.az[i];
    log.gy[i] = -clean.gy[i];
    log.gz[i] = -clean.gz[i];
  }
  return log;
}

// ---------------------------------------------------------------------------
// ULog

std::string UlogVehicle(const UlogData& ulog) {
  std::string vehicle;
  for (const char* key : {"sys_name", "ver_hw"}) {
    if (const UlogInfo* info = ulog.FindInfo(key)) {
      if (!vehicle.empty()) vehicle += " ";
      vehicle += info->value;
    }
  }
  return vehicle;
}

std::vector<double> TopicSeconds(const UlogTopic& topic,
                                 std::string_view field = "timestamp") {
  std::vector<double> t;
  const std::vector<double>* column = topic.FindColumn(field);
  if (column == nullptr) return t;
  t.reserve(column->size());
  for (double us : *column) t.push_back(us * 1e-6);
  return t;
}

Status MissingFields(const std::string& source,
                     const UlogTopic& topic,
                     const std::string& fields) {
  return InvalidArgumentError(source + ": topic '" + topic.name +
                              "' instance " + std::to_string(topic.multi_id) +
                              " lacks the fields " + fields);
}

Status ImuFromSensorCombined(const std::string& source,
                             const UlogTopic& topic,
                             ImuSeries* imu,
                             FlightLog* log) {
  const std::vector<double>* g[3];
  const std::vector<double>* a[3];
  for (int i = 0; i < 3; ++i) {
    g[i] = topic.FindColumn("gyro_rad[" + std::to_string(i) + "]");
    a[i] = topic.FindColumn("accelerometer_m_s2[" + std::to_string(i) + "]");
    if (g[i] == nullptr || a[i] == nullptr ||
        topic.timestamps_us.size() != topic.size()) {
      return MissingFields(
          source, topic, "timestamp, gyro_rad[3], accelerometer_m_s2[3]");
    }
  }
  const std::vector<double>* relative =
      topic.FindColumn("accelerometer_timestamp_relative");
  std::size_t invalid = 0;
  bool shifted = false;
  std::vector<double> accel_t;
  for (std::size_t i = 0; i < topic.size(); ++i) {
    const double rel = relative == nullptr ? 0 : (*relative)[i];
    if (rel == static_cast<double>(kRelativeTimestampInvalid)) {
      ++invalid;
      continue;
    }
    shifted = shifted || rel != 0;
    const double t = static_cast<double>(topic.timestamps_us[i]) * 1e-6;
    accel_t.push_back(t + rel * 1e-6);
    imu->Add(t,
             (*a[0])[i],
             (*a[1])[i],
             (*a[2])[i],
             (*g[0])[i],
             (*g[1])[i],
             (*g[2])[i],
             topic.offsets[i]);
  }
  if (shifted && imu->size() >= 2) {
    // The accelerometer was sampled at timestamp + relative: resample it onto
    // the gyro times so each row describes one instant.
    bool increasing = true;
    for (std::size_t i = 1; i < accel_t.size(); ++i) {
      increasing = increasing && accel_t[i] > accel_t[i - 1];
    }
    if (increasing) {
      for (std::vector<double>* axis : {&imu->ax, &imu->ay, &imu->az}) {
        *axis = Interpolate({"", accel_t, *axis, false}, imu->t);
      }
    }
    log->metadata.emplace_back(
        "imu_accel_time",
        increasing ? "accelerometer resampled from timestamp + "
                     "accelerometer_timestamp_relative onto timestamp"
                   : "accelerometer_timestamp_relative not monotonic; "
                     "accelerometer used at timestamp");
  }
  log->metadata.emplace_back("imu_invalid_accel_samples_skipped",
                             std::to_string(invalid));
  return Status::Ok();
}

Status ImuFromVehicleImu(const std::string& source,
                         const UlogTopic& topic,
                         ImuSeries* imu,
                         FlightLog* log) {
  const std::vector<double>* da[3];
  const std::vector<double>* dv[3];
  for (int i = 0; i < 3; ++i) {
    da[i] = topic.FindColumn("delta_angle[" + std::to_string(i) + "]");
    dv[i] = topic.FindColumn("delta_velocity[" + std::to_string(i) + "]");
  }
  const std::vector<double>* da_dt = topic.FindColumn("delta_angle_dt");
  const std::vector<double>* dv_dt = topic.FindColumn("delta_velocity_dt");
  const std::vector<double>* time = topic.FindColumn("timestamp_sample");
  if (time == nullptr) time = topic.FindColumn("timestamp");
  for (int i = 0; i < 3; ++i) {
    if (da[i] == nullptr || dv[i] == nullptr) da_dt = nullptr;
  }
  if (da_dt == nullptr || dv_dt == nullptr || time == nullptr) {
    return MissingFields(source,
                         topic,
                         "timestamp, delta_angle[3], delta_velocity[3], "
                         "delta_angle_dt, delta_velocity_dt");
  }
  std::size_t skipped = 0;
  for (std::size_t i = 0; i < topic.size(); ++i) {
    const double ta = (*da_dt)[i] * 1e-6;
    const double tv = (*dv_dt)[i] * 1e-6;
    if (!(ta > 0) || !(tv > 0)) {
      ++skipped;
      continue;
    }
    imu->Add((*time)[i] * 1e-6,
             (*dv[0])[i] / tv,
             (*dv[1])[i] / tv,
             (*dv[2])[i] / tv,
             (*da[0])[i] / ta,
             (*da[1])[i] / ta,
             (*da[2])[i] / ta,
             topic.offsets[i]);
  }
  log->metadata.emplace_back("imu_zero_dt_samples_skipped",
                             std::to_string(skipped));
  return Status::Ok();
}

Status ImuFromAccelGyro(const std::string& source,
                        const UlogTopic& accel,
                        const UlogTopic& gyro,
                        ImuSeries* imu,
                        FlightLog* log) {
  const std::vector<double>* a[3] = {
      accel.FindColumn("x"), accel.FindColumn("y"), accel.FindColumn("z")};
  const std::vector<double>* g[3] = {
      gyro.FindColumn("x"), gyro.FindColumn("y"), gyro.FindColumn("z")};
  const bool accel_has_sample = accel.FindColumn("timestamp_sample") != nullptr;
  const bool gyro_has_sample = gyro.FindColumn("timestamp_sample") != nullptr;
  const std::vector<double> ta =
      TopicSeconds(accel, accel_has_sample ? "timestamp_sample" : "timestamp");
  const std::vector<double> tg =
      TopicSeconds(gyro, gyro_has_sample ? "timestamp_sample" : "timestamp");
  for (int i = 0; i < 3; ++i) {
    if (a[i] == nullptr || ta.size() != accel.size()) {
      return MissingFields(source, accel, "timestamp, x, y, z");
    }
    if (g[i] == nullptr || tg.size() != gyro.size()) {
      return MissingFields(source, gyro, "timestamp, x, y, z");
    }
  }
  if (ta.empty() || tg.empty()) return Status::Ok();
  // Pair each gyro sample with the nearest accelerometer sample; pairs
  // further apart than one median interval are not the same instant.
  const double tolerance = std::max(MedianInterval(ta), MedianInterval(tg));
  std::size_t unpaired = 0;
  std::size_t j = 0;
  double max_offset = 0;
  for (std::size_t i = 0; i < tg.size(); ++i) {
    while (j + 1 < ta.size() &&
           std::abs(ta[j + 1] - tg[i]) <= std::abs(ta[j] - tg[i])) {
      ++j;
    }
    const double offset = std::abs(ta[j] - tg[i]);
    if (!(offset <= tolerance)) {
      ++unpaired;
      continue;
    }
    max_offset = std::max(max_offset, offset);
    imu->Add(tg[i],
             (*a[0])[j],
             (*a[1])[j],
             (*a[2])[j],
             (*g[0])[i],
             (*g[1])[i],
             (*g[2])[i],
             gyro.offsets[i]);
  }
  log->metadata.emplace_back("imu_unpaired_gyro_samples_dropped",
                             std::to_string(unpaired));
  log->metadata.emplace_back("imu_max_pairing_offset_s",
                             FormatNumber(max_offset, 6));
  return Status::Ok();
}

std::vector<Signal> UlogChannels(const UlogData& ulog) {
  std::vector<Signal> signals;
  if (const UlogTopic* pos = ulog.FindTopic("vehicle_local_position", 0)) {
    const std::vector<double> t = TopicSeconds(*pos);
    const char* fields[] = {"vx", "vy", "vz"};
    const char* names[] = {kChannelVelN, kChannelVelE, kChannelVelD};
    for (int i = 0; i < 3; ++i) {
      const std::vector<double>* column = pos->FindColumn(fields[i]);
      if (column != nullptr && t.size() == column->size()) {
        signals.push_back({names[i], t, *column, false});
      }
    }
  }
  if (const UlogTopic* att = ulog.FindTopic("vehicle_attitude", 0)) {
    const std::vector<double> t = TopicSeconds(*att);
    const std::vector<double>* q[4];
    bool ok = t.size() == att->size();
    for (int i = 0; i < 4; ++i) {
      q[i] = att->FindColumn("q[" + std::to_string(i) + "]");
      ok = ok && q[i] != nullptr;
    }
    if (ok) {
      Signal roll{kChannelRoll, t, {}, true};
      Signal pitch{kChannelPitch, t, {}, false};
      Signal yaw{kChannelYaw, t, {}, true};
      for (std::size_t i = 0; i < t.size(); ++i) {
        const double w = (*q[0])[i], x = (*q[1])[i], y = (*q[2])[i],
                     z = (*q[3])[i];
        // ZYX Euler angles of the FRD → NED rotation.
        roll.v.push_back(
            std::atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y)));
        pitch.v.push_back(
            std::asin(std::clamp(2 * (w * y - z * x), -1.0, 1.0)));
        yaw.v.push_back(
            std::atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z)));
      }
      signals.push_back(std::move(roll));
      signals.push_back(std::move(pitch));
      signals.push_back(std::move(yaw));
    }
  }
  return signals;
}

std::string TopicList(const UlogData& ulog) {
  std::string list;
  for (const UlogTopic& topic : ulog.topics) {
    if (!list.empty()) list += ", ";
    list += topic.name + "[" + std::to_string(topic.multi_id) + "]";
  }
  return list.empty() ? "(none)" : list;
}

bool PlainValue(const std::string& value) {
  return value.size() <= kMaxMetadataValueChars &&
         value.find_first_of("\r\n") == std::string::npos;
}

// ---------------------------------------------------------------------------
// DataFlash

// The time column of a message in seconds, or empty.
std::vector<double> MessageSeconds(const DataFlashMessage& message) {
  std::vector<double> t;
  double scale = 1e-6;
  const std::vector<double>* column = message.FindColumn("TimeUS");
  if (column == nullptr) {
    column = message.FindColumn("TimeMS");
    scale = 1e-3;
  }
  if (column == nullptr) return t;
  t.reserve(column->size());
  for (double value : *column) t.push_back(value * scale);
  return t;
}

std::string DataFlashVehicle(const DataFlashLog& log) {
  for (const std::string& text : log.texts) {
    if (text.rfind("Ardu", 0) == 0 || text.rfind("APM:", 0) == 0) return text;
  }
  return log.texts.empty() ? std::string() : log.texts.front();
}

std::string MessageList(const DataFlashLog& log) {
  std::string list;
  for (const DataFlashMessage& message : log.messages) {
    if (message.size() == 0) continue;
    if (!list.empty()) list += ", ";
    list += message.name;
  }
  return list.empty() ? "(none)" : list;
}

// Rows of `message` to use: those whose core/instance column `field` equals
// `value` when that column exists, all otherwise.
std::vector<std::size_t> SelectRows(const DataFlashMessage& message,
                                    std::string_view field,
                                    double value) {
  std::vector<std::size_t> rows;
  const std::vector<double>* column = message.FindColumn(field);
  for (std::size_t i = 0; i < message.size(); ++i) {
    if (column == nullptr || (*column)[i] == value) rows.push_back(i);
  }
  return rows;
}

std::vector<Signal> DataFlashChannels(const DataFlashLog& log) {
  std::vector<Signal> signals;
  for (const char* name : {"XKF1", "NKF1", "EKF1"}) {
    const DataFlashMessage* ekf = log.FindMessage(name);
    if (ekf == nullptr || ekf->size() < 2) continue;
    const std::vector<double> t = MessageSeconds(*ekf);
    if (t.size() != ekf->size()) continue;
    // Newer EKF messages interleave cores; core 0 is the primary.
    const std::vector<std::size_t> rows = SelectRows(*ekf, "C", 0);
    const char* fields[] = {"VN", "VE", "VD"};
    const char* channels[] = {kChannelVelN, kChannelVelE, kChannelVelD};
    for (int k = 0; k < 3; ++k) {
      const std::vector<double>* column = ekf->FindColumn(fields[k]);
      if (column == nullptr) continue;
      Signal signal{channels[k], {}, {}, false};
      for (std::size_t row : rows) {
        signal.t.push_back(t[row]);
        signal.v.push_back((*column)[row]);
      }
      signals.push_back(std::move(signal));
    }
    break;
  }
  if (const DataFlashMessage* att = log.FindMessage("ATT")) {
    const std::vector<double> t = MessageSeconds(*att);
    const char* fields[] = {"Roll", "Pitch", "Yaw"};
    const char* channels[] = {kChannelRoll, kChannelPitch, kChannelYaw};
    for (int k = 0; k < 3; ++k) {
      const std::vector<double>* column = att->FindColumn(fields[k]);
      if (column == nullptr || t.size() != column->size()) continue;
      Signal signal{channels[k], t, {}, k != 1};
      for (double degrees : *column) signal.v.push_back(degrees * kPi / 180);
      signals.push_back(std::move(signal));
    }
  }
  return signals;
}

// Time (s) of the last IMU record before byte `offset` (old EV records carry
// no time; old GPS records keep GPS time in TimeMS); nullopt if none.
std::optional<double> TimeBefore(const DataFlashMessage* imu,
                                 const std::vector<double>& imu_t,
                                 std::uint64_t offset) {
  if (imu == nullptr || imu_t.size() != imu->offsets.size()) {
    return std::nullopt;
  }
  auto it = std::lower_bound(imu->offsets.begin(), imu->offsets.end(), offset);
  if (it == imu->offsets.begin()) return std::nullopt;
  return imu_t[static_cast<std::size_t>(it - imu->offsets.begin()) - 1];
}

const char* CopterModeName(int mode) {
  switch (mode) {
    case 0:
      return "STABILIZE";
    case 1:
      return "ACRO";
    case 2:
      return "ALT_HOLD";
    case 3:
      return "AUTO";
    case 4:
      return "GUIDED";
    case 5:
      return "LOITER";
    case 6:
      return "RTL";
    case 7:
      return "CIRCLE";
    case 9:
      return "LAND";
    case 11:
      return "DRIFT";
    case 13:
      return "SPORT";
    case 14:
      return "FLIP";
    case 15:
      return "AUTOTUNE";
    case 16:
      return "POSHOLD";
    case 17:
      return "BRAKE";
    default:
      return nullptr;
  }
}

// Turns (time, on/off) transitions into spans ending at `end`.
void AppendSpans(const std::vector<std::pair<double, std::string>>& changes,
                 double end,
                 std::vector<LogSegment>* spans) {
  for (std::size_t i = 0; i < changes.size(); ++i) {
    if (changes[i].second.empty()) continue;
    const double stop = i + 1 < changes.size() ? changes[i + 1].first : end;
    spans->push_back({changes[i].first, stop, changes[i].second});
  }
}

TopicSummary Summarize(std::string name,
                       int instance,
                       const std::vector<double>& t,
                       std::size_t count,
                       std::vector<std::string> fields) {
  TopicSummary topic;
  topic.name = std::move(name);
  topic.instance = instance;
  topic.count = count;
  topic.fields = std::move(fields);
  if (!t.empty()) {
    topic.first_t_s = t.front();
    topic.last_t_s = t.back();
    const double median = MedianInterval(t);
    topic.rate_hz = median > 0 ? 1 / median : 0;
  }
  return topic;
}

LogSummary SummarizeUlog(const UlogData& ulog) {
  LogSummary summary;
  summary.format = "ulog";
  summary.vehicle = UlogVehicle(ulog);
  double first = 0, last = 0;
  bool any = false;
  for (const UlogTopic& topic : ulog.topics) {
    const std::vector<double> t = TopicSeconds(topic);
    summary.topics.push_back(Summarize(
        topic.name, topic.multi_id, t, topic.size(), topic.field_names));
    if (!t.empty()) {
      first = any ? std::min(first, t.front()) : t.front();
      last = any ? std::max(last, t.back()) : t.back();
      any = true;
    }
  }
  summary.duration_s = last - first;
  for (const char* imu : {"sensor_combined", "sensor_gyro", "vehicle_imu"}) {
    if (const UlogTopic* topic = ulog.FindTopic(imu, 0)) {
      if (topic->timestamps_us.size() >= 2) {
        // Spans end with the IMU data: stray topics (mission) can carry
        // timestamps far outside the flight.
        last = static_cast<double>(topic->timestamps_us.back()) * 1e-6;
        summary.duration_s =
            last - static_cast<double>(topic->timestamps_us.front()) * 1e-6;
        break;
      }
    }
  }
  summary.dropouts = ulog.dropout_count;
  summary.dropout_total_ms = ulog.dropout_total_ms;
  for (const UlogInfo& info : ulog.info) {
    summary.info.emplace_back(info.key, info.value);
  }
  summary.info.emplace_back("parameters",
                            std::to_string(ulog.parameters.size()));
  for (const UlogLoggedString& s : ulog.logged_strings) {
    if (summary.messages.size() >= kMaxSummaryMessages) break;
    summary.messages.push_back(FormatNumber(s.timestamp_us * 1e-6, 9) + " s [" +
                               std::to_string(s.level) + "] " + s.text);
  }
  if (const UlogTopic* status = ulog.FindTopic("vehicle_status", 0)) {
    const std::vector<double> t = TopicSeconds(*status);
    const std::vector<double>* arming = status->FindColumn("arming_state");
    const std::vector<double>* nav = status->FindColumn("nav_state");
    std::vector<std::pair<double, std::string>> armed_changes, mode_changes;
    for (std::size_t i = 0; i < t.size(); ++i) {
      if (arming != nullptr) {
        std::string label = (*arming)[i] == kPx4ArmingStateArmed ? "armed" : "";
        if (armed_changes.empty() || armed_changes.back().second != label) {
          armed_changes.emplace_back(t[i], label);
        }
      }
      if (nav != nullptr) {
        std::string label =
            "nav_state " + std::to_string(static_cast<int>((*nav)[i]));
        if (mode_changes.empty() || mode_changes.back().second != label) {
          mode_changes.emplace_back(t[i], label);
        }
      }
    }
    AppendSpans(armed_changes, last, &summary.armed);
    AppendSpans(mode_changes, last, &summary.modes);
  }
  summary.warnings = ulog.warnings;
  return summary;
}

LogSummary SummarizeDataFlash(const DataFlashLog& log) {
  LogSummary summary;
  summary.format = "dataflash";
  summary.vehicle = DataFlashVehicle(log);
  double first = 0, last = 0;
  bool any = false;
  for (const DataFlashMessage& message : log.messages) {
    if (message.size() == 0) continue;
    const std::vector<double> t = MessageSeconds(message);
    std::vector<std::string> fields = message.column_names;
    fields.insert(fields.end(),
                  message.string_column_names.begin(),
                  message.string_column_names.end());
    summary.topics.push_back(
        Summarize(message.name, 0, t, message.size(), std::move(fields)));
    if (!t.empty()) {
      first = any ? std::min(first, t.front()) : t.front();
      last = any ? std::max(last, t.back()) : t.back();
      any = true;
    }
  }
  summary.duration_s = last - first;
  if (const DataFlashMessage* imu = log.FindMessage("IMU")) {
    const std::vector<double> t = MessageSeconds(*imu);
    if (t.size() >= 2) {
      // Old GPS records keep GPS time of week in TimeMS; the IMU clock is the
      // boot clock every other record uses.
      summary.duration_s = t.back() - t.front();
      last = t.back();
    }
  }
  for (const std::string& text : log.texts) {
    if (summary.messages.size() < kMaxSummaryMessages) {
      summary.messages.push_back(text);
    }
  }
  summary.info.emplace_back("firmware", summary.vehicle);
  summary.info.emplace_back("parameters",
                            std::to_string(log.parameters.size()));
  const bool copter = summary.vehicle.find("Copter") != std::string::npos;
  // Arming: ARM records (newer firmware) or EV ids 10/11.
  std::vector<std::pair<double, std::string>> armed_changes;
  if (const DataFlashMessage* arm = log.FindMessage("ARM")) {
    const std::vector<double> t = MessageSeconds(*arm);
    const std::vector<double>* state = arm->FindColumn("ArmState");
    for (std::size_t i = 0; state != nullptr && i < t.size(); ++i) {
      armed_changes.emplace_back(t[i], (*state)[i] != 0 ? "armed" : "");
    }
  }
  if (armed_changes.empty()) {
    if (const DataFlashMessage* ev = log.FindMessage("EV")) {
      const std::vector<double>* id = ev->FindColumn("Id");
      const std::vector<double> t = MessageSeconds(*ev);
      const DataFlashMessage* imu = log.FindMessage("IMU");
      const std::vector<double> imu_t =
          imu == nullptr ? std::vector<double>() : MessageSeconds(*imu);
      for (std::size_t i = 0; id != nullptr && i < ev->size(); ++i) {
        if ((*id)[i] != kArduEventArmed && (*id)[i] != kArduEventDisarmed) {
          continue;
        }
        std::optional<double> time =
            t.empty() ? TimeBefore(imu, imu_t, ev->offsets[i]) : t[i];
        if (time) {
          armed_changes.emplace_back(
              *time, (*id)[i] == kArduEventArmed ? "armed" : "");
        }
      }
    }
  }
  AppendSpans(armed_changes, last, &summary.armed);
  if (const DataFlashMessage* mode = log.FindMessage("MODE")) {
    const std::vector<double> t = MessageSeconds(*mode);
    const std::vector<double>* number = mode->FindColumn("Mode");
    std::vector<std::pair<double, std::string>> changes;
    for (std::size_t i = 0; number != nullptr && i < t.size(); ++i) {
      const int value = static_cast<int>((*number)[i]);
      const char* name = copter ? CopterModeName(value) : nullptr;
      changes.emplace_back(t[i],
                           name != nullptr ? std::string(name)
                                           : "mode " + std::to_string(value));
    }
    AppendSpans(changes, last, &summary.modes);
  }
  summary.warnings = log.warnings;
  return summary;
}

}  // namespace

const char* LogFormatToString(LogFormat format) {
  switch (format) {
    case LogFormat::kUlog:
      return "ulog";
    case LogFormat::kDataFlash:
      return "dataflash";
    case LogFormat::kCsv:
      return "csv";
  }
  return "csv";
}

LogFormat DetectLogFormat(std::string_view bytes) {
  if (LooksLikeUlog(bytes)) return LogFormat::kUlog;
  if (LooksLikeDataFlash(bytes)) return LogFormat::kDataFlash;
  return LogFormat::kCsv;
}

StatusOr<FlightLog> UlogToFlightLog(const UlogData& ulog,
                                    const std::string& source,
                                    const LogReadOptions& options) {
  FlightLog log;
  log.metadata.emplace_back("format", "ulog");
  log.metadata.emplace_back("vehicle", UlogVehicle(ulog));
  const int instance = options.imu_instance;
  ImuSeries imu;
  std::string what;
  const UlogTopic* combined =
      instance == 0 ? ulog.FindTopic("sensor_combined", 0) : nullptr;
  const UlogTopic* vehicle_imu = ulog.FindTopic("vehicle_imu", instance);
  const UlogTopic* accel = ulog.FindTopic("sensor_accel", instance);
  const UlogTopic* gyro = ulog.FindTopic("sensor_gyro", instance);
  if (combined != nullptr && combined->size() > 0) {
    what = "sensor_combined";
    IMUSYSID_RETURN_IF_ERROR(
        ImuFromSensorCombined(source, *combined, &imu, &log));
  } else if (vehicle_imu != nullptr && vehicle_imu->size() > 0) {
    what = "vehicle_imu";
    IMUSYSID_RETURN_IF_ERROR(
        ImuFromVehicleImu(source, *vehicle_imu, &imu, &log));
  } else if (accel != nullptr && gyro != nullptr && accel->size() > 0 &&
             gyro->size() > 0) {
    what = "sensor_accel+sensor_gyro";
    IMUSYSID_RETURN_IF_ERROR(
        ImuFromAccelGyro(source, *accel, *gyro, &imu, &log));
  } else {
    return NotFoundError(
        source + ": no IMU data for instance " + std::to_string(instance) +
        " (looked for " + (instance == 0 ? "sensor_combined, " : "") +
        "vehicle_imu, sensor_accel + sensor_gyro with multi_id " +
        std::to_string(instance) + "); topics: " + TopicList(ulog));
  }
  log.metadata.emplace_back("imu_source", what);
  log.metadata.emplace_back("imu_instance", std::to_string(instance));
  log.metadata.emplace_back("ulog_version", std::to_string(ulog.version));
  log.metadata.emplace_back("dropouts", std::to_string(ulog.dropout_count));
  log.metadata.emplace_back("dropout_total_ms",
                            FormatNumber(ulog.dropout_total_ms, 9));
  log.metadata.emplace_back("reader_warnings",
                            std::to_string(ulog.warnings.size()));
  for (const UlogInfo& info : ulog.info) {
    // Identity fields only; boot logs and perf counters stay in the summary.
    const bool identity =
        info.key.rfind("sys_", 0) == 0 || info.key.rfind("ver_", 0) == 0;
    if (identity && PlainValue(info.value) &&
        log.FindMetadata(info.key) == nullptr) {
      log.metadata.emplace_back(info.key, info.value);
    }
  }
  StatusOr<FlightLog> finished =
      FinishImu(std::move(imu), source, what, options, std::move(log));
  if (!finished.ok()) return finished;
  AddChannels(UlogChannels(ulog), &finished.value());
  return finished;
}

StatusOr<FlightLog> DataFlashToFlightLog(const DataFlashLog& df,
                                         const std::string& source,
                                         const LogReadOptions& options) {
  FlightLog log;
  log.metadata.emplace_back("format", "dataflash");
  log.metadata.emplace_back("vehicle", DataFlashVehicle(df));
  const int instance = options.imu_instance;
  const DataFlashMessage* message = df.FindMessage("IMU");
  std::string what;
  std::vector<std::size_t> rows;
  if (message != nullptr && message->FindColumn("I") != nullptr) {
    what = "IMU[I=" + std::to_string(instance) + "]";
    rows = SelectRows(*message, "I", instance);
  } else {
    what = instance == 0 ? "IMU" : "IMU" + std::to_string(instance + 1);
    message = df.FindMessage(what);
    if (message != nullptr) rows = SelectRows(*message, "", 0);
  }
  if (message == nullptr || rows.empty()) {
    return NotFoundError(source + ": no IMU data for instance " +
                         std::to_string(instance) + " (looked for " + what +
                         "); messages: " + MessageList(df));
  }
  const std::vector<double> t = MessageSeconds(*message);
  const char* names[] = {"AccX", "AccY", "AccZ", "GyrX", "GyrY", "GyrZ"};
  const std::vector<double>* c[6];
  for (int k = 0; k < 6; ++k) {
    c[k] = message->FindColumn(names[k]);
    if (c[k] == nullptr || t.size() != message->size()) {
      return InvalidArgumentError(
          source + ": byte " + std::to_string(message->fmt_offset) +
          ": message '" + message->name +
          "' lacks TimeUS/TimeMS, GyrX..GyrZ or AccX..AccZ");
    }
  }
  ImuSeries imu;
  for (std::size_t row : rows) {
    imu.Add(t[row],
            (*c[0])[row],
            (*c[1])[row],
            (*c[2])[row],
            (*c[3])[row],
            (*c[4])[row],
            (*c[5])[row],
            message->offsets[row]);
  }
  log.metadata.emplace_back("imu_source", what);
  log.metadata.emplace_back("imu_instance", std::to_string(instance));
  log.metadata.emplace_back(
      "time_base",
      message->FindColumn("TimeUS") != nullptr ? "TimeUS" : "TimeMS");
  log.metadata.emplace_back("reader_warnings",
                            std::to_string(df.warnings.size()));
  StatusOr<FlightLog> finished =
      FinishImu(std::move(imu), source, what, options, std::move(log));
  if (!finished.ok()) return finished;
  AddChannels(DataFlashChannels(df), &finished.value());
  return finished;
}

StatusOr<FlightLog> ParseFlightLog(std::string_view bytes,
                                   const std::string& name,
                                   const LogReadOptions& options) {
  switch (DetectLogFormat(bytes)) {
    case LogFormat::kUlog: {
      // Only the topics the conversion reads are decoded.
      UlogReadOptions ulog_options;
      ulog_options.topics = {"sensor_combined",
                             "vehicle_imu",
                             "sensor_accel",
                             "sensor_gyro",
                             "vehicle_local_position",
                             "vehicle_attitude"};
      StatusOr<UlogData> ulog = ParseUlog(bytes, name, ulog_options);
      if (!ulog.ok()) return ulog.status();
      return UlogToFlightLog(*ulog, name, options);
    }
    case LogFormat::kDataFlash: {
      StatusOr<DataFlashLog> df = ParseDataFlash(bytes, name);
      if (!df.ok()) return df.status();
      return DataFlashToFlightLog(*df, name, options);
    }
    case LogFormat::kCsv:
      break;
  }
  CsvReadOptions csv;
  csv.override_frame = options.override_frame;
  csv.frame = options.frame;
  csv.min_samples = options.min_samples;
  csv.max_gap_factor = options.max_gap_factor;
  return ParseCsvLog(bytes, name, csv);
}

StatusOr<FlightLog> ReadFlightLog(const std::string& path,
                                  const LogReadOptions& options) {
  StatusOr<std::string> read = ReadFileToString(path);
  if (!read.ok()) return read.status();
  const std::string& bytes = *read;
  if (DetectLogFormat(bytes) == LogFormat::kCsv) {
    CsvReadOptions csv;
    csv.override_frame = options.override_frame;
    csv.frame = options.frame;
    csv.min_samples = options.min_samples;
    csv.max_gap_factor = options.max_gap_factor;
    return ReadCsvLog(path, csv);
  }
  return ParseFlightLog(bytes, path, options);
}

StatusOr<LogSummary> SummarizeLogBytes(std::string_view bytes,
                                       const std::string& name) {
  switch (DetectLogFormat(bytes)) {
    case LogFormat::kUlog: {
      StatusOr<UlogData> ulog = ParseUlog(bytes, name);
      if (!ulog.ok()) return ulog.status();
      return SummarizeUlog(*ulog);
    }
    case LogFormat::kDataFlash: {
      StatusOr<DataFlashLog> df = ParseDataFlash(bytes, name);
      if (!df.ok()) return df.status();
      return SummarizeDataFlash(*df);
    }
    case LogFormat::kCsv:
      break;
  }
  CsvReadOptions csv;
  csv.min_samples = 0;
  csv.max_gap_factor = 0;
  StatusOr<FlightLog> log = ParseCsvLog(bytes, name, csv);
  if (!log.ok()) return log.status();
  LogSummary summary;
  summary.format = "csv";
  std::vector<std::string> fields = {"t", "ax", "ay", "az", "gx", "gy", "gz"};
  for (const Channel& channel : log->extra) fields.push_back(channel.name);
  summary.topics.push_back(
      Summarize("csv", 0, log->t_s, log->size(), std::move(fields)));
  if (log->size() >= 2) summary.duration_s = log->t_s.back() - log->t_s.front();
  summary.info = log->metadata;
  if (const std::string* vehicle = log->FindMetadata("vehicle")) {
    summary.vehicle = *vehicle;
  }
  return summary;
}

StatusOr<LogSummary> SummarizeLog(const std::string& path) {
  StatusOr<std::string> bytes = ReadFileToString(path);
  if (!bytes.ok()) return bytes.status();
  return SummarizeLogBytes(*bytes, path);
}

}  // namespace imusysid

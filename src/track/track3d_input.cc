// The tracker's inputs (include/imusysid/track3d.h): a flight log's samples
// with the estimator's track at each, and a 3-D CSV streamed line by line.

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "imusysid/log.h"
#include "imusysid/track3d.h"
#include "src/io/csv_log.h"
#include "src/io/csv_text.h"
#include "src/preprocess/preprocess3d_internal.h"
#include "src/tools/format.h"

namespace imusysid {
namespace {

constexpr const char* kColumns[14] = {"t",
                                      "ax",
                                      "ay",
                                      "az",
                                      "gx",
                                      "gy",
                                      "gz",
                                      "qw",
                                      "qx",
                                      "qy",
                                      "qz",
                                      "vn",
                                      "ve",
                                      "vd"};

std::string Trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

}  // namespace

StatusOr<Track3dLog> Track3dSamplesOfLog(std::shared_ptr<const FlightLog> log) {
  StatusOr<internal::EstimatorTrack> track = internal::ReadEstimator(*log);
  if (!track.ok()) return track.status();
  const double dt = log->MedianDt();
  if (!(dt > 0.0)) {
    return InvalidArgumentError(log->source + ": fewer than two samples");
  }
  auto shared = std::make_shared<internal::EstimatorTrack>(std::move(*track));
  Track3dLog out;
  out.rate_hz = 1.0 / dt;
  out.size = log->size();
  out.sample = [log, shared](std::size_t k) {
    Track3dSample s;
    s.t_s = log->t_s[k];
    s.accel_frd_mps2 = internal::AccelFrd(*log, k);
    s.gyro_frd_radps = internal::GyroFrd(*log, k);
    s.attitude_wxyz = shared->q[k];
    for (int i = 0; i < 3; ++i) s.velocity_ned_mps[i] = shared->v_ned[i][k];
    return s;
  };
  return out;
}

StatusOr<bool> Track3dCsvStream::Line(const std::string& raw_line,
                                      Track3dSample* sample) {
  ++line_;
  const std::string line = Trim(raw_line);
  const std::string where = "line " + std::to_string(line_);
  if (line.empty()) return false;
  if (line[0] == '#') {
    // The reader's own parse of `# key: value` (a key ends at a colon
    // followed by a blank), so that both take the same lines as metadata.
    std::string_view key, value;
    if (!internal::ParseMetadata(line, &key, &value)) return false;
    if (key == "frame") {
      StatusOr<Frame> frame = FrameFromString(value);
      if (!frame.ok()) {
        return InvalidArgumentError(
            where + ", metadata 'frame': " + frame.status().message());
      }
      if (frame_line_ > 0 && *frame != file_frame_) {
        return InvalidArgumentError(
            where + ", metadata 'frame': " + internal::Quote(value) +
            " contradicts 'frame: " + FrameToString(file_frame_) +
            "' on line " + std::to_string(frame_line_));
      }
      if (frame_line_ == 0) frame_line_ = line_;
      file_frame_ = *frame;
      if (!override_frame_) frame_ = *frame;
    } else if (key == "rate_hz") {
      const std::string text(value);
      char* end = nullptr;
      const double rate = std::strtod(text.c_str(), &end);
      if (text.empty() || end != text.c_str() + text.size() ||
          !std::isfinite(rate) || !(rate > 0.0)) {
        return InvalidArgumentError(
            where + ", metadata 'rate_hz': " + internal::Quote(value) +
            " is not a rate (required a positive number of Hz; the rate is "
            "the time column's, the header only checks it)");
      }
      declared_rate_hz_ = rate;
      declared_rate_line_ = line_;
      declared_rate_text_ = text.substr(0, 64);
      if (rate_hz_ > 0.0) IMUSYSID_RETURN_IF_ERROR(CheckDeclaredRate());
    }
    return false;
  }
  // Split on commas.
  std::string cells[64];
  int n = 0;
  std::size_t start = 0;
  while (n < 64) {
    const std::size_t comma = line.find(',', start);
    cells[n++] = Trim(line.substr(start, comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (!have_header_) {
    for (int c = 0; c < 14; ++c) {
      column_[c] = -1;
      for (int i = 0; i < n; ++i) {
        if (cells[i] == kColumns[c]) column_[c] = i;
      }
      if (column_[c] < 0) {
        return InvalidArgumentError(
            where + ": header has no column '" + kColumns[c] +
            "' (required t,ax,ay,az,gx,gy,gz,qw,qx,qy,qz,vn,ve,vd)");
      }
    }
    num_columns_ = n;
    have_header_ = true;
    return false;
  }
  if (n != num_columns_) {
    return InvalidArgumentError(where + ": " + std::to_string(n) +
                                " fields, the header has " +
                                std::to_string(num_columns_));
  }
  double v[14];
  for (int c = 0; c < 14; ++c) {
    const std::string& cell = cells[column_[c]];
    const std::string field = std::string("field '") + kColumns[c] + "'";
    if (cell.empty() && c >= 7) {
      v[c] = std::nan("");  // the estimator not started yet
      continue;
    }
    char* end = nullptr;
    v[c] = std::strtod(cell.c_str(), &end);
    if (cell.empty() || end != cell.c_str() + cell.size()) {
      return InvalidArgumentError(where + ", " + field + ": " +
                                  internal::Quote(cell) + " is not a number");
    }
    if (!std::isfinite(v[c]) || std::abs(v[c]) > kMaxAbsInputValue) {
      return InvalidArgumentError(where + ", " + field + ": " +
                                  internal::Quote(cell) +
                                  " is not a finite number");
    }
  }
  if (!(v[0] > last_t_)) {
    return InvalidArgumentError(where + ", field 't': time " +
                                internal::Quote(cells[column_[0]]) +
                                " does not increase");
  }
  // Holes in time: at once once the rate is known, else when it is.
  if (median_dt_ > 0.0) {
    if (internal::IsTimeGap(
            last_t_, v[0], median_dt_, CsvReadOptions().max_gap_factor)) {
      return InvalidArgumentError(
          where + ", field 't': " +
          internal::TimeGapMessage(
              last_t_, v[0], median_dt_, CsvReadOptions().max_gap_factor) +
          " (the median of the first " + std::to_string(kRateIntervals) +
          " intervals)");
    }
  } else {
    early_t_[rows_] = v[0];
    early_line_[rows_] = line_;
  }
  ++rows_;
  last_t_ = v[0];
  if (median_dt_ == 0.0 && rows_ == kRateIntervals + 1) {
    IMUSYSID_RETURN_IF_ERROR(SettleRate());
  }
  const bool flu = frame_ == Frame::kFlu;
  const double sign = flu ? -1.0 : 1.0;  // FLU → FRD flips y and z
  sample->t_s = v[0];
  sample->accel_frd_mps2 = Eigen::Vector3d(v[1], sign * v[2], sign * v[3]);
  sample->gyro_frd_radps = Eigen::Vector3d(v[4], sign * v[5], sign * v[6]);
  sample->attitude_wxyz = Eigen::Vector4d(v[7], v[8], v[9], v[10]);
  sample->velocity_ned_mps = Eigen::Vector3d(v[11], v[12], v[13]);
  return true;
}

// The median of the first rows' intervals (as FlightLog::MedianDt), then the
// checks that needed it on those rows.
Status Track3dCsvStream::SettleRate() {
  const int intervals = rows_ - 1;
  std::vector<double> dt(static_cast<std::size_t>(intervals));
  for (int i = 0; i < intervals; ++i) dt[i] = early_t_[i + 1] - early_t_[i];
  const std::size_t mid = dt.size() / 2;
  std::nth_element(dt.begin(), dt.begin() + mid, dt.end());
  median_dt_ = dt[mid];
  if (dt.size() % 2 == 0) {
    median_dt_ =
        0.5 * (median_dt_ + *std::max_element(dt.begin(), dt.begin() + mid));
  }
  rate_hz_ = 1.0 / median_dt_;
  rate_line_ = line_;
  const double factor = CsvReadOptions().max_gap_factor;
  for (int i = 1; i < rows_; ++i) {
    if (internal::IsTimeGap(early_t_[i - 1], early_t_[i], median_dt_, factor)) {
      return InvalidArgumentError(
          "line " + std::to_string(early_line_[i]) + ", field 't': " +
          internal::TimeGapMessage(
              early_t_[i - 1], early_t_[i], median_dt_, factor) +
          " (the median of the first " + std::to_string(intervals) +
          " intervals)");
    }
  }
  if (declared_rate_line_ > 0) return CheckDeclaredRate();
  return Status::Ok();
}

Status Track3dCsvStream::CheckDeclaredRate() const {
  if (std::abs(declared_rate_hz_ - rate_hz_) <= kRateTolerance * rate_hz_) {
    return Status::Ok();
  }
  return InvalidArgumentError(
      "line " + std::to_string(declared_rate_line_) +
      ", metadata 'rate_hz': " + internal::Quote(declared_rate_text_) +
      " Hz disagrees with the time column's " + FormatNumber(rate_hz_, 6) +
      " Hz (the median interval " + FormatNumber(median_dt_, 6) +
      " s of the rows up to line " + std::to_string(rate_line_) +
      "; more than " + FormatNumber(100.0 * kRateTolerance, 3) +
      " % apart): the rows or the header are wrong (fix or remove the "
      "header; the rate is taken from the time column)");
}

Status Track3dCsvStream::Finish() {
  if (rows_ < 2) {
    return InvalidArgumentError("line " + std::to_string(line_) + ": " +
                                std::to_string(rows_) +
                                " data row(s), fewer than the two a rate "
                                "needs");
  }
  if (median_dt_ == 0.0) return SettleRate();
  return Status::Ok();
}

}  // namespace imusysid

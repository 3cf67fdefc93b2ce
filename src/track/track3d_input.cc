// The tracker's inputs (include/imusysid/track3d.h): a flight log's samples
// with the estimator's track at each, and a 3-D CSV streamed line by line.

#include <cmath>
#include <cstdlib>
#include <string>
#include <utility>

#include "imusysid/track3d.h"
#include "src/preprocess/preprocess3d_internal.h"

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
    const std::string body = Trim(line.substr(1));
    if (body.rfind("frame:", 0) == 0) {
      const std::string frame = Trim(body.substr(6));
      if (frame != "flu" && frame != "frd") {
        return InvalidArgumentError(where + ": frame '" + frame +
                                    "'; required flu or frd");
      }
      flu_ = frame == "flu";
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
      return InvalidArgumentError(where + ", " + field + ": '" + cell +
                                  "' is not a number");
    }
    if (!std::isfinite(v[c]) || std::abs(v[c]) > kMaxAbsInputValue) {
      return InvalidArgumentError(where + ", " + field + ": '" + cell +
                                  "' is not a finite number");
    }
  }
  if (!(v[0] > last_t_)) {
    return InvalidArgumentError(where + ", field 't': time " +
                                cells[column_[0]] + " does not increase");
  }
  last_t_ = v[0];
  const double sign = flu_ ? -1.0 : 1.0;  // FLU → FRD flips y and z
  sample->t_s = v[0];
  sample->accel_frd_mps2 = Eigen::Vector3d(v[1], sign * v[2], sign * v[3]);
  sample->gyro_frd_radps = Eigen::Vector3d(v[4], sign * v[5], sign * v[6]);
  sample->attitude_wxyz = Eigen::Vector4d(v[7], v[8], v[9], v[10]);
  sample->velocity_ned_mps = Eigen::Vector3d(v[11], v[12], v[13]);
  return true;
}

}  // namespace imusysid

// The Python extension module _imusysid: converts Python arguments to the
// library's types, calls the public API and converts the result back. The
// Python package imusysid (python/imusysid) wraps it with keyword checking
// and documentation; nothing here decides anything a front end would not.
//
// Copies: read_log and simulate hand out NumPy views of the library's
// vectors (kept alive by a capsule owning the log), without copying;
// fit copies its input arrays once, into the ProblemData the library owns;
// the JSON of a fit crosses as text (json.loads on the Python side).

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "imusysid/identify.h"
#include "imusysid/log.h"
#include "imusysid/log_reader.h"
#include "imusysid/simulate.h"
#include "imusysid/simulate3d.h"
#include "imusysid/status.h"
#include "imusysid/version.h"

namespace py = pybind11;

namespace imusysid {
namespace python {
namespace {

// A library error on its way to Python: raised there as imusysid.Error
// with the library's message and `code` (the StatusCode's name).
class StatusError : public std::exception {
 public:
  explicit StatusError(const Status& status)
      : message_(status.message()), code_(StatusCodeToString(status.code())) {}
  const char* what() const noexcept override { return message_.c_str(); }
  const std::string& code() const { return code_; }

 private:
  std::string message_;
  std::string code_;
};

void ThrowIfError(const Status& status) {
  if (!status.ok()) throw StatusError(status);
}

template <typename T>
T ValueOrThrow(StatusOr<T> value) {
  ThrowIfError(value.status());
  return std::move(*value);
}

// Text from the caller quoted in a message, cut as the tool cuts the
// fields it quotes (40 characters).
std::string ShortPyText(const std::string& text) {
  constexpr std::size_t kMaxPyQuoted = 40;
  return text.size() > kMaxPyQuoted ? text.substr(0, kMaxPyQuoted) + "..."
                                    : text;
}

// The shortest text that reads back to `value` ("nan", "inf" as such).
std::string ShortestPyNumber(double value) {
  char buffer[32];
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buffer, sizeof(buffer), "%.*g", digits, value);
    if (!std::isfinite(value) || std::strtod(buffer, nullptr) == value) break;
  }
  return buffer;
}

// A 1-D NumPy view of `values`; `owner` keeps the memory alive.
py::array View(const std::vector<double>& values, const py::handle& owner) {
  return py::array_t<double>({static_cast<py::ssize_t>(values.size())},
                             {static_cast<py::ssize_t>(sizeof(double))},
                             values.data(),
                             owner);
}

// The arrays of a FlightLog as views, plus its metadata, owned by one
// capsule holding the log.
py::dict LogToDict(std::shared_ptr<const FlightLog> log) {
  const FlightLog& l = *log;
  py::capsule owner(new std::shared_ptr<const FlightLog>(std::move(log)),
                    [](void* p) {
                      delete static_cast<std::shared_ptr<const FlightLog>*>(p);
                    });
  py::dict d;
  d["source"] = l.source;
  d["source_frame"] = FrameToString(l.source_frame);
  d["t"] = View(l.t_s, owner);
  d["ax"] = View(l.ax, owner);
  d["ay"] = View(l.ay, owner);
  d["az"] = View(l.az, owner);
  d["gx"] = View(l.gx, owner);
  d["gy"] = View(l.gy, owner);
  d["gz"] = View(l.gz, owner);
  py::dict channels;
  for (const Channel& c : l.extra)
    channels[py::str(c.name)] = View(c.values, owner);
  d["channels"] = channels;
  py::list metadata;
  for (const auto& [key, value] : l.metadata) {
    metadata.append(py::make_tuple(key, value));
  }
  d["metadata"] = metadata;
  d["reader_warnings"] = l.reader_warnings;
  return d;
}

py::dict ReadLog(const std::string& path, int imu, const std::string& frame) {
  if (imu < 0 || imu > 2) {
    ThrowIfError(InvalidArgumentError(
        "imu=" + std::to_string(imu) +
        "; read_log reads one instance: 0, 1 or 2 (-1, every instance, is "
        "for identify with a 3-D model)"));
  }
  LogReadOptions options;
  options.imu_instance = imu;
  if (!frame.empty()) {
    options.override_frame = true;
    options.frame = ValueOrThrow(FrameFromString(frame));
  }
  std::shared_ptr<FlightLog> log;
  std::vector<std::pair<std::string, double>> parameters;
  {
    py::gil_scoped_release unlocked;
    const std::string bytes = ValueOrThrow(ReadFileToString(path));
    log = std::make_shared<FlightLog>(
        ValueOrThrow(ParseFlightLog(bytes, path, options)));
    parameters = ValueOrThrow(ParseLogParameters(bytes, path));
  }
  py::dict d = LogToDict(std::move(log));
  d["parameters"] = parameters;
  return d;
}

// What identify and fit share: the options a Python call may set.
struct CallOptions {
  std::string model;
  std::vector<std::string> estimators;
  bool all_estimators = false;
  std::uint64_t seed = 1;
  int threads = 1;
  double max_time_s = 0.0;
  std::string covariance = "hac";
  bool use_measured_fz = false;
  bool trace = false;
  std::map<std::string, OptionValue> named;
  // Log inputs only.
  std::optional<int> imu;
  std::string frame;
  bool allow_damaged = false;
  std::string plane = "pitch";
  std::string velocity = "auto";
  std::optional<double> cutoff_hz;
  std::optional<double> t_start;
  std::optional<double> t_end;
};

IdentifyOptions ToIdentifyOptions(const CallOptions& c) {
  IdentifyOptions io;
  io.model = c.model;
  io.estimators = c.estimators;
  io.all_estimators = c.all_estimators;
  EstimatorOptions& eo = io.estimator;
  eo.seed = c.seed;
  if (!std::isfinite(c.max_time_s)) {
    ThrowIfError(
        InvalidArgumentError("max_time_s=" + ShortestPyNumber(c.max_time_s) +
                             ": the value must be a finite number"));
  }
  if (!(c.max_time_s >= 0.0)) {
    ThrowIfError(
        InvalidArgumentError("max_time_s=" + ShortestPyNumber(c.max_time_s) +
                             "; required >= 0 (0: no limit)"));
  }
  if (c.max_time_s > 0.0) eo.max_wall_time_s = c.max_time_s;
  eo.record_trace = c.trace;
  eo.ga.num_threads = c.threads;
  io.num_threads = c.threads;
  eo.covariance = ValueOrThrow(CovarianceTypeFromString(c.covariance));
  eo.named = c.named;
  ThrowIfError(eo.Validate());
  io.model_options.use_measured_fz = c.use_measured_fz;
  if (c.imu) io.imu = *c.imu;
  if (!c.frame.empty()) io.frame = ValueOrThrow(FrameFromString(c.frame));
  io.allow_damaged = c.allow_damaged;
  io.preprocess.plane = ValueOrThrow(PlaneFromString(c.plane));
  io.velocity_auto = c.velocity == "auto";
  if (!io.velocity_auto) {
    io.preprocess.velocity_source =
        ValueOrThrow(VelocitySourceFromString(c.velocity));
  }
  // As the tool's number flags: given, a value must be finite (None is
  // the unset flag); a cutoff also >= 0.
  const std::pair<const char*, const std::optional<double>*> numbers[] = {
      {"cutoff_hz", &c.cutoff_hz},
      {"t_start", &c.t_start},
      {"t_end", &c.t_end}};
  for (const auto& [name, value] : numbers) {
    if (*value && !std::isfinite(**value)) {
      ThrowIfError(InvalidArgumentError(std::string(name) + "=" +
                                        ShortestPyNumber(**value) +
                                        ": the value must be a finite number"));
    }
  }
  if (c.cutoff_hz && !(*c.cutoff_hz >= 0.0)) {
    ThrowIfError(InvalidArgumentError(
        "cutoff_hz=" + ShortestPyNumber(*c.cutoff_hz) + "; required >= 0"));
  }
  if (c.cutoff_hz) {
    io.preprocess.cutoff_hz = *c.cutoff_hz;
    io.preprocess3d.cutoff_hz = *c.cutoff_hz;
  }
  if (c.t_start) {
    io.preprocess.t_start = *c.t_start;
    io.preprocess3d.t_start = *c.t_start;
  }
  if (c.t_end) {
    io.preprocess.t_end = *c.t_end;
    io.preprocess3d.t_end = *c.t_end;
  }
  return io;
}

// Runs Identify without the GIL; returns the summary's JSON text.
std::string RunIdentify(const IdentifyInput& input,
                        const CallOptions& options,
                        std::shared_ptr<IdentifySummary>* summary_out) {
  const IdentifyOptions io = ToIdentifyOptions(options);
  auto summary = std::make_shared<IdentifySummary>();
  std::string text;
  {
    py::gil_scoped_release unlocked;
    *summary = ValueOrThrow(Identify(input, io));
    summary->context.include_trace = options.trace;
    text = IdentifySummaryToJson(*summary, options.all_estimators).dump();
  }
  if (summary_out != nullptr) *summary_out = std::move(summary);
  return text;
}

// identify(path or bytes): the JSON text of `fit --format=json`.
std::string IdentifyLog(const std::string& source,
                        const std::optional<py::bytes>& bytes,
                        const CallOptions& options) {
  const IdentifyInput input =
      bytes ? IdentifyInput::LogBytes(std::string(*bytes), source)
            : IdentifyInput::LogFile(source);
  return RunIdentify(input, options, nullptr);
}

using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;

std::vector<double> ToVector(const std::optional<Doubles>& a,
                             const char* name) {
  if (!a) return {};
  if (a->ndim() != 1) {
    ThrowIfError(
        InvalidArgumentError(ShortPyText(name) + ": a 1-D array is required"));
  }
  return std::vector<double>(a->data(), a->data() + a->size());
}

// fit(arrays): preprocessed planar samples, fitted as they are
// (IdentifyInput::Data). Returns the JSON text and, per result, the full
// estimate and its covariance (nuisance parameters included).
py::tuple FitArrays(const Doubles& t,
                    const Doubles& f_x,
                    const Doubles& omega,
                    const Doubles& omega_dot,
                    const std::optional<Doubles>& v,
                    const std::optional<Doubles>& f_z,
                    const std::optional<Doubles>& theta,
                    const std::string& source,
                    double gravity,
                    const CallOptions& options) {
  // A problem file's '# gravity:' range (problem_io.cc): a typo such as
  // 9806.65 (mm/s^2), a sign or NaN would otherwise be fitted as a gravity.
  if (!(gravity >= 0.1 && gravity <= 100.0)) {
    ThrowIfError(InvalidArgumentError(
        "gravity=" + ShortestPyNumber(gravity) +
        " is outside [0.1, 100] m/s^2; expected the gravity in m/s^2, e.g. "
        "9.80665"));
  }
  auto data = std::make_shared<ProblemData>();
  data->source = source;
  data->gravity = gravity;
  data->t_s = ToVector(t, "t");
  data->planar.f_x = ToVector(f_x, "f_x");
  data->planar.omega = ToVector(omega, "omega");
  data->planar.omega_dot = ToVector(omega_dot, "omega_dot");
  data->planar.v = ToVector(v, "v");
  data->planar.f_z = ToVector(f_z, "f_z");
  data->planar.theta = ToVector(theta, "theta");
  std::shared_ptr<IdentifySummary> summary;
  const std::string text =
      RunIdentify(IdentifyInput::Data(std::move(data)), options, &summary);
  py::list estimates;
  for (const EstimateResult& r : summary->fits) {
    py::dict one;
    one["estimate"] = py::array_t<double>(
        static_cast<py::ssize_t>(r.parameters.size()), r.parameters.data());
    // Eigen is column-major; the covariance is symmetric, so the same bytes
    // read row-major are the same matrix.
    one["covariance"] =
        py::array_t<double>({static_cast<py::ssize_t>(r.covariance.rows()),
                             static_cast<py::ssize_t>(r.covariance.cols())},
                            r.covariance.data());
    std::vector<std::string> names;
    for (const auto& info : r.parameter_info) names.push_back(info.name);
    one["names"] = names;
    estimates.append(one);
  }
  return py::make_tuple(text, estimates);
}

// simulate: a planar or 3-D scenario flown with `seed` and `settings`
// (planar: any SimulatorOptions field by name; 3-D: rate_hz and
// sensor_profile). Returns (logs as dicts of views, truth JSON text, file
// images in `format`: one, or one per IMU for a 3-D CSV).
py::tuple RunSimulate(const std::string& scenario,
                      std::optional<std::uint64_t> seed,
                      const std::map<std::string, std::string>& settings,
                      const std::string& format,
                      const std::string& frame,
                      bool want_files) {
  std::vector<std::shared_ptr<FlightLog>> logs;
  std::string truth;
  std::vector<std::string> files;
  bool three_d = false;
  for (const std::string& name : Scenario3dNames()) {
    if (name == scenario) three_d = true;
  }
  const std::vector<std::string> planar = ScenarioNames();
  if (!three_d &&
      std::find(planar.begin(), planar.end(), scenario) == planar.end()) {
    // ScenarioOptions would list the planar scenarios alone: this takes
    // both kinds, so the message lists both, from the library's lists.
    std::string valid;
    for (const std::string& name : planar) valid += " " + name;
    for (const std::string& name : Scenario3dNames()) valid += " " + name;
    ThrowIfError(NotFoundError("unknown scenario '" + ShortPyText(scenario) +
                               "'; valid names:" + valid));
  }
  if (!three_d) {
    if (!format.empty() && format != "csv") {
      ThrowIfError(InvalidArgumentError("format='" + ShortPyText(format) +
                                        "': the planar scenarios write csv "
                                        "only"));
    }
    SimulatorOptions o = ValueOrThrow(ScenarioOptions(scenario));
    for (const auto& [name, value] : settings) {
      ThrowIfError(SetSimulatorSetting(&o, name, value));
    }
    if (seed) o.seed = *seed;
    ThrowIfError(o.Validate());
    CsvWriteOptions write;
    if (!frame.empty()) write.frame = ValueOrThrow(FrameFromString(frame));
    py::gil_scoped_release unlocked;
    SimulatedFlight flight = ValueOrThrow(Simulate(o));
    truth = TruthJson(o, flight);
    if (want_files)
      files.push_back(ValueOrThrow(FormatCsvLog(flight.log, write)));
    logs.push_back(std::make_shared<FlightLog>(std::move(flight.log)));
  } else {
    Simulator3dOptions o = ValueOrThrow(Scenario3dOptions(scenario));
    const std::string kind = format.empty() ? "csv" : format;
    if (kind != "csv" && kind != "ulog" && kind != "dataflash") {
      ThrowIfError(InvalidArgumentError("format='" + ShortPyText(format) +
                                        "'; valid: csv, ulog, dataflash"));
    }
    // As `imusysid simulate`: realistic sensors, and the binary logs
    // sample the raw IMU at 1 kHz.
    o.sensor_profile = "realistic";
    if (kind != "csv") o.rate_hz = 1000.0;
    for (const auto& [name, value] : settings) {
      if (name == "sensor_profile") {
        o.sensor_profile = value;
      } else if (name == "rate_hz") {
        // The whole text, a finite number (std::stod would take "100abc"
        // and throw on "abc").
        char* end = nullptr;
        o.rate_hz = std::strtod(value.c_str(), &end);
        if (value.empty() || *end != '\0' || !std::isfinite(o.rate_hz)) {
          ThrowIfError(InvalidArgumentError("setting rate_hz='" +
                                            ShortPyText(value) +
                                            "'; required a finite number, Hz"));
        }
      } else {
        ThrowIfError(InvalidArgumentError(
            "setting '" + ShortPyText(name) +
            "': a 3-D scenario takes rate_hz and sensor_profile"));
      }
    }
    if (seed) o.seed = *seed;
    ThrowIfError(o.Validate());
    Sim3dLogOptions log_options;
    log_options.ulog_imu_rate_hz =
        std::min(log_options.ulog_imu_rate_hz, o.rate_hz);
    log_options.dataflash_imu_rate_hz =
        std::min(log_options.dataflash_imu_rate_hz, o.rate_hz);
    if (kind != "csv") ThrowIfError(log_options.Validate(o));
    py::gil_scoped_release unlocked;
    Simulated3dFlight flight = ValueOrThrow(Simulate3d(o));
    truth = Truth3dJson(o, flight);
    if (want_files && kind == "csv") {
      for (const FlightLog& log : flight.logs) {
        files.push_back(ValueOrThrow(FormatSimulated3dCsv(log)));
      }
    } else if (want_files) {
      files.push_back(ValueOrThrow(
          kind == "ulog" ? FormatSimulated3dUlog(o, flight, log_options)
                         : FormatSimulated3dDataFlash(o, flight, log_options)));
    }
    for (FlightLog& log : flight.logs) {
      logs.push_back(std::make_shared<FlightLog>(std::move(log)));
    }
  }
  py::list log_dicts;
  for (auto& log : logs) log_dicts.append(LogToDict(std::move(log)));
  py::list file_bytes;
  for (const std::string& f : files) file_bytes.append(py::bytes(f));
  return py::make_tuple(log_dicts, truth, file_bytes, three_d);
}

// InvalidArgument naming the array and the sample when `values` holds one
// that a CSV log cannot carry: NaN or infinity, except NaN in the rows
// before an estimator channel's first value (the cells the reader takes
// empty). Checked here, on the arrays, so that the message points at
// them and not into the CSV text written from them.
Status CheckLogArray(const std::string& source,
                     const std::string& kind,
                     const std::string& name,
                     const std::vector<double>& values) {
  bool leading_nan_allowed = false;
  for (const char* channel : kEstimatorChannels) {
    if (name == channel) leading_nan_allowed = kind == "channel";
  }
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (std::isnan(values[i]) && leading_nan_allowed) continue;
    leading_nan_allowed = false;
    if (!std::isfinite(values[i])) {
      return InvalidArgumentError(
          source + ": " + kind + " '" + ShortPyText(name) + "' sample " +
          std::to_string(i) + " is " + ShortestPyNumber(values[i]) +
          "; a log's samples must be finite (an estimator channel, " +
          "qw ... vd, may be NaN before its first value)");
    }
  }
  return Status::Ok();
}

// `text` (CSV rows from FormatCsvLog) with every "nan" or "-nan" cell of
// the data rows left empty, as the reader reads an estimator channel's
// cells before its first value (FormatSimulated3dCsv writes them so too).
std::string BlankNanCells(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  bool header_seen = false;
  std::size_t line_start = 0;
  while (line_start < text.size()) {
    std::size_t line_end = text.find('\n', line_start);
    if (line_end == std::string::npos) line_end = text.size();
    const std::string_view line(text.data() + line_start,
                                line_end - line_start);
    if (!header_seen || line.empty() || line[0] == '#') {
      header_seen = header_seen || (!line.empty() && line[0] != '#');
      out.append(line);
    } else {
      std::size_t cell = 0;
      while (cell <= line.size()) {
        std::size_t comma = line.find(',', cell);
        if (comma == std::string_view::npos) comma = line.size();
        const std::string_view value = line.substr(cell, comma - cell);
        if (value != "nan" && value != "-nan") out.append(value);
        if (comma < line.size()) out += ',';
        cell = comma + 1;
      }
    }
    if (line_end < text.size()) out += '\n';
    line_start = line_end + 1;
  }
  return out;
}

// A log given as arrays (what read_log and simulate return) as the CSV
// text Identify reads, in the frame the log came in (`frame`), every value
// written so that it reads back exactly.
py::bytes FormatLog(
    const std::string& source,
    const std::map<std::string, Doubles>& columns,
    const std::map<std::string, Doubles>& channels,
    const std::vector<std::pair<std::string, std::string>>& metadata,
    const std::string& frame) {
  FlightLog log;
  log.source = source;
  log.metadata = metadata;
  for (const auto& [name, values] : log.Columns()) {
    const auto it = columns.find(name);
    if (it == columns.end()) {
      ThrowIfError(InvalidArgumentError(
          source + ": the log has no '" + std::string(name) +
          "' array; a log as arrays is a dict as read_log returns (t, ax, "
          "ay, az, gx, gy, gz) or a simulate result"));
    }
    *values = ToVector(it->second, name);
    ThrowIfError(CheckLogArray(source, "array", name, *values));
  }
  for (std::size_t i = 1; i < log.t_s.size(); ++i) {
    if (!(log.t_s[i] > log.t_s[i - 1])) {
      ThrowIfError(InvalidArgumentError(
          source + ": array 't' sample " + std::to_string(i) + " (" +
          ShortestPyNumber(log.t_s[i]) + ") is not after sample " +
          std::to_string(i - 1) + " (" + ShortestPyNumber(log.t_s[i - 1]) +
          "); time must increase strictly"));
    }
  }
  for (const auto& [name, values] : channels) {
    log.extra.push_back({name, ToVector(values, name.c_str())});
    ThrowIfError(
        CheckLogArray(source, "channel", name, log.extra.back().values));
  }
  CsvWriteOptions write;
  write.precision = 0;  // the shortest text that reads back exactly
  write.frame = ValueOrThrow(FrameFromString(frame));
  std::string text;
  {
    py::gil_scoped_release unlocked;
    text = BlankNanCells(ValueOrThrow(FormatCsvLog(log, write)));
  }
  return py::bytes(text);
}

void WriteFile(const std::string& path, const py::bytes& contents) {
  std::string text(contents);
  py::gil_scoped_release unlocked;
  ThrowIfError(WriteFileAtomically(path, text));
}

}  // namespace
}  // namespace python
}  // namespace imusysid

PYBIND11_MODULE(_imusysid, m) {
  using imusysid::python::CallOptions;
  using imusysid::python::StatusError;
  m.doc() = "imusysid's C++ library; use the imusysid package, not this.";
  m.attr("__version__") = IMUSYSID_VERSION_STRING;

  static py::exception<StatusError> error(m, "Error", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const StatusError& e) {
      py::object instance =
          py::reinterpret_borrow<py::object>(error.ptr())(e.what());
      instance.attr("code") = e.code();
      PyErr_SetObject(error.ptr(), instance.ptr());
    }
  });

  py::class_<CallOptions>(m, "CallOptions")
      .def(py::init<>())
      .def_readwrite("model", &CallOptions::model)
      .def_readwrite("estimators", &CallOptions::estimators)
      .def_readwrite("all_estimators", &CallOptions::all_estimators)
      .def_readwrite("seed", &CallOptions::seed)
      .def_readwrite("threads", &CallOptions::threads)
      .def_readwrite("max_time_s", &CallOptions::max_time_s)
      .def_readwrite("covariance", &CallOptions::covariance)
      .def_readwrite("use_measured_fz", &CallOptions::use_measured_fz)
      .def_readwrite("trace", &CallOptions::trace)
      .def_readwrite("named", &CallOptions::named)
      .def_readwrite("imu", &CallOptions::imu)
      .def_readwrite("frame", &CallOptions::frame)
      .def_readwrite("allow_damaged", &CallOptions::allow_damaged)
      .def_readwrite("plane", &CallOptions::plane)
      .def_readwrite("velocity", &CallOptions::velocity)
      .def_readwrite("cutoff_hz", &CallOptions::cutoff_hz)
      .def_readwrite("t_start", &CallOptions::t_start)
      .def_readwrite("t_end", &CallOptions::t_end);

  m.def("read_log",
        &imusysid::python::ReadLog,
        py::arg("path"),
        py::arg("imu"),
        py::arg("frame"));
  m.def("identify",
        &imusysid::python::IdentifyLog,
        py::arg("source"),
        py::arg("bytes"),
        py::arg("options"));
  m.def("fit",
        &imusysid::python::FitArrays,
        py::arg("t"),
        py::arg("f_x"),
        py::arg("omega"),
        py::arg("omega_dot"),
        py::arg("v"),
        py::arg("f_z"),
        py::arg("theta"),
        py::arg("source"),
        py::arg("gravity"),
        py::arg("options"));
  m.def("simulate",
        &imusysid::python::RunSimulate,
        py::arg("scenario"),
        py::arg("seed"),
        py::arg("settings"),
        py::arg("format"),
        py::arg("frame"),
        py::arg("want_files"));
  m.def("format_log",
        &imusysid::python::FormatLog,
        py::arg("source"),
        py::arg("columns"),
        py::arg("channels"),
        py::arg("metadata"),
        py::arg("frame"));
  m.def("write_file",
        &imusysid::python::WriteFile,
        py::arg("path"),
        py::arg("contents"));
  // The largest input any reader takes (imusysid::kMaxInputFileBytes):
  // imusysid.fleet refuses larger logs before reading them, as the tool.
  m.attr("MAX_INPUT_FILE_BYTES") =
      static_cast<std::uint64_t>(imusysid::kMaxInputFileBytes);
  m.def("scenario_names", [] {
    std::vector<std::string> names = imusysid::ScenarioNames();
    for (const std::string& n : imusysid::Scenario3dNames()) names.push_back(n);
    return names;
  });
}

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
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "imusysid/identify.h"
#include "imusysid/log.h"
#include "imusysid/log_reader.h"
#include "imusysid/simulate.h"
#include "imusysid/simulate3d.h"
#include "imusysid/status.h"

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
  if (!(c.max_time_s >= 0.0)) {
    ThrowIfError(InvalidArgumentError("max_time_s must be >= 0 (0: no limit)"));
  }
  if (c.max_time_s > 0.0) eo.max_wall_time_s = c.max_time_s;
  eo.record_trace = c.trace;
  eo.ga.num_threads = c.threads;
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
        InvalidArgumentError(std::string(name) + ": a 1-D array is required"));
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
        {static_cast<py::ssize_t>(r.parameters.size())}, r.parameters.data());
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
  if (!three_d) {
    if (!format.empty() && format != "csv") {
      ThrowIfError(InvalidArgumentError(
          "format='" + format + "': the planar scenarios write csv only"));
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
      ThrowIfError(InvalidArgumentError("format='" + format +
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
        o.rate_hz = std::stod(value);
      } else {
        ThrowIfError(InvalidArgumentError(
            "setting '" + name +
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

// A log given as arrays (what read_log and simulate return) as the CSV
// text Identify reads, every value written so that it reads back exactly.
py::bytes FormatLog(
    const std::string& source,
    const std::map<std::string, Doubles>& columns,
    const std::map<std::string, Doubles>& channels,
    const std::vector<std::pair<std::string, std::string>>& metadata) {
  FlightLog log;
  log.source = source;
  log.metadata = metadata;
  for (const auto& [name, values] : log.Columns()) {
    const auto it = columns.find(name);
    if (it == columns.end()) {
      ThrowIfError(InvalidArgumentError(source + ": the log has no '" +
                                        std::string(name) + "' array"));
    }
    *values = ToVector(it->second, name);
  }
  for (const auto& [name, values] : channels) {
    log.extra.push_back({name, ToVector(values, name.c_str())});
  }
  CsvWriteOptions write;
  write.precision = 0;  // the shortest text that reads back exactly
  std::string text;
  {
    py::gil_scoped_release unlocked;
    text = ValueOrThrow(FormatCsvLog(log, write));
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
        py::arg("metadata"));
  m.def("write_file",
        &imusysid::python::WriteFile,
        py::arg("path"),
        py::arg("contents"));
  m.def("scenario_names", [] {
    std::vector<std::string> names = imusysid::ScenarioNames();
    for (const std::string& n : imusysid::Scenario3dNames()) names.push_back(n);
    return names;
  });
}

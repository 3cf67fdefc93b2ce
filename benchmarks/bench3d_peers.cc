#include "benchmarks/bench3d_peers.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>

#include "benchmarks/bench_internal.h"
#include "imusysid/identify.h"
#include "imusysid/rigid3d.h"
#include "src/io/problem3d_io.h"
#include "src/tools/format.h"

namespace imusysid {
namespace bench {
namespace {

constexpr const char* kPeers3dAxes[3] = {"x", "y", "z"};

// `text` single-quoted for sh.
std::string Peers3dShellQuote(const std::string& text) {
  std::string q = "'";
  for (char c : text) {
    if (c == '\'') {
      q += "'\\''";
    } else {
      q += c;
    }
  }
  return q + "'";
}

std::string Peers3dReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The problem file of `log`'s instance 0, as export-problem writes it.
StatusOr<std::string> Peers3dProblemFile(const BenchConfig& config,
                                         const Log3d& log) {
  IdentifyOptions options;
  options.model = kRigid3dModelName;
  options.estimators = {"linear"};
  options.estimator = config.options;
  options.imu = 0;
  options.num_threads = 1;
  const IdentifyInput input =
      log.bytes.empty() ? IdentifyInput::LogFile(log.path)
                        : IdentifyInput::LogBytes(log.bytes, log.name);
  StatusOr<IdentifySummary> summary = Identify(input, options);
  if (!summary.ok()) return summary.status();
  if (summary->data == nullptr || summary->imus.empty()) {
    return FailedPreconditionError("no 3-D data");
  }
  const ImuPosition3d& imu = summary->imus.front();
  const ProblemMetadata metadata = {
      {"source", log.name},
      {"instance", std::to_string(imu.instance)},
      {"estimator_delay_s", FormatShortest(imu.estimator_delay_s)},
      {"gravity", FormatShortest(summary->data->gravity)},
      {"frame", "FRD, the IMU's own axes"}};
  return ::imusysid::internal::FormatLinearProblem3dCsv(
      summary->model, summary->data, metadata);
}

void ScorePeer3d(const Log3d& log, Peer3dRecord* r) {
  if (log.truth.known && !log.truth.position_imu_axes_m.empty()) {
    r->error_m = r->position_m - log.truth.position_imu_axes_m.front();
  }
}

}  // namespace

Status FindPeers3dPython(const std::vector<std::string>& pythons,
                         Peers3dSetup* setup) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(setup->script, ec)) {
    return FailedPreconditionError("--peers: no peers script at '" +
                                   setup->script + "'");
  }
  std::string tried;
  for (const std::string& python : pythons) {
    const std::string probe =
        Peers3dShellQuote(python) +
        " -c 'import numpy, scipy.optimize, scipy.linalg' >/dev/null 2>&1";
    if (std::system(probe.c_str()) == 0) {
      setup->python = python;
      return Status::Ok();
    }
    tried += (tried.empty() ? "" : ", ") + internal::Truncate(python, 40);
  }
  return FailedPreconditionError(
      "--peers: no python with NumPy and SciPy (tried " + tried +
      "; Debian: apt-get install python3-numpy python3-scipy; "
      "scripts/setup.sh --with-peers)");
}

StatusOr<std::vector<Peer3dRecord>> RunPeers3d(
    const Peers3dSetup& setup,
    const BenchConfig& config,
    const std::vector<Log3d>& logs,
    const std::vector<Run3dRecord>& runs) {
  std::vector<Peer3dRecord> records;
  std::error_code ec;
  std::filesystem::create_directories(setup.work_dir, ec);
  for (std::size_t i = 0; i < logs.size(); ++i) {
    const Log3d& log = logs[i];
    if (!log.status.ok()) continue;
    for (const Run3dRecord& r : runs) {
      if (r.log != log.name || r.log_path != log.path ||
          r.model != kRigid3dModelName || r.instance != 0 ||
          !r.preprocessing.empty() || !r.Usable()) {
        continue;
      }
      Peer3dRecord own;
      own.log = log.name;
      own.method = "imusysid-" + r.estimator;
      own.position_m = r.imu.position_m;
      own.time_s = r.fit_time_s;
      for (int a = 0; a < 3; ++a) {
        own.decisions += std::string(a > 0 ? "/" : "") +
                         (r.imu.determined[a] ? "given" : "withheld");
      }
      ScorePeer3d(log, &own);
      records.push_back(std::move(own));
    }
    StatusOr<std::string> problem = Peers3dProblemFile(config, log);
    if (!problem.ok()) {
      return problem.status().WithPrefix("--peers: exporting " + log.name);
    }
    const std::string base = setup.work_dir + "/peers3d_" + std::to_string(i);
    Status s = WriteFileAtomically(base + ".csv", *problem);
    if (!s.ok()) return s;
    const std::string command = Peers3dShellQuote(setup.python) + " " +
                                Peers3dShellQuote(setup.script) + " " +
                                Peers3dShellQuote(base + ".csv") + " >" +
                                Peers3dShellQuote(base + ".jsonl") + " 2>" +
                                Peers3dShellQuote(base + ".err");
    const int rc = std::system(command.c_str());
    const std::string out = Peers3dReadFile(base + ".jsonl");
    const std::string err = Peers3dReadFile(base + ".err");
    std::filesystem::remove(base + ".csv", ec);
    std::filesystem::remove(base + ".jsonl", ec);
    std::filesystem::remove(base + ".err", ec);
    if (rc != 0) {
      return InternalError("--peers: peers3d.py on " + log.name +
                           " failed: " + internal::Truncate(err, 200));
    }
    std::istringstream lines(out);
    std::string line;
    while (std::getline(lines, line)) {
      if (line.empty()) continue;
      const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
      if (j.is_discarded() || !j.is_object() || !j.contains("method") ||
          !j["method"].is_string() || !j.contains("position_frd_m") ||
          !j["position_frd_m"].is_array() || j["position_frd_m"].size() != 3) {
        return InternalError("--peers: peers3d.py on " + log.name +
                             ": not a result line: '" +
                             internal::Truncate(line, 40) + "'");
      }
      Peer3dRecord p;
      p.log = log.name;
      p.peer = true;
      p.method = internal::Truncate(j["method"].get<std::string>(), 40);
      for (int a = 0; a < 3; ++a) {
        const nlohmann::json& v = j["position_frd_m"][a];
        p.position_m[a] = v.is_number() ? v.get<double>() : kNaN;
      }
      if (j.contains("time_s") && j["time_s"].is_number()) {
        p.time_s = j["time_s"].get<double>();
      }
      ScorePeer3d(log, &p);
      records.push_back(std::move(p));
    }
  }
  std::filesystem::remove(setup.work_dir, ec);  // only when empty
  return records;
}

nlohmann::ordered_json Peer3dToJson(const Peer3dRecord& r) {
  auto vec = [](const Eigen::Vector3d& v) {
    nlohmann::ordered_json a = nlohmann::ordered_json::array();
    for (int i = 0; i < 3; ++i) {
      a.push_back(std::isfinite(v[i]) ? nlohmann::ordered_json(v[i])
                                      : nlohmann::ordered_json(nullptr));
    }
    return a;
  };
  return {{"log", r.log},
          {"instance", 0},
          {"method", r.method},
          {"peer", r.peer},
          {"position_frd_m", vec(r.position_m)},
          {"position_error_m", vec(r.error_m)},
          {"decisions", r.decisions},
          {"time_s",
           std::isfinite(r.time_s) ? nlohmann::ordered_json(r.time_s)
                                   : nlohmann::ordered_json(nullptr)}};
}

report::HtmlTable Peers3dHtmlTable(const std::vector<Peer3dRecord>& records) {
  report::HtmlTable t;
  t.id = "peers3d";
  t.caption =
      "3-D peers on the same flights, IMU instance 0 (mm; error = fitted − "
      "truth in the IMU's own axes; time = the solve alone)";
  t.header = {"log",
              "method",
              "p x / y / z mm",
              "err x / y / z mm",
              "|err| mm",
              "x / y / z",
              "time ms"};
  auto mm3 = [](const Eigen::Vector3d& v) {
    return internal::FixedCell(1000.0 * v[0], 2) + " / " +
           internal::FixedCell(1000.0 * v[1], 2) + " / " +
           internal::FixedCell(1000.0 * v[2], 2);
  };
  for (const Peer3dRecord& r : records) {
    t.rows.push_back({r.log,
                      r.method,
                      mm3(r.position_m),
                      mm3(r.error_m),
                      internal::NumCell(1000.0 * r.error_m.norm(), 2),
                      r.decisions.empty() ? "-" : r.decisions,
                      internal::NumCell(1000.0 * r.time_s, 2)});
  }
  return t;
}

std::string Peers3dMarkdown(const std::vector<Peer3dRecord>& records) {
  if (records.empty()) return "";
  return "## 3-D peers on the same flights\n\n"
         "IMU instance 0 of each log: imusysid's rigid3d estimators (the "
         "bench's runs above) beside benchmarks/peers/peers3d.py on the "
         "rows of rigid3d's linear system the fit sees (`export-problem "
         "--model=rigid3d`): SciPy's lstsq and least_squares, and an RLS in "
         "indiflight's manner without and with forgetting. time = the solve "
         "alone; x / y / z = imusysid's decision per axis (a peer gives "
         "every axis, withheld ones included).\n\n" +
         internal::HtmlTableMarkdown(Peers3dHtmlTable(records)) + "\n";
}

std::string Peers3dCsv(const std::vector<Peer3dRecord>& records) {
  std::ostringstream out;
  out << "log,method,peer";
  for (const char* what : {"p", "error"}) {
    for (const char* a : kPeers3dAxes) out << "," << what << "_" << a << "_m";
  }
  out << ",decisions,time_s\n";
  auto num = [](double v) {
    return std::isfinite(v) ? FormatShortest(v) : std::string();
  };
  for (const Peer3dRecord& r : records) {
    out << r.log << "," << r.method << "," << (r.peer ? "true" : "false");
    for (int a = 0; a < 3; ++a) out << "," << num(r.position_m[a]);
    for (int a = 0; a < 3; ++a) out << "," << num(r.error_m[a]);
    out << "," << r.decisions << "," << num(r.time_s) << "\n";
  }
  return out.str();
}

}  // namespace bench
}  // namespace imusysid

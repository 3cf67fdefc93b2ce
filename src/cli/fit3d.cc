#include "src/cli/fit3d.h"

#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "imusysid/rigid3d_report.h"
#include "src/cli/common.h"
#include "src/cli/log_flags.h"
#include "src/report/plan_files.h"
#include "src/report/rigid3d_page.h"
#include "src/tools/file_probe.h"

DEFINE_double(estimator_delay_s,
              std::numeric_limits<double>::quiet_NaN(),
              "--model=rigid3d: how late the log's attitude and velocity "
              "describe the state, s. Default: estimated (0-60 ms).");
DEFINE_string(report,
              "",
              "--model=rigid3d (or rigid3d_imu): write a report page, "
              "DIR/index.html with SVG figures (gnuplot) and tables: the "
              "log's timeline, the x/y specific force against the model and "
              "the residual, the residual's spectrum, the estimates per "
              "window and IMU with 2-sigma bars, each axis's decision and "
              "the parameter file (docs/model-3d.md).");

namespace imusysid {
namespace cli {
namespace {

const char kCmd[] = "fit";

// A flight's label on the report page: its file name.
std::string PageLabel(const std::string& source) {
  std::string label = std::filesystem::path(source).filename();
  return label.empty() ? source : label;
}

// The output (stdout or --out), then the --emit file and the --report page
// of `pages` titled `title`: kExitOk when all were written, else the exit
// code of the first failure.
int WriteOutputs(const std::string& text,
                 const AutopilotParameters* emitted,
                 const std::string& emit_out,
                 const std::vector<report::Rigid3dPageFlight>& pages,
                 const std::string& title,
                 const std::vector<PooledImuPosition3d>* pooled = nullptr) {
  Status s = EmitOutput(text, FLAGS_out);
  if (!s.ok()) return ReportError(kCmd, s);
  if (!FLAGS_out.empty()) std::cerr << "wrote " << FLAGS_out << "\n";
  if (!emit_out.empty() && emitted != nullptr) {
    s = WriteFileAtomically(emit_out, emitted->snippet);
    if (!s.ok()) return ReportError(kCmd, s);
    std::cerr << "wrote " << emit_out << "\n";
  }
  if (!FLAGS_report.empty()) {
    report::Rigid3dPageOptions options;
    options.cutoff_hz = FLAGS_cutoff_hz;
    options.title = title;
    options.pooled = pooled;
    std::vector<report::Figure> figures;
    s = report::WriteRigid3dPage(FLAGS_report, pages, options, &figures);
    if (!s.ok()) return ReportError(kCmd, s.WithPrefix("--report"));
    std::cerr << "wrote " << figures.size() << " figures and " << FLAGS_report
              << "/index.html\n";
  }
  return kExitOk;
}

}  // namespace

Preprocess3dOptions Preprocess3dOptionsFromFlags() {
  Preprocess3dOptions po;
  po.estimator_delay_s = FLAGS_estimator_delay_s;
  po.cutoff_hz = FLAGS_cutoff_hz;
  po.t_start = FLAGS_t_start;
  po.t_end = FLAGS_t_end;
  return po;
}

int WriteFit3d(const IdentifySummary& summary,
               EmitFormat emit,
               const std::string& emit_out) {
  const AutopilotParameters* emitted =
      emit != EmitFormat::kNone && summary.emit.has_value() &&
              !summary.emit->parameters.empty() &&
              summary.emit->parameters.front().has_value()
          ? &*summary.emit->parameters.front()
          : nullptr;
  std::string text;
  if (JsonOutput()) {
    nlohmann::ordered_json j = FlightImusToJson(summary);
    if (emitted != nullptr) {
      for (std::size_t i = 0; i < summary.imus.size(); ++i) {
        j[i]["emit"] = AutopilotParametersToJson(*emitted);
      }
    }
    text = DumpJson(j.size() == 1 ? j[0] : j) + "\n";
  } else {
    for (const ImuPosition3d& r : summary.imus) text += Rigid3dToText(r);
    for (const IdentifySummary::SkippedImu& skipped : summary.skipped_imus) {
      text += "IMU " + std::to_string(skipped.instance) +
              ": not fitted: " + skipped.reason + "\n";
    }
    if (summary.plan.has_value()) {
      text += "\nThe flight that would determine the withheld axes (IMU " +
              std::to_string(summary.plan->source_instance) +
              "; `imusysid plan --log=" + summary.source +
              " --out=DIR` writes its files):\n" +
              PlanCardText(summary.plan->plan);
      if (!summary.plan->reached) {
        text += "not reached: " + summary.plan->shortfall + "\n";
      }
      text +=
          "Fly it, then fit the new log alone, or pool it with this one "
          "(--log=" +
          summary.source + " --log=NEW).\n";
    }
    if (emitted != nullptr) text += AutopilotParametersToText(*emitted);
  }
  const std::string label = PageLabel(summary.source);
  const int written =
      WriteOutputs(text,
                   emitted,
                   emit_out,
                   {{label, &summary}},
                   "imusysid fit --model=" + summary.model + ": " + label);
  if (written != kExitOk) return written;
  return summary.usable() ? kExitOk : kExitBadInput;
}

namespace {

// The flight's agreement with the pool on one instance, per axis.
nlohmann::ordered_json AgreementJson(const PooledImuPosition3d& pooled,
                                     std::size_t flight) {
  nlohmann::ordered_json axes = nlohmann::ordered_json::array();
  for (const PooledFlightAxis& part : pooled.flights[flight].axes) {
    nlohmann::ordered_json one;
    one["entered"] = part.entered;
    one["deviation_sigmas"] =
        std::isfinite(part.deviation_sigmas)
            ? nlohmann::ordered_json(part.deviation_sigmas)
            : nlohmann::ordered_json(nullptr);
    one["chi_square_term"] = std::isfinite(part.chi_square_term)
                                 ? nlohmann::ordered_json(part.chi_square_term)
                                 : nlohmann::ordered_json(nullptr);
    one["disagrees"] = part.disagrees;
    axes.push_back(std::move(one));
  }
  return axes;
}

}  // namespace

int WriteFlights3d(const FlightsSummary& summary,
                   EmitFormat emit,
                   const std::string& emit_out) {
  const AutopilotParameters* emitted =
      emit != EmitFormat::kNone && summary.emit.has_value() ? &*summary.emit
                                                            : nullptr;
  std::string text;
  if (JsonOutput()) {
    nlohmann::ordered_json j;
    nlohmann::ordered_json imus = nlohmann::ordered_json::array();
    for (const PooledImuPosition3d& p : summary.imus) {
      imus.push_back(PooledToJson(p));
    }
    j["imus"] = std::move(imus);
    // Every input in order: a refused flight with why, beside the fitted.
    std::vector<nlohmann::ordered_json> by_input(summary.flights.size() +
                                                 summary.refused.size());
    for (const FlightsSummary::RefusedFlight& r : summary.refused) {
      nlohmann::ordered_json one;
      one["log"] = r.source;
      one["fitted"] = false;
      one["reason"] = r.reason;
      if (r.input < by_input.size()) by_input[r.input] = std::move(one);
    }
    for (std::size_t f = 0; f < summary.flights.size(); ++f) {
      const IdentifySummary& flight = summary.flights[f];
      nlohmann::ordered_json one;
      one["log"] = flight.source;
      nlohmann::ordered_json own = FlightImusToJson(flight);
      // Each fitted IMU's agreement with its pool, beside its own fit.
      for (nlohmann::ordered_json& imu : own) {
        if (!imu.contains("fitted_position_frd_m")) continue;
        for (const PooledImuPosition3d& p : summary.imus) {
          if (p.instance == imu["instance"].get<int>()) {
            imu["agreement"] = AgreementJson(p, f);
          }
        }
      }
      one["imus"] = std::move(own);
      const std::size_t input =
          f < summary.flight_inputs.size() ? summary.flight_inputs[f] : f;
      if (input < by_input.size()) by_input[input] = std::move(one);
    }
    nlohmann::ordered_json flights = nlohmann::ordered_json::array();
    for (nlohmann::ordered_json& one : by_input) {
      if (!one.is_null()) flights.push_back(std::move(one));
    }
    j["flights"] = std::move(flights);
    if (emitted != nullptr) j["emit"] = AutopilotParametersToJson(*emitted);
    text = DumpJson(j) + "\n";
  } else {
    // The instances a flight did not fit are in the table, each with why;
    // a flight refused as a whole is named first.
    for (const FlightsSummary::RefusedFlight& r : summary.refused) {
      text += "flight " + std::to_string(r.input + 1) + " (" + r.source +
              ") not pooled: " + r.reason + "\n";
    }
    for (const PooledImuPosition3d& p : summary.imus) text += PooledToText(p);
    if (emitted != nullptr) text += AutopilotParametersToText(*emitted);
  }
  // The page shows each flight on its own, then the pool.
  std::vector<report::Rigid3dPageFlight> pages;
  std::string labels;
  for (const IdentifySummary& flight : summary.flights) {
    const std::string label = PageLabel(flight.source);
    labels += (labels.empty() ? "" : ", ") + label;
    pages.push_back({label, &flight});
  }
  const int written = WriteOutputs(
      text,
      emitted,
      emit_out,
      pages,
      "imusysid fit --model=" + summary.flights.front().model + ": " + labels,
      &summary.imus);
  if (written != kExitOk) return written;
  return summary.usable() ? kExitOk : kExitBadInput;
}

Status CheckReportFlag(bool three_d) {
  if (FLAGS_report.empty()) return Status::Ok();
  if (!three_d) {
    return InvalidArgumentError(
        "--report draws the page of a 3-D fit (--model=rigid3d or "
        "rigid3d_imu); for a planar model, --plot=DIR draws its figures");
  }
  return report::CheckRigid3dPageFolder(FLAGS_report).WithPrefix("--report");
}

Status CheckOutputFileTarget(const std::string& flag, const std::string& path) {
  if (path.empty() || path == "-" || path == "/dev/stdout" ||
      path == "/dev/stderr" || path == "/dev/fd/1" || path == "/dev/fd/2") {
    return Status::Ok();
  }
  const auto refuse = [&](const std::string& why) {
    return InvalidArgumentError(flag + "=" + path + ": " + why +
                                " (checked before the fit)");
  };
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);  // through links
  if (st.type() == fs::file_type::fifo ||
      st.type() == fs::file_type::character) {
    return access(path.c_str(), W_OK) == 0
               ? Status::Ok()
               : refuse(std::string("cannot write it: ") +
                        std::strerror(errno));
  }
  fs::path file = path;
  if (st.type() == fs::file_type::regular) {
    file = fs::canonical(path, ec);  // a link's target is what is replaced
    if (ec) return refuse("cannot resolve it: " + ec.message());
  } else if (st.type() != fs::file_type::not_found) {
    return refuse(st.type() == fs::file_type::directory
                      ? "it is a folder, not a file to write"
                      : "it is not a regular file to write");
  }
  const fs::path parent =
      file.has_parent_path() ? file.parent_path() : fs::path(".");
  if (!fs::is_directory(parent, ec)) {
    return refuse("its folder '" + parent.string() +
                  "' does not exist or is not a folder");
  }
  // The file is written beside its target and renamed over it.
  const std::string why = WhyFolderTakesNoEntry(parent.string());
  if (!why.empty()) {
    return refuse("no file can be made in '" + parent.string() + "': " + why);
  }
  return Status::Ok();
}

}  // namespace cli
}  // namespace imusysid

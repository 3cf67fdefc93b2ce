#include "tests/fuzz/fuzz_targets.h"

#include <string>
#include <string_view>

#include "imusysid/log.h"
#include "imusysid/log_reader.h"
#include "imusysid/log_sanity.h"
#include "imusysid/problem_io.h"
#include "src/tools/fit_json.h"

namespace imusysid {
namespace fuzz {
namespace {

std::string_view View(const std::uint8_t* data, std::size_t size) {
  return std::string_view(reinterpret_cast<const char*>(data), size);
}

// Accept tiny logs so the conversions run on small fuzz inputs too.
LogReadOptions Permissive() {
  LogReadOptions options;
  options.min_samples = 1;
  options.max_gap_factor = 0;
  return options;
}

}  // namespace

void FuzzCsv(const std::uint8_t* data, std::size_t size) {
  CsvReadOptions options;
  options.min_samples = 1;
  StatusOr<FlightLog> log = ParseCsvLog(View(data, size), "fuzz.csv", options);
  if (log.ok()) (void)FormatCsvLog(*log);
}

void FuzzUlog(const std::uint8_t* data, std::size_t size) {
  StatusOr<UlogData> ulog = ParseUlog(View(data, size), "fuzz.ulg");
  if (!ulog.ok()) return;
  for (int instance = 0; instance < 2; ++instance) {
    LogReadOptions options = Permissive();
    options.imu_instance = instance;
    (void)UlogToFlightLog(*ulog, "fuzz.ulg", options);
  }
  (void)SummarizeLogBytes(View(data, size), "fuzz.ulg");
}

void FuzzDataFlash(const std::uint8_t* data, std::size_t size) {
  StatusOr<DataFlashLog> log = ParseDataFlash(View(data, size), "fuzz.bin");
  if (!log.ok()) return;
  for (int instance = 0; instance < 2; ++instance) {
    LogReadOptions options = Permissive();
    options.imu_instance = instance;
    (void)DataFlashToFlightLog(*log, "fuzz.bin", options);
  }
  (void)SummarizeLogBytes(View(data, size), "fuzz.bin");
}

void FuzzProblemCsv(const std::uint8_t* data, std::size_t size) {
  StatusOr<ProblemFile> file = ParseProblemCsv(View(data, size), "fuzz.csv");
  if (!file.ok()) return;
  (void)CheckFitSegmentSize(file->data, "fuzz.csv");
  (void)FormatProblemCsv(file->data, file->metadata);
}

void FuzzFitJson(const std::uint8_t* data, std::size_t size) {
  // With and without a pick: an array takes the other path.
  (void)ParseFitJson(View(data, size), "fuzz.json", "");
  (void)ParseFitJson(View(data, size), "fuzz.json", "ga");
}

}  // namespace fuzz
}  // namespace imusysid

// The tool against bad input, as a hostile or careless user would try it: a
// table of cases over CSV logs, problem files, fit JSON, ULog, DataFlash,
// flags and output paths, each run through the real command line and checked
// for its exit code (2: the user's input; never a crash, never 0) and for a
// fragment of the one-line message that names what was wrong. The families
// and what the tool says are listed in docs/failure-modes.md.

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "nlohmann/json.hpp"
#include "tests/synthetic_logs.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

using ::testing::HasSubstr;
using testing::SyntheticSample;

// Enough samples for every gate (>= 100 samples over >= 1 s) and still a
// fraction of a second to fit.
constexpr int kSamples = 600;
// The synthetic flight has no manoeuvre the detector accepts, so commands
// that preprocess a CSV get the fit segment explicitly.
const char kWindow[] = " --t_start=2.1 --t_end=4.3";

std::string Q(const std::string& path) { return "'" + path + "'"; }

std::string Write(const std::string& dir,
                  const std::string& name,
                  const std::string& contents) {
  const std::string path = dir + "/" + name;
  std::ofstream out(path, std::ios::binary);
  out << contents;
  return path;
}

std::string Csv(int n = kSamples) { return testing::SyntheticCsvLog(n); }
template <typename F>
std::string Csv(F transform, int n = kSamples) {
  return testing::SyntheticCsvLog(n, transform);
}

// The synthetic CSV with line `line` (1-based, counting the frame and header
// lines) replaced.
std::string CsvWithLine(int line, const std::string& text) {
  std::string csv = Csv();
  std::size_t start = 0;
  for (int i = 1; i < line; ++i) start = csv.find('\n', start) + 1;
  const std::size_t end = csv.find('\n', start);
  return csv.substr(0, start) + text + csv.substr(end);
}

// A problem file of `n` rows of equation 9's regressors.
std::string Problem(int n = 400,
                    const std::string& extra_metadata = "",
                    int bad_row = -1,
                    const std::string& bad_row_text = "") {
  std::string text = extra_metadata + "t,f,omega,omega_dot,v\n";
  for (int i = 0; i < n; ++i) {
    const double t = 0.01 * i;
    if (i == bad_row) {
      text += bad_row_text + "\n";
      continue;
    }
    text += std::to_string(t) + "," + std::to_string(0.3 * std::sin(t)) + "," +
            std::to_string(std::sin(2 * t)) + "," +
            std::to_string(2 * std::cos(2 * t)) + "," +
            std::to_string(std::sin(0.7 * t)) + "\n";
  }
  return text;
}

std::string FitJson(const std::string& body) { return "{" + body + "}"; }

struct BadCase {
  std::string family;
  std::string name;
  // Creates the case's files in `dir` and returns the command line.
  std::function<std::string(const std::string& dir)> args;
  int exit_code;
  std::string fragment;
};

std::ostream& operator<<(std::ostream& os, const BadCase& c) {
  return os << c.family << "/" << c.name;
}

BadCase Case(std::string family,
             std::string name,
             std::function<std::string(const std::string&)> args,
             std::string fragment,
             int exit_code = 2) {
  return {std::move(family),
          std::move(name),
          std::move(args),
          exit_code,
          std::move(fragment)};
}

// `fit` of a CSV log with these contents.
std::function<std::string(const std::string&)> FitCsv(
    const std::string& contents, const std::string& flags = "") {
  return [contents, flags](const std::string& dir) {
    return "fit --estimator=varpro" + std::string(kWindow) + " " + flags +
           " --log=" + Q(Write(dir, "log.csv", contents));
  };
}

std::function<std::string(const std::string&)> FitProblem(
    const std::string& contents, const std::string& flags = "") {
  return [contents, flags](const std::string& dir) {
    return "fit --estimator=linear " + flags +
           " --problem=" + Q(Write(dir, "p.csv", contents));
  };
}

std::function<std::string(const std::string&)> Displacement(
    const std::string& json, const std::string& flags = "") {
  return [json, flags](const std::string& dir) {
    const std::string good =
        Write(dir, "good.json", FitJson("\"r_m\": 0.19, \"beta_deg\": 56.3"));
    return "displacement " + flags + " " + Q(good) + " " +
           Q(Write(dir, "fit.json", json));
  };
}

std::function<std::string(const std::string&)> FitBinary(
    const std::string& bytes,
    const std::string& name,
    const std::string& flags = "") {
  return [bytes, name, flags](const std::string& dir) {
    return "fit --estimator=varpro " + flags +
           " --log=" + Q(Write(dir, name, bytes));
  };
}

std::function<std::string(const std::string&)> Flags(
    const std::string& command) {
  return [command](const std::string& dir) {
    std::string c = command;
    const std::string key = "LOG";
    const std::size_t at = c.find(key);
    if (at != std::string::npos) {
      c.replace(at, key.size(), Q(Write(dir, "log.csv", Csv())));
      if (c.find("--t_") == std::string::npos) c += kWindow;
    }
    return c;
  };
}

// Bytes [from, to) of `bytes` overwritten with `value`.
std::string Overwritten(std::string bytes,
                        std::size_t from,
                        std::size_t to,
                        char value) {
  for (std::size_t i = from; i < to && i < bytes.size(); ++i) bytes[i] = value;
  return bytes;
}

std::vector<BadCase> CsvCases() {
  const std::string f = "csv_log";
  std::vector<BadCase> c;
  c.push_back(Case(f, "empty", FitCsv(""), "the file is empty"));
  c.push_back(Case(f,
                   "header_only",
                   FitCsv("t,ax,ay,az,gx,gy,gz\n"),
                   "the log has 0 samples, fewer than the 10 the fit needs"));
  c.push_back(Case(f,
                   "missing_column",
                   FitCsv("t,ax,ay,gx,gy,gz\n0,1,2,3,4,5\n"),
                   "missing required column 'az'"));
  c.push_back(Case(f,
                   "duplicate_column",
                   FitCsv("t,ax,ay,az,gx,gy,gz,ax\n"),
                   "duplicate column name 'ax'"));
  c.push_back(
      Case(f,
           "not_a_number",
           FitCsv(CsvWithLine(10, "2.032,abc,0,9.8,0,0,0")),
           "log.csv:10:7: line 10: column 'ax': 'abc' is not a number"));
  c.push_back(Case(f,
                   "nan",
                   FitCsv(CsvWithLine(11, "2.036,nan,0,9.8,0,0,0")),
                   "line 11: column 'ax': 'nan' is not a finite number"));
  c.push_back(Case(f,
                   "inf",
                   FitCsv(CsvWithLine(12, "2.04,0,0,inf,0,0,0")),
                   "column 'az': 'inf' is not a finite number"));
  c.push_back(Case(f,
                   "square_overflows",
                   FitCsv(CsvWithLine(13, "2.044,0,0,9.8,0,1e200,0")),
                   "line 13: column 'gy': '1e200' is beyond +/-1e100"));
  c.push_back(Case(f,
                   "beyond_double",
                   FitCsv(CsvWithLine(14, "2.048,1e400,0,9.8,0,0,0")),
                   "'1e400' is outside the range of a double"));
  c.push_back(Case(f,
                   "ragged_row",
                   FitCsv(CsvWithLine(15, "2.052,0,0,9.8")),
                   "line 15: row has 4 fields, expected 7"));
  c.push_back(Case(f,
                   "extra_field",
                   FitCsv(CsvWithLine(15, "2.052,0,0,9.8,0,0,0,7")),
                   "extra field '7'"));
  c.push_back(
      Case(f,
           "time_backwards",
           FitCsv(CsvWithLine(20, "1.0,0,0,9.8,0,0,0")),
           "line 20: column 't': time '1.0' is before the previous time"));
  c.push_back(Case(f,
                   "time_gap",
                   FitCsv(Csv([](SyntheticSample* s) {
                     if (s->t_s > 2.1) s->t_s += 10.0;
                   })),
                   "the log has a hole"));
  c.push_back(
      Case(f,
           "binary_garbage",
           FitCsv(std::string("\x7f\x45\x4c\x46\x02\x01\x01\0\0\0", 10) +
                  std::string(200, '\x01')),
           "not a CSV, ULog or DataFlash log (first bytes: 7f 45 4c "
           "46 02 01 01 00"));
  c.push_back(Case(f,
                   "nul_in_text",
                   FitCsv("t,ax,ay,az,gx,gy,gz\n" + std::string(1, '\0') +
                          "0,1,2,3,4,5,6\n"),
                   "not a CSV, ULog or DataFlash log"));
  c.push_back(Case(f,
                   "escape_sequence_in_header",
                   FitCsv("t,ax,ay,az,gx,gy,gz,\x1b[31mred\n0,1,2,3,4,5,6\n"),
                   "column '\\x1b[31mred' is missing"));
  c.push_back(Case(f,
                   "invalid_utf8_in_cell",
                   FitCsv(CsvWithLine(9, "2.028,\xff\xfe,0,9.8,0,0,0")),
                   "'\\xff\\xfe' is not a number"));
  c.push_back(Case(f,
                   "accelerometer_in_g",
                   FitCsv(Csv([](SyntheticSample* s) {
                     s->ax /= 9.80665;
                     s->ay /= 9.80665;
                     s->az /= 9.80665;
                   })),
                   "the units look like g, not m/s^2"));
  c.push_back(Case(f,
                   "accelerometer_in_mm_s2",
                   FitCsv(Csv([](SyntheticSample* s) {
                     s->ax *= 1000;
                     s->ay *= 1000;
                     s->az *= 1000;
                   })),
                   "the units look like mm/s^2"));
  c.push_back(
      Case(f,
           "flu_labelled_frd",
           FitCsv("# frame: frd\n" + Csv().substr(Csv().find('\n') + 1)),
           "so the frame looks wrong: the data look flu"));
  c.push_back(Case(
      f,
      "frd_overridden_as_flu",
      FitCsv(Csv([](SyntheticSample* s) { s->az = -s->az; }), "--frame=flu"),
      "the frame looks wrong: the data look frd"));
  c.push_back(Case(f,
                   "ten_samples",
                   FitCsv(Csv(10), "--t_start=2 --t_end=2.036"),
                   "the fit segment holds 10 samples over 0.036 s; a fit "
                   "needs at least 100 samples"));
  c.push_back(Case(f,
                   "five_samples",
                   FitCsv(Csv(5)),
                   "the log has 5 samples, fewer than the 10 the fit needs"));
  c.push_back(
      Case(f,
           "bad_frame_metadata",
           FitCsv("# frame: sideways\n" + Csv().substr(Csv().find('\n') + 1)),
           "metadata 'frame': unknown frame 'sideways'"));
  return c;
}

std::vector<BadCase> ProblemCases() {
  const std::string f = "problem";
  std::vector<BadCase> c;
  c.push_back(Case(f, "empty", FitProblem(""), "the file is empty"));
  c.push_back(Case(f,
                   "missing_column",
                   FitProblem("t,f,omega,v\n0,1,2,3\n"),
                   "is missing required column 'omega_dot'"));
  c.push_back(Case(f,
                   "not_a_number",
                   FitProblem(Problem(400, "", 5, "0.05,abc,0,0,0")),
                   "p.csv:7:6: line 7: column 'f': 'abc' is not a number"));
  c.push_back(Case(f,
                   "nan",
                   FitProblem(Problem(400, "", 5, "0.05,0,nan,0,0")),
                   "column 'omega': 'nan' is not a finite number"));
  c.push_back(Case(f,
                   "square_overflows",
                   FitProblem(Problem(400, "", 5, "0.05,0,0,0,1e200")),
                   "line 7: column 'v': '1e200' is beyond +/-1e100"));
  c.push_back(Case(f,
                   "huge_v_every_row_all_estimators",
                   FitProblem(
                       [] {
                         std::string text = "t,f,omega,omega_dot,v\n";
                         for (int i = 0; i < 200; ++i) {
                           text += std::to_string(0.01 * i) + ",0.1," +
                                   std::to_string(std::sin(i)) + ",0.2,1e99\n";
                         }
                         return text;
                       }(),
                       "--estimator=all --ga_max_generations=5"),
                   "fitting paper with cmaes (200 samples)"));
  c.push_back(Case(f,
                   "gravity_1e300",
                   FitProblem(Problem(400, "# gravity: 1e300\n")),
                   "metadata 'gravity': '1e300' is beyond +/-1e100"));
  c.push_back(Case(f,
                   "gravity_in_mm_s2",
                   FitProblem(Problem(400, "# gravity: 9806.65\n")),
                   "'9806.65' is outside [0.1, 100] m/s^2"));
  c.push_back(Case(f,
                   "gravity_negative",
                   FitProblem(Problem(400, "# gravity: -9.8\n")),
                   "'-9.8' is outside [0.1, 100] m/s^2"));
  c.push_back(Case(f,
                   "gravity_text",
                   FitProblem(Problem(400, "# gravity: heavy\n")),
                   "'heavy' is not a number"));
  c.push_back(Case(f,
                   "ten_rows",
                   FitProblem(Problem(10)),
                   "the fit segment holds 10 samples"));
  c.push_back(Case(f,
                   "time_backwards",
                   FitProblem(Problem(400, "", 50, "0.1,0,0,0,0")),
                   "p.csv:52:1: line 52: column 't': time '0.1' is before the "
                   "previous time"));
  c.push_back(Case(f,
                   "ragged",
                   FitProblem(Problem(400, "", 50, "0.5,0,0")),
                   "row has 3 fields"));
  c.push_back(Case(f,
                   "consistent_model",
                   FitProblem(Problem(), "--model=consistent"),
                   "cannot be fitted from a problem file"));
  c.push_back(Case(f,
                   "binary",
                   FitProblem(std::string("\x89PNG\r\n\x1a\n\0\0\0\rIHDR", 16)),
                   "header '\\x89PNG' is missing required columns"));
  return c;
}

std::vector<BadCase> FitJsonCases() {
  const std::string f = "fit_json";
  std::vector<BadCase> c;
  c.push_back(Case(f,
                   "syntax_error",
                   Displacement("{\"r_m\": 0.19,\n \"beta_deg\": x}"),
                   "fit.json:2:14: not valid JSON"));
  c.push_back(
      Case(f, "empty", Displacement(""), "fit.json:1:1: not valid JSON"));
  c.push_back(Case(f,
                   "negative_r",
                   Displacement(FitJson("\"r_m\": -0.19, \"beta_deg\": 56")),
                   "fit.json: r_m = -0.19; required a finite number in [0, "
                   "1000]"));
  c.push_back(Case(f,
                   "huge_r",
                   Displacement(FitJson("\"r_m\": 1e300, \"beta_deg\": 56")),
                   "r_m = 1e+300; required"));
  c.push_back(Case(f,
                   "huge_beta",
                   Displacement(FitJson("\"r_m\": 0.2, \"beta_deg\": 1e300")),
                   "beta_deg = 1e+300"));
  c.push_back(Case(f,
                   "missing_r",
                   Displacement(FitJson("\"beta_deg\": 56")),
                   "field 'r_m' is missing"));
  c.push_back(Case(f,
                   "r_is_text",
                   Displacement(FitJson("\"r_m\": \"0.19\", \"beta_deg\": 56")),
                   "field 'r_m' must be a number, not string"));
  c.push_back(Case(f,
                   "r_is_null",
                   Displacement(FitJson("\"r_m\": null, \"beta_deg\": 56")),
                   "field 'r_m' is null"));
  c.push_back(Case(f,
                   "estimator_is_number",
                   Displacement(FitJson(
                       "\"estimator\": 5, \"r_m\": 0.19, \"beta_deg\": 56")),
                   "field 'estimator' must be a string, not number"));
  c.push_back(Case(
      f,
      "warnings_of_strings",
      Displacement(
          FitJson("\"r_m\": 0.19, \"beta_deg\": 56, \"warnings\": [\"a\"]")),
      "each entry of 'warnings' must be an object"));
  c.push_back(Case(f,
                   "warning_code_is_number",
                   Displacement(FitJson("\"r_m\": 0.19, \"beta_deg\": 56, "
                                        "\"warnings\": [{\"code\": 3}]")),
                   "each entry of 'warnings' must be an object"));
  c.push_back(Case(
      f,
      "warnings_not_array",
      Displacement(FitJson("\"r_m\": 0.19, \"beta_deg\": 56, \"warnings\": 4")),
      "field 'warnings' must be an array, not number"));
  c.push_back(Case(f,
                   "stderr_is_text",
                   Displacement(FitJson(
                       "\"r_m\": 0.19, \"beta_deg\": 56, \"stderr\": \"x\"")),
                   "field 'stderr' must be an object, not string"));
  c.push_back(Case(f,
                   "negative_stderr",
                   Displacement(FitJson("\"r_m\": 0.19, \"beta_deg\": 56, "
                                        "\"stderr\": {\"r_m\": -1}")),
                   "stderr.r_m = -1"));
  c.push_back(
      Case(f,
           "raw_parameters_is_text",
           Displacement(FitJson("\"raw_parameters\": \"x\", \"r_m\": 0.19, "
                                "\"beta_deg\": 56")),
           "field 'raw_parameters' must be an object"));
  c.push_back(Case(
      f,
      "not_identifiable",
      Displacement(
          FitJson("\"r_m\": 0.19, \"beta_deg\": 56, \"warnings\": "
                  "[{\"code\": \"not_identifiable\", \"message\": \"m\"}]")),
      "that fit could not identify r and beta"));
  c.push_back(Case(f,
                   "top_level_number",
                   Displacement("42"),
                   "expected a fit object, not number"));
  c.push_back(Case(f,
                   "array_without_pick",
                   Displacement("[{\"r_m\": 0.1, \"beta_deg\": 1}]"),
                   "holds 1 fits; choose one with --estimator_pick=NAME"));
  c.push_back(Case(f,
                   "array_pick_missing",
                   Displacement("[{\"estimator\": \"lm\", \"r_m\": 0.1, "
                                "\"beta_deg\": 1}]",
                                "--estimator_pick=ga"),
                   "no fit by estimator 'ga'"));
  c.push_back(Case(f,
                   "array_of_numbers",
                   Displacement("[1, 2]", "--estimator_pick=ga"),
                   "expected an array of fit objects, found number"));
  // Found by fit_json_fuzzer: the JSON library throws out_of_range, not a
  // parse error, for a number beyond a double.
  c.push_back(
      Case(f,
           "number_beyond_double",
           Displacement(FitJson("\"r_m\": 1e999, \"beta_deg\": 56")),
           "fit.json: not valid JSON: number overflow parsing '1e999'"));
  c.push_back(
      Case(f,
           "invalid_utf8",
           Displacement("{\"r_m\": 0.1, \"beta_deg\": 1, \"x\": \"\xff\"}"),
           "not valid JSON"));
  c.push_back(
      Case(f,
           "deep_nesting",
           Displacement(std::string(100000, '[') + std::string(100000, ']'),
                        "--estimator_pick=ga"),
           "expected an array of fit objects, found array"));
  return c;
}

std::vector<BadCase> UlogCases() {
  const std::string f = "ulog";
  const std::string good = testing::SyntheticUlog(kSamples);
  std::vector<BadCase> c;
  c.push_back(Case(f,
                   "header_only",
                   FitBinary(good.substr(0, 20), "a.ulg"),
                   "no IMU data for instance 0"));
  c.push_back(Case(
      f,
      "unknown_incompat_flag",
      FitBinary(Overwritten(good, 16 + 3 + 8, 16 + 3 + 9, '\x02'), "a.ulg"),
      "byte 16: unknown incompat_flags[0] bits 0x02"));
  c.push_back(Case(
      f,
      "no_imu",
      FitBinary(good.substr(0, good.find("sensor_combined:") - 3), "a.ulg"),
      "no IMU data"));
  c.push_back(Case(f,
                   "damaged_middle",
                   FitBinary(Overwritten(good,
                                         good.size() / 3,
                                         good.size() / 3 + good.size() / 10,
                                         '\xff'),
                             "a.ulg"),
                   "the log is damaged: the reader skipped"));
  c.push_back(Case(f,
                   "nan_accelerometer",
                   FitBinary(testing::SyntheticUlog(kSamples,
                                                    [](SyntheticSample* s) {
                                                      if (s->t_s > 2.5 &&
                                                          s->t_s < 2.51) {
                                                        s->ax = std::nan("");
                                                      }
                                                    }),
                             "a.ulg"),
                   "has a non-finite value"));
  c.push_back(Case(f,
                   "accelerometer_in_g",
                   FitBinary(testing::SyntheticUlog(kSamples,
                                                    [](SyntheticSample* s) {
                                                      s->ax /= 9.80665;
                                                      s->ay /= 9.80665;
                                                      s->az /= 9.80665;
                                                    }),
                             "a.ulg"),
                   "the units look like g"));
  c.push_back(
      Case(f,
           "upside_down",
           FitBinary(testing::SyntheticUlog(
                         kSamples, [](SyntheticSample* s) { s->az = -s->az; }),
                     "a.ulg"),
           "the frame looks wrong"));
  c.push_back(Case(f,
                   "time_backwards",
                   FitBinary(testing::SyntheticUlog(kSamples,
                                                    [](SyntheticSample* s) {
                                                      if (s->t_s > 2.4 &&
                                                          s->t_s < 2.405) {
                                                        s->t_s = 1.0;
                                                      }
                                                    }),
                             "a.ulg"),
                   "is before the previous sample's"));
  c.push_back(Case(f,
                   "five_samples",
                   FitBinary(testing::SyntheticUlog(5), "a.ulg"),
                   "sensor_combined has 5 usable samples, fewer than the 10"));
  return c;
}

std::vector<BadCase> DataFlashCases() {
  const std::string f = "dataflash";
  const std::string good = testing::SyntheticDataFlash(kSamples);
  std::vector<BadCase> c;
  c.push_back(Case(f,
                   "magic_only",
                   FitBinary(std::string("\xA3\x95\x80", 3), "a.bin"),
                   "byte 0: no complete FMT record in the file"));
  c.push_back(Case(f,
                   "no_imu",
                   FitBinary(good.substr(0, 89 * 2), "a.bin"),
                   "no IMU data for instance 0"));
  c.push_back(Case(f,
                   "damaged_middle",
                   FitBinary(Overwritten(good,
                                         good.size() / 3,
                                         good.size() / 3 + good.size() / 10,
                                         '\x00'),
                             "a.bin"),
                   "the log is damaged: the reader skipped"));
  c.push_back(Case(f,
                   "nan_accelerometer",
                   FitBinary(testing::SyntheticDataFlash(
                                 kSamples,
                                 [](SyntheticSample* s) {
                                   if (s->t_s > 2.5 && s->t_s < 2.51) {
                                     s->az = std::nan("");
                                   }
                                 }),
                             "a.bin"),
                   "has a non-finite value"));
  c.push_back(
      Case(f,
           "accelerometer_in_g",
           FitBinary(testing::SyntheticDataFlash(kSamples,
                                                 [](SyntheticSample* s) {
                                                   s->ax /= 9.80665;
                                                   s->ay /= 9.80665;
                                                   s->az /= 9.80665;
                                                 }),
                     "a.bin"),
           "the units look like g"));
  c.push_back(Case(f,
                   "time_backwards",
                   FitBinary(testing::SyntheticDataFlash(
                                 kSamples,
                                 [](SyntheticSample* s) {
                                   if (s->t_s > 2.4 && s->t_s < 2.405) {
                                     s->t_s = 1.0;
                                   }
                                 }),
                             "a.bin"),
                   "is before the previous sample's"));
  c.push_back(Case(f,
                   "five_samples",
                   FitBinary(testing::SyntheticDataFlash(5), "a.bin"),
                   "IMU[I=0] has 5 usable samples"));
  c.push_back(Case(f,
                   "truncated_in_fmt",
                   FitBinary(good.substr(0, 50), "a.bin"),
                   "no complete FMT record"));
  return c;
}

std::vector<BadCase> FlagCases() {
  const std::string f = "flags";
  std::vector<BadCase> c;
  auto add = [&](const std::string& name,
                 const std::string& command,
                 const std::string& fragment) {
    c.push_back(Case(f, name, Flags(command), fragment));
  };
  add("t_start_nan",
      "fit --log=LOG --t_start=nan",
      "--t_start=nan: the value must be a finite number");
  add("t_end_inf",
      "fit --log=LOG --t_end=inf",
      "--t_end=inf: the value must be a finite number");
  add("max_time_negative",
      "fit --log=LOG --max_time_s=-1",
      "--max_time_s=-1; required >= 0");
  add("max_time_nan",
      "fit --log=LOG --max_time_s=nan",
      "the value must be a finite number");
  add("ga_population_huge",
      "fit --log=LOG --estimator=ga --ga_population=2000000000",
      "population_size` = 2000000000; required in [2, 1000000]");
  add("ga_population_beyond_int",
      "fit --log=LOG --estimator=ga --ga_population=3000000000",
      "required in [-2147483648, 2147483647]");
  add("ga_population_text",
      "fit --log=LOG --ga_population=many",
      "bad value 'many' for flag '--ga_population'");
  add("threads_zero", "fit --log=LOG --threads=0", "num_threads` = 0");
  add("imu_seven", "fit --log=LOG --imu=7", "--imu=7; required 0, 1 or 2");
  add("cutoff_negative", "fit --log=LOG --cutoff_hz=-1", "cutoff_hz");
  add("seed_negative", "fit --log=LOG --seed=-1", "bad value '-1'");
  add("format_xml", "fit --log=LOG --format=xml", "--format must be");
  add("unknown_estimator", "fit --log=LOG --estimator=nope", "nope");
  add("unknown_model", "fit --log=LOG --model=nope", "nope");
  add("bounds_malformed", "fit --log=LOG --bounds=r:1", "is not name:lo:hi");
  add("initial_text", "fit --log=LOG --initial=abc", "'abc' is not a number");
  add("covariance_unknown", "fit --log=LOG --covariance=x", "--covariance");
  add("plane_unknown", "fit --log=LOG --plane=yaw", "--plane");
  add("gyro_bias_text", "fit --log=LOG --gyro_bias=abc", "--gyro_bias='abc'");
  add("emit_unknown", "fit --log=LOG --emit=betaflight", "--emit");
  add("unknown_flag", "fit --log=LOG --no_such_flag=1", "no_such_flag");
  add("r0_nan",
      "displacement --r0=nan --beta0_deg=1 --r1=0.1 --beta1_deg=2",
      "--r0=nan: the value must be a finite number");
  add("r0_negative",
      "displacement --r0=-1 --beta0_deg=1 --r1=0.1 --beta1_deg=2",
      "must be >= 0");
  add("r1_huge",
      "displacement --r0=0.1 --beta0_deg=1 --r1=1e9 --beta1_deg=2",
      "r_m = 1e+09; required a finite number in [0, 1000]");
  add("bench_repeats_zero",
      "bench --repeats=0",
      "--repeats=0; required in [1, 1000]");
  add("bench_seeds_negative", "bench --seeds=-5", "--seeds=-5; required");
  add("simulate_rate_nan",
      "simulate --rate_hz=nan --out=x.csv",
      "--rate_hz=nan: the value must be a finite number");
  add("simulate_bad_setting",
      "simulate --set=mass_kg=-1 --out=/nonexistent/x.csv",
      "mass_kg");
  add("unknown_command", "frobnicate", "unknown command 'frobnicate'");
  // `plan` refuses its flags before flying anything (no --log: a bad value
  // must not reach the simulator).
  add("plan_target_zero",
      "plan --target_mm=0",
      "--target_mm=0; required in (0, 1000]");
  add("plan_target_nan",
      "plan --target_mm=nan",
      "--target_mm=nan: the value must be a finite number");
  add("plan_target_beyond",
      "plan --target_mm=1001",
      "--target_mm=1001; required in (0, 1000]");
  add("plan_autopilot_unknown",
      "plan --autopilot=foo",
      "--autopilot=foo; required ardupilot or px4");
  add("plan_mass_zero",
      "plan --mass_kg=0",
      "--mass_kg=0; required in [0.1, 50]");
  add("plan_size_huge", "plan --size_m=5", "--size_m=5; required in [0.05, 3]");
  add("plan_vehicle_with_log",
      "plan --log=flight.bin --mass_kg=2",
      "--mass_kg and --size_m describe a vehicle without --log");
  return c;
}

std::vector<BadCase> PathCases() {
  const std::string f = "paths";
  std::vector<BadCase> c;
  auto export_to = [](std::function<std::string(const std::string&)> out) {
    return [out](const std::string& dir) {
      const std::string log = Write(dir, "log.csv", Csv());
      return "export-problem" + std::string(kWindow) + " --log=" + Q(log) +
             " --out=" + Q(out(dir));
    };
  };
  c.push_back(Case(
      f,
      "out_in_missing_folder",
      export_to([](const std::string& dir) { return dir + "/missing/p.csv"; }),
      "No such file or directory"));
  c.push_back(Case(f,
                   "out_in_read_only_folder",
                   export_to([](const std::string& dir) {
                     // root writes anywhere a mode allows nothing; /sys is
                     // read-only to it as well.
                     if (geteuid() == 0) return std::string("/sys/p.csv");
                     std::filesystem::create_directory(dir + "/ro");
                     chmod((dir + "/ro").c_str(), 0555);
                     return dir + "/ro/p.csv";
                   }),
                   "Permission denied"));
  c.push_back(Case(f,
                   "out_is_a_folder",
                   export_to([](const std::string& dir) { return dir; }),
                   "it is a folder, not a file to replace"));
  c.push_back(Case(f,
                   "out_is_a_fifo_without_reader",
                   export_to([](const std::string& dir) {
                     mkfifo((dir + "/fifo").c_str(), 0600);
                     return dir + "/fifo";
                   }),
                   "it is a FIFO that nothing reads"));
  c.push_back(Case(
      f,
      "out_is_the_input",
      [](const std::string& dir) {
        const std::string log = Write(dir, "log.csv", Csv());
        return "export-problem" + std::string(kWindow) + " --log=" + Q(log) +
               " --out=" + Q(log);
      },
      "is the input"));
  c.push_back(Case(
      f,
      "out_is_the_input_through_a_link",
      [](const std::string& dir) {
        const std::string log = Write(dir, "log.csv", Csv());
        std::filesystem::create_symlink(log, dir + "/link.json");
        return "fit --estimator=varpro" + std::string(kWindow) +
               " --log=" + Q(log) + " --out=" + Q(dir + "/link.json");
      },
      "is the input"));
  c.push_back(Case(
      f,
      "convert_out_is_the_input",
      [](const std::string& dir) {
        const std::string log = Write(dir, "log.csv", Csv());
        return "convert --log=" + Q(log) + " --out=" + Q(dir + "/./log.csv");
      },
      "is the input"));
  c.push_back(Case(
      f,
      "log_is_a_folder",
      [](const std::string& dir) { return "fit --log=" + Q(dir); },
      "it is a folder, not a regular file"));
  c.push_back(Case(
      f,
      "log_is_a_fifo",
      [](const std::string& dir) {
        mkfifo((dir + "/fifo").c_str(), 0600);
        return "inspect " + Q(dir + "/fifo");
      },
      "it is a FIFO, not a regular file (give '-' to read "
      "standard input)"));
  c.push_back(Case(
      f,
      "log_is_dev_zero",
      [](const std::string&) { return "fit --log=/dev/zero"; },
      "it is a character device"));
  c.push_back(Case(
      f,
      "log_missing",
      [](const std::string& dir) {
        return "fit --log=" + Q(dir + "/none.csv");
      },
      "No such file or directory"));
  c.push_back(Case(
      f,
      "problem_is_a_folder",
      [](const std::string& dir) { return "fit --problem=" + Q(dir); },
      "it is a folder"));
  c.push_back(Case(
      f,
      "fit_json_is_dev_zero",
      [](const std::string&) { return "displacement /dev/zero /dev/zero"; },
      "it is a character device"));
  c.push_back(Case(
      f,
      "plan_out_is_a_file",
      [](const std::string& dir) {
        return "plan --out=" + Q(Write(dir, "f", "x"));
      },
      "exists and is not a folder"));
  c.push_back(Case(
      f,
      "bench_out_is_a_file",
      [](const std::string& dir) {
        return "bench --out=" + Q(Write(dir, "f", "x"));
      },
      "exists and is not a folder"));
  c.push_back(Case(
      f,
      "simulate_out_is_stdout",
      [](const std::string&) { return "simulate --out=-"; },
      "--out must name a file"));
  c.push_back(Case(
      f,
      "simulate_out_is_a_folder",
      [](const std::string& dir) {
        std::filesystem::create_directory(dir + "/x.csv");
        return "simulate --scenario=hover_only --out=" + Q(dir + "/x.csv");
      },
      "is not a regular file"));
  c.push_back(Case(
      f,
      "emit_out_is_a_folder",
      [](const std::string& dir) {
        return "fit --estimator=varpro --emit=px4" + std::string(kWindow) +
               " --log=" + Q(Write(dir, "log.csv", Csv())) +
               " --emit_out=" + Q(dir);
      },
      "it is a folder"));
  return c;
}

std::vector<BadCase> AllCases() {
  std::vector<BadCase> all;
  for (auto family : {CsvCases(),
                      ProblemCases(),
                      FitJsonCases(),
                      UlogCases(),
                      DataFlashCases(),
                      FlagCases(),
                      PathCases()}) {
    for (auto& c : family) all.push_back(std::move(c));
  }
  return all;
}

class BadInput : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadInput, ExitsWithTwoAndNamesTheProblem) {
  const BadCase& c = GetParam();
  const std::string dir = testing::MakeTempDir();
  const std::string args = c.args(dir);
  if (args.rfind("bench ", 0) == 0) IMUSYSID_REQUIRE_BENCH();
  const testing::CommandResult run = testing::RunCli(args);
  EXPECT_EQ(run.exit_code, c.exit_code) << run.err;
  EXPECT_THAT(run.err, HasSubstr(c.fragment));
  // One line from the barrier, never a raw control byte from a file.
  for (char ch : run.err) {
    EXPECT_FALSE(ch == '\x1b' || ch == '\0') << "raw control byte in stderr";
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cases,
    BadInput,
    ::testing::ValuesIn(AllCases()),
    [](const ::testing::TestParamInfo<BadCase>& param_info) {
      return param_info.param.family + "_" + param_info.param.name;
    });

// The table's size per family is part of the contract in
// docs/failure-modes.md; a family that shrinks by accident fails here.
TEST(BadInputTable, HasAtLeastEightyCasesOverEveryFamily) {
  EXPECT_GE(AllCases().size(), 80u);
  EXPECT_GE(CsvCases().size(), 15u);
  EXPECT_GE(ProblemCases().size(), 10u);
  EXPECT_GE(FitJsonCases().size(), 15u);
  EXPECT_GE(UlogCases().size(), 5u);
  EXPECT_GE(DataFlashCases().size(), 5u);
  EXPECT_GE(FlagCases().size(), 15u);
  EXPECT_GE(PathCases().size(), 10u);
}

// --- Outputs that are not plain files ---------------------------------------

TEST(OutputPaths, ASymlinkIsWrittenThroughAndStaysALink) {
  const std::string dir = testing::MakeTempDir();
  const std::string log = Write(dir, "log.csv", Csv());
  const std::string target = Write(dir, "target.csv", "old");
  std::filesystem::create_symlink("target.csv", dir + "/link.csv");
  const auto r =
      testing::RunCli("export-problem" + std::string(kWindow) +
                      " --log=" + Q(log) + " --out=" + Q(dir + "/link.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(std::filesystem::is_symlink(dir + "/link.csv"));
  std::ifstream in(target);
  std::string first;
  std::getline(in, first);
  EXPECT_THAT(first, HasSubstr("# imusysid problem file"));
}

TEST(OutputPaths, DevNullStaysADevice) {
  const std::string dir = testing::MakeTempDir();
  const auto r = testing::RunCli("export-problem" + std::string(kWindow) +
                                 " --log=" + Q(Write(dir, "log.csv", Csv())) +
                                 " --out=/dev/null");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(std::filesystem::is_character_file("/dev/null"));
}

TEST(OutputPaths, DashAndDevStdoutStream) {
  const std::string dir = testing::MakeTempDir();
  const std::string log = Write(dir, "log.csv", Csv());
  for (const char* out : {"-", "/dev/stdout"}) {
    const auto r = testing::RunCli("export-problem" + std::string(kWindow) +
                                   " --log=" + Q(log) + " --out=" + out);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_THAT(r.out, HasSubstr("# imusysid problem file")) << out;
  }
}

TEST(OutputPaths, AFifoWithAReaderGetsTheData) {
  const std::string dir = testing::MakeTempDir();
  const std::string fifo = dir + "/fifo";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  // The read end is open before the tool starts (a FIFO without a reader is
  // refused), and drained by a thread so the writer never blocks for good.
  const int fd = open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(fd, 0);
  std::string got;
  std::thread reader([&] {
    char buffer[1 << 16];
    for (int idle = 0; idle < 3000;) {
      const ssize_t n = read(fd, buffer, sizeof(buffer));
      if (n > 0) {
        got.append(buffer, static_cast<std::size_t>(n));
        idle = 0;
      } else if (n == 0 && !got.empty()) {
        break;  // the writer closed its end
      } else {
        ++idle;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
    }
  });
  const std::string log = Write(dir, "log.csv", Csv());
  const auto r = testing::RunCli("export-problem" + std::string(kWindow) +
                                 " --log=" + Q(log) + " --out=" + Q(fifo));
  reader.join();
  close(fd);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(got.substr(0, 40), HasSubstr("# imusysid problem file"));
  EXPECT_EQ(std::filesystem::status(fifo).type(),
            std::filesystem::file_type::fifo);
}

TEST(InputPaths, StandardInputIsReadAsDash) {
  const std::string dir = testing::MakeTempDir();
  const std::string log = Write(dir, "log.csv", Csv());
  // RunCli feeds /dev/null to standard input; this runs the tool itself.
  const std::string cmd = "'" + testing::CliPath() +
                          "' inspect --format=json - < " + Q(log) + " > " +
                          Q(dir + "/out") + " 2>/dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  std::ifstream in(dir + "/out");
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  ASSERT_FALSE(j.is_discarded());
  EXPECT_EQ(j["samples"].get<int>(), kSamples);
}

// Four runs writing one name at once used to leave a log and a truth
// sidecar from different runs; the pair is now renamed into place under a
// lock on the folder.
TEST(OutputPaths, ConcurrentSimulateRunsLeaveAMatchingPair) {
  const std::string dir = testing::MakeTempDir();
  const std::string out = dir + "/pair.csv";
  std::string script =
      "for s in 1 2 3 4; do '" + testing::CliPath() +
      "' simulate --scenario=hover_only --seed=$s --out=" + Q(out) +
      " > /dev/null 2>&1 & done; wait";
  ASSERT_EQ(std::system(script.c_str()), 0);
  std::ifstream log(out);
  std::string line, log_seed;
  while (std::getline(log, line) && line.rfind("#", 0) == 0) {
    if (line.rfind("# seed: ", 0) == 0) log_seed = line.substr(8);
  }
  std::ifstream truth(dir + "/pair.truth.json");
  const nlohmann::json j = nlohmann::json::parse(truth, nullptr, false);
  ASSERT_FALSE(j.is_discarded());
  EXPECT_EQ(log_seed, std::to_string(j["seed"].get<int>()));
  // Nothing but the pair is left behind.
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    (void)entry;
    ++files;
  }
  EXPECT_EQ(files, 2);
}

// --- Strings from files ------------------------------------------------------

// A ULog info string in Latin-1 (one byte that is not UTF-8) aborted
// `inspect --format=json` on the JSON library's exception; the table must
// not pass the byte through either.
TEST(SafeText, ALatin1InfoStringIsEscapedInTablesAndReplacedInJson) {
  const std::string dir = testing::MakeTempDir();
  std::string ulog = testing::SyntheticUlog(kSamples);
  const std::string key = "char[5] sys_name";
  const std::string info = testing::UlogMessageBytes(
      'I',
      std::string(1, static_cast<char>(key.size())) + key + "ab\xe9" + "cd");
  // After the 16-byte header and the 43-byte flag-bits message.
  ulog.insert(16 + 43, info);
  const std::string path = Write(dir, "latin1.ulg", ulog);
  const auto json = testing::RunCli("inspect --format=json " + Q(path));
  ASSERT_EQ(json.exit_code, 0) << json.err;
  const nlohmann::json j = testing::ParseJson(json);
  ASSERT_TRUE(j.is_object());
  EXPECT_THAT(j["vehicle"].get<std::string>(),
              HasSubstr("ab\xef\xbf\xbd"
                        "cd"));
  const auto table = testing::RunCli("inspect " + Q(path));
  ASSERT_EQ(table.exit_code, 0) << table.err;
  EXPECT_THAT(table.out, HasSubstr("ab\\xe9cd"));
  EXPECT_EQ(table.out.find('\xe9'), std::string::npos);
}

// --- A damaged log's fit carries the damage ---------------------------------

TEST(DamagedLogs, AllowDamagedFitsWithAWarning) {
  const std::string dir = testing::MakeTempDir();
  const std::string good = testing::SyntheticUlog(2000);
  const std::string path = Write(
      dir,
      "d.ulg",
      Overwritten(
          good, good.size() / 3, good.size() / 3 + good.size() / 10, '\0'));
  const auto r = testing::RunCli(
      "fit --estimator=varpro --format=json "
      "--allow_damaged --log=" +
      Q(path));
  const nlohmann::json j = testing::ParseJson(r);
  ASSERT_TRUE(j.is_object()) << r.err;
  bool damaged = false;
  for (const auto& w : j["warnings"]) {
    damaged = damaged || w["code"] == "damaged_log";
  }
  EXPECT_TRUE(damaged) << j["warnings"].dump();
}

}  // namespace
}  // namespace imusysid

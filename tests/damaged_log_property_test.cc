// Properties of damaged binary logs: every truncation and a sample of
// single-byte flips of a small ULog and DataFlash log either read or fail
// with a Status (never a crash: this runs under ASan/UBSan in CI), a log
// read with bytes skipped always carries a damage note, and through the
// command line such inputs exit 0 or 2, with a damaged_log warning on every
// fit of a log the reader had to repair.

#include <sys/resource.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "imusysid/log_reader.h"
#include "imusysid/log_sanity.h"
#include "imusysid/preprocess.h"
#include "imusysid/segments.h"
#include "nlohmann/json.hpp"
#include "tests/synthetic_logs.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

// Small enough that reading every prefix stays within a few seconds under
// the sanitizers, long enough for several hundred IMU records.
constexpr int kInProcessSamples = 160;
// For the command-line runs: 2.4 s at 250 Hz, so most damaged variants
// still hold the >= 100 samples over >= 1 s a fit needs.
constexpr int kCliSamples = 600;
constexpr int kFlipsInProcess = 2000;
constexpr int kCliRuns = 12;

struct Outcome {
  bool read = false;
  bool skipped = false;
};

// Reads `bytes` as the CLI would (no whole-log gap check for binary logs),
// and when that works runs the pre-fit gates and preprocessing on the
// fallback segment, the path `fit` takes. Checks the damage property.
Outcome ReadAndCheck(const std::string& bytes, const std::string& what) {
  LogReadOptions options;
  options.max_gap_factor = 0.0;
  StatusOr<FlightLog> log = ParseFlightLog(bytes, "x", options);
  Outcome outcome;
  if (!log.ok()) {
    EXPECT_FALSE(log.status().message().empty()) << what;
    return outcome;
  }
  outcome.read = true;
  outcome.skipped = log->skipped_bytes > 0;
  if (outcome.skipped) {
    EXPECT_FALSE(DamageSummary(*log).empty()) << what;
    EXPECT_LE(log->skipped_bytes, log->file_bytes) << what;
  }
  if (CheckAccelerometer(*log).ok()) {
    PreprocessOptions po;
    StatusOr<std::string> fallback = ApplyFallbackSegment(*log, &po);
    if (fallback.ok()) {
      StatusOr<PreprocessResult> pre = Preprocess(*log, po);
      if (pre.ok()) {
        for (double f : pre->data.planar.f_x) {
          EXPECT_TRUE(std::isfinite(f)) << what;
          if (!std::isfinite(f)) break;
        }
      }
    }
  }
  return outcome;
}

void EveryTruncation(const std::string& good) {
  int read = 0, skipped = 0;
  for (std::size_t length = 0; length <= good.size(); ++length) {
    const Outcome o = ReadAndCheck(good.substr(0, length),
                                   "truncated to " + std::to_string(length));
    read += o.read;
    skipped += o.skipped;
  }
  // The property is not vacuous: many prefixes read, and most of those cut
  // a record in two.
  EXPECT_GT(read, static_cast<int>(good.size() / 2));
  EXPECT_GT(skipped, read / 2);
}

void SampledFlips(const std::string& good, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::size_t> where(0, good.size() - 1);
  std::uniform_int_distribution<int> bit(0, 7);
  int read = 0;
  for (int k = 0; k < kFlipsInProcess; ++k) {
    std::string bytes = good;
    const std::size_t at = where(rng);
    bytes[at] = static_cast<char>(bytes[at] ^ (1 << bit(rng)));
    read += ReadAndCheck(bytes, "byte " + std::to_string(at) + " flipped").read;
  }
  EXPECT_GT(read, kFlipsInProcess / 2);
}

TEST(DamagedUlog, EveryTruncationReadsOrFailsCleanly) {
  EveryTruncation(testing::SyntheticUlog(kInProcessSamples));
}

TEST(DamagedUlog, SampledByteFlipsReadOrFailCleanly) {
  SampledFlips(testing::SyntheticUlog(kInProcessSamples), 11);
}

TEST(DamagedDataFlash, EveryTruncationReadsOrFailsCleanly) {
  EveryTruncation(testing::SyntheticDataFlash(kInProcessSamples));
}

TEST(DamagedDataFlash, SampledByteFlipsReadOrFailCleanly) {
  SampledFlips(testing::SyntheticDataFlash(kInProcessSamples), 12);
}

// Found by the byte flips: one bit in the last sample's time stamp put it
// 100 days ahead, and preprocessing resampled the whole span onto a uniform
// grid (2e9 points, killed for memory at 22 GB). Now it reads, preprocesses
// the gap-free part and stays small.
TEST(DamagedUlog, ATimeStampDaysAheadIsNotResampled) {
  const std::string bytes = testing::SyntheticUlog(
      kInProcessSamples, [](testing::SyntheticSample* s) {
        if (s->t_s > 2.0 + 0.004 * (kInProcessSamples - 1.5)) s->t_s += 8.8e6;
      });
  // The process's peak before: earlier tests in the same process may have
  // raised it past any fixed bound (1.2 GB when every case runs in one
  // process), so the test bounds what this case adds to it.
  struct rusage before;
  ASSERT_EQ(getrusage(RUSAGE_SELF, &before), 0);
  LogReadOptions options;
  options.max_gap_factor = 0.0;
  StatusOr<FlightLog> log = ParseFlightLog(bytes, "late.ulg", options);
  ASSERT_TRUE(log.ok()) << log.status().message();
  ASSERT_GT(log->t_s.back(), 8.8e6);
  PreprocessOptions po;
  StatusOr<std::string> fallback = ApplyFallbackSegment(*log, &po);
  ASSERT_TRUE(fallback.ok()) << fallback.status().message();
  EXPECT_LT(po.t_end, 3.0);
  StatusOr<PreprocessResult> pre = Preprocess(*log, po);
  // Either answer is fine; the point is the memory it took to give it.
  (void)pre;
  struct rusage after;
  ASSERT_EQ(getrusage(RUSAGE_SELF, &after), 0);
  EXPECT_LT(after.ru_maxrss - before.ru_maxrss, 1024L * 1024L)
      << "growth of the peak RSS in KB";
}

// Through the tool: exit 0 or 2 only, and a fit of a log with skipped bytes
// always says so.
void CliRuns(const std::string& good, const std::string& name, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::size_t> cut(good.size() * 3 / 5,
                                                 good.size() - 1);
  std::uniform_int_distribution<std::size_t> where(0, good.size() - 1);
  const std::string dir = testing::MakeTempDir();
  int fitted_damaged = 0;
  for (int k = 0; k < 2 * kCliRuns; ++k) {
    std::string bytes = good;
    if (k % 2 == 0) {
      bytes.resize(cut(rng));
    } else {
      const std::size_t at = where(rng);
      bytes[at] = static_cast<char>(bytes[at] ^ 0x10);
    }
    LogReadOptions options;
    options.max_gap_factor = 0.0;
    StatusOr<FlightLog> log = ParseFlightLog(bytes, name, options);
    const bool skipped = log.ok() && log->skipped_bytes > 0;
    const std::string path = dir + "/" + std::to_string(k) + name;
    {
      std::ofstream out(path, std::ios::binary);
      out << bytes;
    }
    const testing::CommandResult r = testing::RunCli(
        "fit --estimator=varpro --format=json --allow_damaged --log='" + path +
        "'");
    ASSERT_TRUE(r.exit_code == 0 || r.exit_code == 2)
        << "exit " << r.exit_code << " for " << path << ": " << r.err;
    if (r.exit_code != 0 || !skipped) continue;
    const nlohmann::json j = nlohmann::json::parse(r.out, nullptr, false);
    ASSERT_TRUE(j.is_object()) << r.out;
    bool warned = false;
    for (const auto& w : j["warnings"]) {
      warned = warned || w["code"] == "damaged_log";
    }
    EXPECT_TRUE(warned) << path << ": " << j["warnings"].dump();
    ++fitted_damaged;
  }
  EXPECT_GT(fitted_damaged, 0) << "no damaged log was fitted: vacuous";
}

TEST(DamagedUlog, CommandLineExitsZeroOrTwoAndWarns) {
  CliRuns(testing::SyntheticUlog(kCliSamples), ".ulg", 21);
}

TEST(DamagedDataFlash, CommandLineExitsZeroOrTwoAndWarns) {
  CliRuns(testing::SyntheticDataFlash(kCliSamples), ".bin", 22);
}

}  // namespace
}  // namespace imusysid

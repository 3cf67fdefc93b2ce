// The tracker's inputs and the `track` command: the streamed CSV reader's
// refusals (line and field named), the options' checks, and the command
// streaming its estimates before its input ends and stopping on a bad row
// with every estimate before it printed.

#include "imusysid/track3d.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "Eigen/Cholesky"
#include "gtest/gtest.h"
#include "src/track/track3d_internal.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

constexpr const char* kHeader = "t,ax,ay,az,gx,gy,gz,qw,qx,qy,qz,vn,ve,vd";

TEST(Track3dCsvStream, ReadsRowsInFrdAndFlu) {
  Track3dCsvStream frd;
  Track3dSample s;
  EXPECT_FALSE(*frd.Line("# frame: frd", &s));
  EXPECT_FALSE(*frd.Line(kHeader, &s));
  StatusOr<bool> got = frd.Line("0.5,1,2,3,4,5,6,1,0,0,0,7,8,9", &s);
  ASSERT_TRUE(got.ok()) << got.status().ToString();
  EXPECT_TRUE(*got);
  EXPECT_EQ(s.t_s, 0.5);
  EXPECT_EQ(s.accel_frd_mps2, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(s.gyro_frd_radps, Eigen::Vector3d(4, 5, 6));
  EXPECT_EQ(s.velocity_ned_mps, Eigen::Vector3d(7, 8, 9));

  Track3dCsvStream flu;
  EXPECT_FALSE(*flu.Line("# frame: flu", &s));
  EXPECT_FALSE(*flu.Line(kHeader, &s));
  ASSERT_TRUE(*flu.Line("0.5,1,2,3,4,5,6,1,0,0,0,7,8,9", &s));
  // FLU → FRD flips y and z of both sensors; the estimator's channels are
  // NED whatever the frame.
  EXPECT_EQ(s.accel_frd_mps2, Eigen::Vector3d(1, -2, -3));
  EXPECT_EQ(s.gyro_frd_radps, Eigen::Vector3d(4, -5, -6));
  EXPECT_EQ(s.velocity_ned_mps, Eigen::Vector3d(7, 8, 9));
}

TEST(Track3dCsvStream, EmptyEstimatorCellsAreMissing) {
  Track3dCsvStream in;
  Track3dSample s;
  ASSERT_FALSE(*in.Line(kHeader, &s));
  ASSERT_TRUE(*in.Line("0,0,0,-9.8,0,0,0,,,,,,,", &s));
  EXPECT_TRUE(std::isnan(s.attitude_wxyz[0]));
  EXPECT_TRUE(std::isnan(s.velocity_ned_mps[2]));
}

TEST(Track3dCsvStream, BadRowsNameLineAndField) {
  struct Case {
    std::string row;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"0.1,abc,0,-9.8,0,0,0,1,0,0,0,0,0,0", "line 3, field 'ax': 'abc'"},
      {"0.1,0,0,nan,0,0,0,1,0,0,0,0,0,0", "line 3, field 'az': 'nan'"},
      {"0.1,0,0,-9.8,0,0,0,1,0,0,0,0,0,inf", "line 3, field 'vd': 'inf'"},
      {"0,0,0,-9.8,0,0,0,1,0,0,0,0,0,0", "line 3, field 't'"},
      {"-1,0,0,-9.8,0,0,0,1,0,0,0,0,0,0", "line 3, field 't'"},
      {"0.1,0,0,-9.8", "line 3: 4 fields, the header has 14"},
      {"0.1,,0,-9.8,0,0,0,1,0,0,0,0,0,0", "line 3, field 'ax': ''"},
  };
  for (const Case& c : cases) {
    Track3dCsvStream in;
    Track3dSample s;
    ASSERT_FALSE(*in.Line(kHeader, &s));
    ASSERT_TRUE(*in.Line("0,0,0,-9.8,0,0,0,1,0,0,0,0,0,0", &s));
    StatusOr<bool> got = in.Line(c.row, &s);
    ASSERT_FALSE(got.ok()) << c.row;
    EXPECT_EQ(got.status().code(), StatusCode::kInvalidArgument);
    EXPECT_NE(got.status().message().find(c.expected), std::string::npos)
        << got.status().message();
  }
  Track3dCsvStream no_header;
  Track3dSample s;
  StatusOr<bool> got = no_header.Line("t,ax,ay,az,gx,gy,gz", &s);
  ASSERT_FALSE(got.ok());
  EXPECT_NE(got.status().message().find("line 1: header has no column 'qw'"),
            std::string::npos)
      << got.status().message();
}

// Rows at `rate_hz` from t = 0 (FRD, at rest): `count` of them, the k-th
// at time k / rate_hz.
std::vector<std::string> RestRows(int count, double rate_hz) {
  std::vector<std::string> rows;
  for (int k = 0; k < count; ++k) {
    std::ostringstream row;
    row.precision(17);
    row << k / rate_hz << ",0,0,-9.8,0,0,0,1,0,0,0,0,0,0";
    rows.push_back(row.str());
  }
  return rows;
}

// Feeds `lines`; the first error, or OK after Finish.
Status FeedStream(const std::vector<std::string>& lines, Track3dCsvStream* in) {
  Track3dSample s;
  for (const std::string& line : lines) {
    StatusOr<bool> got = in->Line(line, &s);
    if (!got.ok()) return got.status();
  }
  return in->Finish();
}

std::vector<std::string> WithRateHeader(const std::string& rate,
                                        int rows,
                                        double rate_hz) {
  std::vector<std::string> lines = {"# rate_hz: " + rate, kHeader};
  for (const std::string& r : RestRows(rows, rate_hz)) lines.push_back(r);
  return lines;
}

// The rate is the time column's; a `# rate_hz:` that disagrees with it (a
// 100 Hz header on 400 Hz rows left z 76 mm off) or is not a rate is
// refused, naming its line.
TEST(Track3dCsvStream, RateComesFromTheTimeColumnAndTheHeaderIsChecked) {
  {
    Track3dCsvStream in;
    const Status st = FeedStream(WithRateHeader("100", 200, 400.0), &in);
    ASSERT_FALSE(st.ok());
    EXPECT_EQ(st.code(), StatusCode::kInvalidArgument);
    EXPECT_NE(st.message().find("line 1, metadata 'rate_hz': '100' Hz "
                                "disagrees with the time column's 400 Hz"),
              std::string::npos)
        << st.message();
  }
  // Equal, and within the tolerance either way: accepted, at the time
  // column's rate.
  for (const char* rate : {"400", "400.0", "381", "419"}) {
    Track3dCsvStream in;
    const Status st = FeedStream(WithRateHeader(rate, 200, 400.0), &in);
    EXPECT_TRUE(st.ok()) << rate << ": " << st.message();
    EXPECT_NEAR(in.rate_hz(), 400.0, 1e-6) << rate;
  }
  for (const char* rate : {"379", "421"}) {
    Track3dCsvStream in;
    EXPECT_FALSE(FeedStream(WithRateHeader(rate, 200, 400.0), &in).ok())
        << rate;
  }
  // Not a rate.
  for (const char* rate : {"abc", "nan", "0", "-400", "inf", "400Hz", ""}) {
    Track3dCsvStream in;
    const Status st = FeedStream(WithRateHeader(rate, 200, 400.0), &in);
    ASSERT_FALSE(st.ok()) << rate;
    EXPECT_NE(st.message().find("line 1, metadata 'rate_hz': '" +
                                std::string(rate) + "' is not a rate"),
              std::string::npos)
        << st.message();
  }
  // Without a header the time column alone; a stream shorter than the
  // intervals the rate waits for gets it (and the check) at its end.
  {
    Track3dCsvStream in;
    std::vector<std::string> lines = {kHeader};
    for (const std::string& r : RestRows(10, 250.0)) lines.push_back(r);
    Track3dSample s;
    for (const std::string& line : lines) ASSERT_TRUE(in.Line(line, &s).ok());
    EXPECT_EQ(in.rate_hz(), 0.0);
    ASSERT_TRUE(in.Finish().ok());
    EXPECT_NEAR(in.rate_hz(), 250.0, 1e-6);
    Track3dCsvStream short_in;
    EXPECT_FALSE(FeedStream(WithRateHeader("100", 10, 250.0), &short_in).ok());
  }
  // A header after the rate is known is checked at once.
  {
    Track3dCsvStream in;
    std::vector<std::string> lines = {kHeader};
    for (const std::string& r : RestRows(100, 400.0)) lines.push_back(r);
    lines.push_back("# rate_hz: 100");
    const Status st = FeedStream(lines, &in);
    ASSERT_FALSE(st.ok());
    EXPECT_NE(st.message().find("line 102, metadata 'rate_hz'"),
              std::string::npos)
        << st.message();
  }
}

// The CSV reader's hole in time (10 median intervals, CsvReadOptions::
// max_gap_factor): refused in the stream too, also among the rows read
// before the rate was known.
TEST(Track3dCsvStream, RefusesAHoleInTimeAsTheReaderDoes) {
  const double dt = 1.0 / 400.0;
  auto rows_with_step = [&](int at, double step) {
    std::vector<std::string> lines = {kHeader};
    double t = 0.0;
    for (int k = 0; k < 200; ++k) {
      std::ostringstream row;
      row.precision(17);
      row << t << ",0,0,-9.8,0,0,0,1,0,0,0,0,0,0";
      lines.push_back(row.str());
      t += k + 1 == at ? step : dt;
    }
    return lines;
  };
  {
    Track3dCsvStream in;
    const Status st = FeedStream(rows_with_step(150, 1e6), &in);
    ASSERT_FALSE(st.ok());
    // Row 150 (0-based) is on line 152.
    EXPECT_NE(st.message().find("line 152, field 't': gap of 1e+06 s"),
              std::string::npos)
        << st.message();
    EXPECT_NE(st.message().find("exceeds 10 x the median interval 0.0025 s"),
              std::string::npos)
        << st.message();
  }
  {
    Track3dCsvStream in;
    const Status st = FeedStream(rows_with_step(20, 1e6), &in);
    ASSERT_FALSE(st.ok());
    EXPECT_NE(st.message().find("line 22, field 't': gap of 1e+06 s"),
              std::string::npos)
        << st.message();
  }
  for (int at : {20, 150}) {
    Track3dCsvStream in;
    const Status st = FeedStream(rows_with_step(at, 9.99 * dt), &in);
    EXPECT_TRUE(st.ok()) << st.message();
    Track3dCsvStream over;
    EXPECT_FALSE(FeedStream(rows_with_step(at, 10.01 * dt), &over).ok());
  }
}

TEST(Track3dCsvStream, FrameLinesAsTheReaderTakesThemAndTheOverride) {
  Track3dSample s;
  const std::string row = "0.5,1,2,3,4,5,6,1,0,0,0,7,8,9";
  Track3dCsvStream contradicted;
  ASSERT_TRUE(contradicted.Line("# frame: frd", &s).ok());
  StatusOr<bool> got = contradicted.Line("# frame: flu", &s);
  ASSERT_FALSE(got.ok());
  EXPECT_NE(got.status().message().find(
                "line 2, metadata 'frame': 'flu' contradicts 'frame: frd' on "
                "line 1"),
            std::string::npos)
      << got.status().message();
  Track3dCsvStream unknown;
  got = unknown.Line("# frame: nwu", &s);
  ASSERT_FALSE(got.ok());
  EXPECT_NE(got.status().message().find("line 1, metadata 'frame'"),
            std::string::npos);
  // --frame=flu over a file's frd.
  Track3dCsvStream overridden(Frame::kFlu);
  ASSERT_TRUE(overridden.Line("# frame: FRD", &s).ok());
  ASSERT_TRUE(overridden.Line(kHeader, &s).ok());
  ASSERT_TRUE(*overridden.Line(row, &s));
  EXPECT_EQ(s.accel_frd_mps2, Eigen::Vector3d(1, -2, -3));
}

// A field of 10 MB is quoted cut to 40 characters, as fit's reader does.
TEST(Track3dCsvStream, CutsLongFieldsInMessages) {
  const std::string huge(10 << 20, '7');
  const std::string bad = huge + "x";
  const std::vector<std::string> rows = {
      "0.1," + bad + ",0,-9.8,0,0,0,1,0,0,0,0,0,0",
      "0.1,0,0,-9.8,0,0,0,1,0,0,0,0,0," + bad,
      "0,0,0,-9.8,0,0,0,1,0,0,0,0,0,0",  // replaced by the huge time below
      "# rate_hz: " + bad,
      "# frame: " + bad,
      "# rate_hz: " + huge,  // beyond a double: infinite
  };
  for (std::size_t i = 0; i < rows.size(); ++i) {
    Track3dCsvStream in;
    Track3dSample s;
    ASSERT_FALSE(*in.Line(kHeader, &s));
    ASSERT_TRUE(*in.Line("0,0,0,-9.8,0,0,0,1,0,0,0,0,0,0", &s));
    std::string row = rows[i];
    if (i == 2) row = "-" + huge + ",0,0,-9.8,0,0,0,1,0,0,0,0,0,0";
    const Status st = in.Line(row, &s).status();
    ASSERT_FALSE(st.ok()) << i;
    EXPECT_LT(st.message().size(), 300u) << i << ": " << st.message().size();
    EXPECT_NE(st.message().find("..."), std::string::npos) << st.message();
  }
}

TEST(Track3dOptions, RefusesOutOfRangeNamingTheField) {
  Track3dOptions o;
  EXPECT_TRUE(o.Validate().ok());
  o.rate_hz = 10.0;
  EXPECT_NE(o.Validate().message().find("rate_hz"), std::string::npos);
  o = Track3dOptions();
  o.mean_time_between_false_alarms_s = 1.0;
  EXPECT_NE(o.Validate().message().find("mean_time_between_false_alarms_s"),
            std::string::npos);
  o = Track3dOptions();
  o.window_s = 1.0;
  EXPECT_NE(o.Validate().message().find("window_s"), std::string::npos);
  EXPECT_FALSE(Track3d::Create(o).ok());
}

TEST(Track3d, OnTheGroundNothingIsEstimated) {
  StatusOr<Track3d> tracker = Track3d::Create(Track3dOptions());
  ASSERT_TRUE(tracker.ok());
  Track3dSample s;
  s.accel_frd_mps2 = Eigen::Vector3d(0.0, 0.0, -9.80665);
  for (int k = 0; k < 4000; ++k) {
    s.t_s = k / 400.0;
    EXPECT_FALSE(tracker->Update(s));
  }
  const Track3dEstimate e = tracker->Estimate();
  EXPECT_EQ(e.state, Track3dState::kOnGround);
  EXPECT_FALSE(e.valid);
  EXPECT_TRUE(std::isnan(e.position_frd_m.x()));
  EXPECT_FALSE(tracker->calibration().done);
}

// The tracker's σ̂ against the closed form of weighted least squares on a
// case small enough to write out: three blocks of 8 rows (11 coefficients
// and a target each, fixed numbers), folded with a forgetting factor of
// 1/2 per block, so that the rows weigh w = 1/4, 1/2, 1 by age. Then
//   β = (AᵀWA)⁻¹ AᵀWy,  σ² = Σ w r² / (Σw − 11),
//   Cov = σ² (AᵀWA)⁻¹ Σw²/Σw,  Σw = 8 (1/4 + 1/2 + 1) = 14,
//   Σw² = 8 (1/16 + 1/4 + 1) = 10.5,
// computed here from A, y and w directly, not from the tracker's factors.
TEST(Track3dSigma, ForgettingMatchesTheWeightedLeastSquaresClosedForm) {
  using track3d_internal::Factor;
  using track3d_internal::kM;
  constexpr int kRowsPerBlock = 8;
  constexpr int kBlocks = 3;
  auto pipe = std::make_unique<track3d_internal::Pipeline>();
  Track3dOptions o;
  o.memory_s = o.block_s / std::log(2.0);
  pipe->Init(o, 0.0, 0.0, 0.0, false);
  ASSERT_NEAR(pipe->lambda_block, 0.5, 1e-15);
  // Fixed, well-conditioned rows: a_ij = sin(1 + 3i + 7j) + (i mod 11 == j),
  // target y_i = Σ_j a_ij (j + 1)/10 + 0.3 cos(5i) (a residual to estimate
  // σ² from).
  const int n = kRowsPerBlock * kBlocks;
  Eigen::MatrixXd a(n, kM);
  Eigen::VectorXd y(n);
  for (int i = 0; i < n; ++i) {
    y[i] = 0.3 * std::cos(5.0 * i);
    for (int j = 0; j < kM; ++j) {
      a(i, j) = std::sin(1.0 + 3.0 * i + 7.0 * j) + (i % kM == j ? 1.0 : 0.0);
      y[i] += a(i, j) * (j + 1) / 10.0;
    }
  }
  for (int b = 0; b < kBlocks; ++b) {
    pipe->current = track3d_internal::Block();
    for (int i = b * kRowsPerBlock; i < (b + 1) * kRowsPerBlock; ++i) {
      double row[track3d_internal::kC];
      for (int j = 0; j < kM; ++j) row[j] = a(i, j);
      row[kM] = y[i];
      track3d_internal::FoldRow(&pipe->current.r, row);
    }
    pipe->current.rows = kRowsPerBlock;
    pipe->EndBlock(0.5 * (b + 1));
  }
  // The weights by age, written out.
  Eigen::VectorXd w(n);
  for (int i = 0; i < n; ++i) {
    const int age = kBlocks - 1 - i / kRowsPerBlock;
    w[i] = std::pow(0.5, age);
  }
  const double sum_w = w.sum();
  const double sum_w2 = w.squaredNorm();
  ASSERT_DOUBLE_EQ(sum_w, 14.0);
  ASSERT_DOUBLE_EQ(sum_w2, 10.5);
  const Eigen::MatrixXd info = a.transpose() * w.asDiagonal() * a;
  const Eigen::MatrixXd info_inv =
      info.ldlt().solve(Eigen::MatrixXd::Identity(kM, kM));
  const Eigen::VectorXd beta = info_inv * (a.transpose() * w.asDiagonal() * y);
  const Eigen::VectorXd r = y - a * beta;
  const double sigma2 = r.dot(w.asDiagonal() * r) / (sum_w - kM);
  const Eigen::Matrix3d expected =
      sigma2 * sum_w2 / sum_w * info_inv.topLeftCorner<3, 3>();

  auto check = [&](const char* what) {
    SCOPED_TRACE(what);
    EXPECT_NEAR(pipe->main_rows, sum_w, 1e-12);
    EXPECT_NEAR(pipe->main_rows_sq, sum_w2, 1e-12);
    Eigen::Vector3d p;
    Eigen::Matrix3d cov;
    ASSERT_TRUE(pipe->PositionOf(
        pipe->main, pipe->main_rows, pipe->main_rows_sq, &p, &cov));
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(p[k], beta[k], 1e-9 * (1.0 + std::abs(beta[k])));
      EXPECT_NEAR(std::sqrt(cov(k, k)),
                  std::sqrt(expected(k, k)),
                  1e-9 * std::sqrt(expected(k, k)))
          << k;
    }
  };
  // As the blocks were folded one by one, and as the factor is rebuilt
  // from the ring (after a restart) with each block's weight λ^age.
  check("folded block by block");
  pipe->RebuildMain();
  check("rebuilt from the ring");
}

// The simulated figure-eight as a CSV (gentle sensors: the command's
// output, not its accuracy, is under test), once per binary.
const std::string& FigureEightCsv() {
  static const std::string path = [] {
    const std::string out = testing::MakeTempDir() + "/F.csv";
    const auto r = testing::RunCli(
        "simulate --scenario=figure8_3d --sensor_profile=gentle --out=" + out);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return out;
  }();
  return path;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The command run with its standard input and output on pipes.
class Child {
 public:
  explicit Child(const std::vector<std::string>& args,
                 const std::string& err_path = "/dev/null") {
    signal(SIGPIPE, SIG_IGN);
    int in[2], out[2];
    EXPECT_EQ(pipe(in), 0);
    EXPECT_EQ(pipe(out), 0);
    pid_ = fork();
    if (pid_ == 0) {
      dup2(in[0], 0);
      dup2(out[1], 1);
      const int err =
          open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (err >= 0) dup2(err, 2);
      close(in[1]);
      close(out[0]);
      std::vector<char*> argv;
      std::string cli = testing::CliPath();
      argv.push_back(cli.data());
      std::vector<std::string> copy = args;
      for (std::string& a : copy) argv.push_back(a.data());
      argv.push_back(nullptr);
      execv(cli.c_str(), argv.data());
      _exit(127);
    }
    close(in[0]);
    close(out[1]);
    to_ = in[1];
    from_ = out[0];
  }
  // Stops where the command has stopped reading (it refused its input
  // before the end): a write to its closed pipe fails with EPIPE, SIGPIPE
  // being ignored.
  void Write(const std::string& text) {
    std::size_t done = 0;
    while (done < text.size()) {
      const ssize_t n = write(to_, text.data() + done, text.size() - done);
      if (n <= 0) return;
      done += static_cast<std::size_t>(n);
    }
  }
  // One line of output, waiting up to `timeout_s`; empty on timeout.
  std::string ReadLine(double timeout_s) {
    const auto end = std::chrono::steady_clock::now() +
                     std::chrono::duration<double>(timeout_s);
    while (true) {
      const auto nl = buffer_.find('\n');
      if (nl != std::string::npos) {
        std::string line = buffer_.substr(0, nl);
        buffer_.erase(0, nl + 1);
        return line;
      }
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          end - std::chrono::steady_clock::now());
      if (left.count() <= 0) return "";
      pollfd p{from_, POLLIN, 0};
      if (poll(&p, 1, static_cast<int>(left.count())) <= 0) continue;
      char chunk[4096];
      const ssize_t n = read(from_, chunk, sizeof(chunk));
      if (n <= 0) return "";
      buffer_.append(chunk, static_cast<std::size_t>(n));
    }
  }
  // Closes the input; the rest of the output and the exit code.
  int Finish(std::string* rest) {
    close(to_);
    char chunk[4096];
    ssize_t n;
    while ((n = read(from_, chunk, sizeof(chunk))) > 0) {
      buffer_.append(chunk, static_cast<std::size_t>(n));
    }
    *rest = buffer_;
    close(from_);
    int status = 0;
    waitpid(pid_, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

 private:
  pid_t pid_ = -1;
  int to_ = -1, from_ = -1;
  std::string buffer_;
};

// The command with `input` on its standard input: exit code, stdout and
// stderr.
testing::CommandResult RunWithInput(const std::string& input) {
  const std::string err_path = testing::MakeTempDir() + "/stderr";
  Child child({"track", "--log=-"}, err_path);
  child.Write(input);
  testing::CommandResult r;
  r.exit_code = child.Finish(&r.out);
  r.err = ReadFile(err_path);
  return r;
}

TEST(TrackCli, StreamsItsFirstEstimateBeforeTheInputEnds) {
  const std::string csv = ReadFile(FigureEightCsv());
  ASSERT_GT(csv.size(), 1000u);
  const std::size_t half = csv.find('\n', csv.size() / 2) + 1;
  Child child({"track", "--log=-"});
  child.Write(csv.substr(0, half));
  // Half of the rows in, and the pipe still open: an estimate is out.
  const std::string first = child.ReadLine(20.0);
  ASSERT_FALSE(first.empty()) << "no estimate before the input ended";
  const nlohmann::json j = nlohmann::json::parse(first);
  EXPECT_EQ(j["t"].get<double>(), 0.0);
  EXPECT_EQ(j["state"], "on_ground");
  EXPECT_TRUE(j.contains("imu_position_frd_m"));
  EXPECT_TRUE(j.contains("imu_position_frd_stderr_m"));
  child.Write(csv.substr(half));
  std::string rest;
  EXPECT_EQ(child.Finish(&rest), 0);
  // One line a second of the 68 s flight, the last ones tracking or, after
  // touchdown, on the ground; some tracking with a position.
  std::istringstream lines(rest);
  std::string line;
  int tracking = 0, total = 1;
  while (std::getline(lines, line)) {
    ++total;
    const nlohmann::json e = nlohmann::json::parse(line);
    if (e.value("state", "") == "tracking") {
      ++tracking;
      EXPECT_TRUE(e["imu_position_frd_m"][0].is_number()) << line;
    }
  }
  EXPECT_EQ(total, 68);
  EXPECT_GE(tracking, 25);
}

TEST(TrackCli, BadRowEndsWithExitTwoAfterTheEstimatesBeforeIt) {
  const std::string csv = ReadFile(FigureEightCsv());
  // Cut after ~10 s of rows (the header and metadata first) and append a
  // row with text in a number.
  std::istringstream in(csv);
  std::string line, head;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    head += line + "\n";
    if (line_no > 10 && line.rfind("10.0025,", 0) == 0) break;
  }
  ASSERT_GT(line_no, 4000);
  const auto r =
      RunWithInput(head + "10.005,0.1,x1,-9.8,0,0,0,1,0,0,0,0,0,0\n");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("line " + std::to_string(line_no + 1) +
                       ", field 'ay': 'x1' is not a number"),
            std::string::npos)
      << r.err;
  // Every estimate before it: t = 0 … 10 s, one a second.
  std::istringstream out(r.out);
  int printed = 0;
  double last_t = -1.0;
  while (std::getline(out, line)) {
    last_t = nlohmann::json::parse(line)["t"].get<double>();
    ++printed;
  }
  EXPECT_EQ(printed, 11);
  // An estimate's time is that of the IMU sample it has reached, the
  // estimator's delay (20 ms, held until the calibration) behind the input.
  EXPECT_NEAR(last_t, 10.0, 0.03);

  // Time going backwards and NaN alike.
  const auto r2 = RunWithInput(head + "9.5,0.1,0,-9.8,0,0,0,1,0,0,0,0,0,0\n");
  EXPECT_EQ(r2.exit_code, 2);
  EXPECT_NE(r2.err.find("field 't': time '9.5' does not increase"),
            std::string::npos)
      << r2.err;
  const auto r3 =
      RunWithInput(head + "10.005,0.1,0,-9.8,nan,0,0,1,0,0,0,0,0,0\n");
  EXPECT_EQ(r3.exit_code, 2);
  EXPECT_NE(r3.err.find("field 'gx': 'nan' is not a finite number"),
            std::string::npos)
      << r3.err;
}

// `fit`'s checks in `track`, on the same simulated figure-eight (FRD, 400 Hz
// rows, `# rate_hz: 400`).
std::string FigureEightWithRateHeader(const std::string& rate) {
  std::string csv = ReadFile(FigureEightCsv());
  const std::size_t at = csv.find("# rate_hz: 400\n");
  EXPECT_NE(at, std::string::npos);
  return csv.replace(at, 15, "# rate_hz: " + rate + "\n");
}

int LineOf(const std::string& csv, const std::string& text) {
  const std::size_t at = csv.find(text);
  EXPECT_NE(at, std::string::npos) << text;
  return 1 + static_cast<int>(std::count(csv.begin(), csv.begin() + at, '\n'));
}

TEST(TrackCli, RateHeaderDisagreeingOrMalformedIsExitTwo) {
  const std::string csv = FigureEightWithRateHeader("100");
  const std::string line =
      "line " + std::to_string(LineOf(csv, "# rate_hz:")) + ", ";
  const auto r = RunWithInput(csv);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("stdin: " + line +
                       "metadata 'rate_hz': '100' Hz disagrees with the "
                       "time column's 400 Hz"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.out, "");  // refused before anything was tracked
  for (const char* rate : {"abc", "nan", "0", "-400"}) {
    const auto bad = RunWithInput(FigureEightWithRateHeader(rate));
    EXPECT_EQ(bad.exit_code, 2) << rate;
    EXPECT_NE(
        bad.err.find(line + "metadata 'rate_hz': '" + rate + "' is not a rate"),
        std::string::npos)
        << bad.err;
  }
}

// A hole of 10^6 s after 10 s of rows: exit 2 naming the row, after the
// estimates before it.
TEST(TrackCli, HoleInTimeOnStandardInputIsExitTwo) {
  std::istringstream in(ReadFile(FigureEightCsv()));
  std::string line, head;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    head += line + "\n";
    if (line_no > 10 && line.rfind("10.0025,", 0) == 0) break;
  }
  const auto r =
      RunWithInput(head + "1000010.005,0,0,-9.8,0,0,0,1,0,0,0,0,0,0\n");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("line " + std::to_string(line_no + 1) +
                       ", field 't': gap of 1e+06 s"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 11);
  // Just under the reader's threshold (10 intervals of 2.5 ms): tracked on.
  const auto ok = RunWithInput(head + "10.0274,0,0,-9.8,0,0,0,1,0,0,0,0,0,0\n");
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
}

// --frame=flu on an FRD log: fit refuses it; track too, from a file before
// tracking and from standard input at the calibration (the accelerometer's
// median z then reads -g).
TEST(TrackCli, WrongFrameIsRefusedAsFitRefusesIt) {
  const auto fit = testing::RunCli("fit --model=rigid3d --frame=flu --log=" +
                                   FigureEightCsv());
  EXPECT_EQ(fit.exit_code, 2);
  const std::string reason = "so the frame looks wrong: the data look frd";
  EXPECT_NE(fit.err.find(reason), std::string::npos) << fit.err;
  const auto file =
      testing::RunCli("track --frame=flu --log=" + FigureEightCsv());
  EXPECT_EQ(file.exit_code, 2);
  EXPECT_NE(file.err.find(reason), std::string::npos) << file.err;

  const std::string err_path = testing::MakeTempDir() + "/stderr";
  Child child({"track", "--log=-", "--frame=flu"}, err_path);
  child.Write(ReadFile(FigureEightCsv()));
  std::string out;
  EXPECT_EQ(child.Finish(&out), 2);
  const std::string err = ReadFile(err_path);
  EXPECT_NE(err.find("refused the input"), std::string::npos) << err;
  EXPECT_NE(err.find(reason), std::string::npos) << err;
  // What came before it was printed, and nothing was tracked.
  EXPECT_GT(std::count(out.begin(), out.end(), '\n'), 20);
  EXPECT_EQ(out.find("tracking"), std::string::npos);
}

TEST(TrackCli, LongFieldIsCutInTheMessage) {
  const std::string row =
      "0.1," + std::string(10 << 20, 'x') + ",0,-9.8,0,0,0,1,0,0,0,0,0,0\n";
  const auto r = RunWithInput(std::string(kHeader) + "\n" + row);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_LT(r.err.size(), 200u) << r.err.substr(0, 300);
  EXPECT_NE(r.err.find("line 2, field 'ax': 'xxxx"), std::string::npos);
}

TEST(TrackCli, ReportDrawsTheTrack) {
  if (std::system("command -v gnuplot > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "gnuplot not installed";
  }
  const std::string dir = testing::MakeTempDir() + "/R";
  const auto r =
      testing::RunCli("track --log=" + FigureEightCsv() + " --report=" + dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string svg = ReadFile(dir + "/track.svg");
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  // The data beside it: t and, per axis, the estimate and its band.
  std::istringstream data(ReadFile(dir + "/track.dat"));
  std::string row;
  int rows = 0;
  while (std::getline(data, row)) {
    std::istringstream cells(row);
    std::string cell;
    int n = 0;
    while (cells >> cell) ++n;
    EXPECT_EQ(n, 10) << row;
    ++rows;
  }
  EXPECT_EQ(rows, 68);
}

TEST(TrackCli, HelpAndRefusals) {
  const auto help = testing::RunCli("track --help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("--false_alarm_s"), std::string::npos);
  EXPECT_NE(help.out.find("--output_hz"), std::string::npos);
  EXPECT_EQ(testing::RunCli("track").exit_code, 2);
  EXPECT_EQ(testing::RunCli("track --log=- --format=xml").exit_code, 2);
  const auto planar =
      testing::RunCli("track --log=" + testing::DataDir() + "/paper_test1.csv");
  EXPECT_EQ(planar.exit_code, 2) << planar.err;
}

// --format is shared with fit and inspect, whose default is the table; the
// help of track must say its own default, JSON lines, and fit's its own.
TEST(TrackCli, HelpShowsTracksOwnFormatDefault) {
  const auto help = testing::RunCli("track --help");
  ASSERT_EQ(help.exit_code, 0);
  const std::size_t flag = help.out.find("--format=TEXT");
  ASSERT_NE(flag, std::string::npos) << help.out;
  const std::size_t line_end =
      help.out.find('\n', help.out.find('\n', flag) + 1);
  const std::string entry = help.out.substr(flag, line_end - flag);
  EXPECT_NE(entry.find("(default: json)"), std::string::npos) << entry;
  EXPECT_EQ(entry.find("(default: table)"), std::string::npos) << entry;
  const auto fit = testing::RunCli("fit --help");
  ASSERT_EQ(fit.exit_code, 0);
  EXPECT_NE(fit.out.find("(default: table)"), std::string::npos);
}

}  // namespace
}  // namespace imusysid

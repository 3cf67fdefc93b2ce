// `imusysid export-problem --model=rigid3d`: the rows of the 3-D model's
// linear system at the data its fit sees, read back and solved here.

#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "Eigen/Dense"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "nlohmann/json.hpp"
#include "tests/test_util.h"

namespace imusysid {
namespace {

using ::testing::HasSubstr;
using testing::RunCli;

// The file holds 17 significant digits and the solve is one QR of a
// well-conditioned 11-column system (condition ~200), so the positions
// agree to ~1e-15 m; 1e-9 m is far above rounding and far below any
// difference in the rows (a sample more or less moves them by ~1e-7 m).
constexpr double kSamePositionM = 1e-9;

struct Problem3dFile {
  std::map<std::string, std::string> metadata;
  std::vector<std::string> columns;
  Eigen::MatrixXd a;
  Eigen::VectorXd y;
  std::vector<int> axis;
};

// Reads the file as a peer would: '# key: value' lines, the header, rows.
Problem3dFile ReadProblem3d(const std::string& path) {
  Problem3dFile f;
  std::ifstream in(path);
  std::string line;
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    if (line.rfind("# ", 0) == 0) {
      const std::size_t colon = line.find(": ");
      if (colon != std::string::npos) {
        f.metadata[line.substr(2, colon - 2)] = line.substr(colon + 2);
      }
      continue;
    }
    std::stringstream ss(line);
    std::string cell;
    if (f.columns.empty()) {
      while (std::getline(ss, cell, ',')) f.columns.push_back(cell);
      continue;
    }
    std::vector<double> row;
    while (std::getline(ss, cell, ',')) row.push_back(std::stod(cell));
    EXPECT_EQ(row.size(), f.columns.size()) << line;
    rows.push_back(row);
  }
  const auto n = static_cast<Eigen::Index>(rows.size());
  const auto m = static_cast<Eigen::Index>(f.columns.size()) - 3;
  f.a.resize(n, m);
  f.y.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const std::vector<double>& r = rows[static_cast<std::size_t>(i)];
    f.axis.push_back(static_cast<int>(r[1]));
    f.y[i] = r[2];
    for (Eigen::Index j = 0; j < m; ++j) {
      f.a(i, j) = r[static_cast<std::size_t>(j + 3)];
    }
  }
  return f;
}

Eigen::Vector3d FittedPosition(const nlohmann::json& imu) {
  Eigen::Vector3d p;
  for (int a = 0; a < 3; ++a)
    p[a] = imu["fitted_position_frd_m"][a].get<double>();
  return p;
}

TEST(ExportProblem3d, LeastSquaresOfTheRowsIsTheLinearFit) {
  const std::string dir = testing::MakeTempDir();
  const std::string log = dir + "/F.ulg";
  ASSERT_EQ(RunCli("simulate --scenario=figure8_3d --out=" + log).exit_code, 0);
  const auto exported = RunCli("export-problem --model=rigid3d --log=" + log +
                               " --out=" + dir + "/P.csv");
  ASSERT_EQ(exported.exit_code, 0) << exported.err;
  EXPECT_THAT(exported.err, HasSubstr("wrote " + dir + "/P.csv (IMU 0, "));
  const auto fit = RunCli(
      "fit --model=rigid3d --estimator=linear --format=json "
      "--log=" +
      log);
  ASSERT_EQ(fit.exit_code, 0) << fit.err;
  const nlohmann::json j = testing::ParseJson(fit);
  const nlohmann::json imu = j.is_array() ? j[0] : j;

  const Problem3dFile p = ReadProblem3d(dir + "/P.csv");
  EXPECT_EQ(p.metadata.at("model"), "rigid3d");
  EXPECT_EQ(p.metadata.at("instance"), "0");
  EXPECT_EQ(p.metadata.at("coefficients"),
            "p_x,p_y,p_z,mu,rotor_drag,bias_x,bias_y,thrust_to_x,"
            "thrust_to_y,rotor_drag*wind_n,rotor_drag*wind_e");
  EXPECT_EQ(std::stoi(p.metadata.at("samples")), imu["samples"].get<int>());
  EXPECT_EQ(p.a.rows(), 2 * imu["samples"].get<int>());
  EXPECT_EQ(p.a.cols(), 11);
  EXPECT_NEAR(std::stod(p.metadata.at("estimator_delay_s")),
              imu["estimator_delay_s"].get<double>(),
              1e-12);
  // One window "t0..t1", the fit's.
  EXPECT_THAT(p.metadata.at("windows_s"), HasSubstr(".."));
  // Truth-free: nothing of the simulator's truth in the header.
  for (const auto& [key, value] : p.metadata) {
    EXPECT_THAT(key, ::testing::Not(HasSubstr("truth")));
  }
  // Rows alternate x, y per sample.
  EXPECT_EQ(p.axis[0], 0);
  EXPECT_EQ(p.axis[1], 1);

  const Eigen::VectorXd b = p.a.colPivHouseholderQr().solve(p.y);
  const Eigen::Vector3d fitted = FittedPosition(imu);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(b[a], fitted[a], kSamePositionM) << "axis " << a;
  }
  // And it is the truth's neighbourhood (IMU 0 at 50, −20, −30 mm), so the
  // columns are the position's and not another coefficient's.
  EXPECT_NEAR(b[0], 0.05, 2e-3);
  EXPECT_NEAR(b[1], -0.02, 2e-3);
  EXPECT_NEAR(b[2], -0.03, 2e-3);
}

TEST(ExportProblem3d, OneFilePerInstanceEachItsOwnFit) {
  const std::string dir = testing::MakeTempDir();
  const std::string log = dir + "/F.bin";
  ASSERT_EQ(RunCli("simulate --scenario=figure8_3d --out=" + log).exit_code, 0);
  // Three instances and no --out: which file would each go to?
  const auto refused = RunCli("export-problem --model=rigid3d --log=" + log);
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_THAT(refused.err, HasSubstr("3 IMU instances"));
  const auto exported = RunCli("export-problem --model=rigid3d --log=" + log +
                               " --out=" + dir + "/P.csv");
  ASSERT_EQ(exported.exit_code, 0) << exported.err;
  const auto fit = RunCli(
      "fit --model=rigid3d --estimator=linear --format=json "
      "--log=" +
      log);
  ASSERT_EQ(fit.exit_code, 0) << fit.err;
  const nlohmann::json j = testing::ParseJson(fit);
  ASSERT_TRUE(j.is_array());
  ASSERT_EQ(j.size(), 3u);
  for (const nlohmann::json& imu : j) {
    const int instance = imu["instance"].get<int>();
    const Problem3dFile p =
        ReadProblem3d(dir + "/P.imu" + std::to_string(instance) + ".csv");
    EXPECT_EQ(p.metadata.at("instance"), std::to_string(instance));
    // The first instance's delay and wind, as the fit passes them on.
    EXPECT_NEAR(std::stod(p.metadata.at("estimator_delay_s")),
                imu["estimator_delay_s"].get<double>(),
                1e-12);
    const Eigen::VectorXd b = p.a.colPivHouseholderQr().solve(p.y);
    const Eigen::Vector3d fitted = FittedPosition(imu);
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(b[a], fitted[a], kSamePositionM)
          << "instance " << instance << " axis " << a;
    }
  }
}

TEST(ExportProblem3d, AModelWithNonlinearParametersIsRefused) {
  const auto r =
      RunCli("export-problem --model=rigid3d_imu --log=" + testing::DataDir() +
             "/model_exact.csv");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("not one linear system"));
}

}  // namespace
}  // namespace imusysid

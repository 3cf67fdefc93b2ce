// The bundled logs in data/ are reproducible: regenerating each with the
// documented command (scripts/make_data.sh, data/regenerate.txt) gives the
// same bytes.

#include <fstream>
#include <sstream>
#include <string>

#include "gtest/gtest.h"
#include "tests/test_util.h"

namespace imusysid {
namespace {

std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(BundledData, RegeneratesByteForByte) {
  std::istringstream manifest(Slurp(testing::DataDir() + "/regenerate.txt"));
  std::string line;
  int checked = 0;
  while (std::getline(manifest, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string scenario, seed;
    fields >> scenario >> seed;
    const std::string out = testing::MakeTempDir() + "/" + scenario + ".csv";
    const auto r = testing::RunCli("simulate --scenario=" + scenario +
                                   " --seed=" + seed + " --out=" + out);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string base = testing::DataDir() + "/" + scenario;
    EXPECT_TRUE(Slurp(out) == Slurp(base + ".csv"))
        << scenario << ".csv differs from a fresh simulation; run "
        << "scripts/make_data.sh if the simulator changed on purpose";
    const std::string truth = out.substr(0, out.size() - 4) + ".truth.json";
    EXPECT_TRUE(Slurp(truth) == Slurp(base + ".truth.json"))
        << scenario << ".truth.json differs";
    ++checked;
  }
  EXPECT_GE(checked, 3);
}

}  // namespace
}  // namespace imusysid

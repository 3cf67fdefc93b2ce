#include "src/numerics/trapezoid.h"

#include "glog/logging.h"

namespace imusysid {

std::vector<double> CumulativeTrapezoid(const std::vector<double>& t,
                                        const std::vector<double>& x) {
  CHECK_EQ(t.size(), x.size());
  std::vector<double> y(t.size(), 0.0);
  for (std::size_t k = 1; k < t.size(); ++k) {
    y[k] = y[k - 1] + 0.5 * (t[k] - t[k - 1]) * (x[k] + x[k - 1]);
  }
  return y;
}

}  // namespace imusysid

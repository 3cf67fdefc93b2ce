#include "src/numerics/random.h"

#include <numeric>
#include <utility>

namespace imusysid {
namespace internal {

void Random::Permutation(int n, std::vector<int>* out) {
  out->resize(static_cast<std::size_t>(n));
  std::iota(out->begin(), out->end(), 0);
  for (int i = n - 1; i > 0; --i) {
    const auto j = static_cast<int>(Below(static_cast<std::uint64_t>(i) + 1));
    std::swap((*out)[static_cast<std::size_t>(i)],
              (*out)[static_cast<std::size_t>(j)]);
  }
}

}  // namespace internal
}  // namespace imusysid

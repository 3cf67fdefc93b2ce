// The change scan's fixed limits (change3d.h), apart from the scan so that
// the report that prints them (Rigid3dToJson) includes no analysis.

#ifndef IMUSYSID_SRC_ANALYSE_CHANGE3D_LIMITS_H_
#define IMUSYSID_SRC_ANALYSE_CHANGE3D_LIMITS_H_

namespace imusysid {
namespace internal {

// The test's level over all splits tried (Bonferroni), and the least
// difference on some axis that counts as a move: a significant difference
// smaller than that is below what a lever-arm correction can use.
inline constexpr double kChangeAlpha = 1e-3;
inline constexpr double kChangeMinDifferenceM = 0.005;

}  // namespace internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_ANALYSE_CHANGE3D_LIMITS_H_

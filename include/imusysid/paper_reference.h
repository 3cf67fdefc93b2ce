// The numbers the paper ("An IMU-based System Identification Technique for
// Quadrotors") publishes, typed once: its two fits, the CoM displacement it
// derives from them and the CAD expectation it compares with. The simulator's
// scenarios, the bench's Table I and the tests all take them from here.

#ifndef IMUSYSID_PAPER_REFERENCE_H_
#define IMUSYSID_PAPER_REFERENCE_H_

#include "imusysid/parameters.h"

namespace imusysid {

// Test 1, battery on top: the fit of Table I (r m, β deg, α deg, μ 1/m) and
// its objective OF (equation 10), m/s². The simulator's default truth.
inline constexpr ImuParameters kPaperTest1Fit = {0.19, 56.299, -2.812, 0.0716};
inline constexpr double kPaperTest1OfMps2 = 0.677;

// Test 2, the battery moved beneath: the fit of Table I. The paper gives no
// OF for it.
inline constexpr ImuParameters kPaperTest2Fit = {0.213, 66.066, -4.0132, 0.107};

// The vehicle's mass in each test, kg (the experiment's description).
inline constexpr double kPaperTest1MassKg = 1.636;
inline constexpr double kPaperTest2MassKg = 1.633;

// The CoM displacement test 1 → test 2 the paper reports from its two fits
// (equation 11): l = |d| and δ = atan2(d_z, d_x), and the Cartesian
// components in cm. The paper prints |Δz| = 3.66 cm; the sign is its fits'
// (the CoM moved down when the battery moved beneath).
inline constexpr double kPaperDisplacementLM = 0.0413;
inline constexpr double kPaperDisplacementDeltaDeg = 297.44;
inline constexpr double kPaperDisplacementDxCm = 1.90;
inline constexpr double kPaperDisplacementDzCm = -3.66;

// The displacement the paper expected from its CAD (SolidWorks) model, cm,
// signed as above (the paper prints |Δz| = 4.45 cm).
inline constexpr double kPaperCadDxCm = 1.68;
inline constexpr double kPaperCadDzCm = -4.45;

}  // namespace imusysid

#endif  // IMUSYSID_PAPER_REFERENCE_H_

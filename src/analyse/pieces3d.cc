// The gates of a flight's pieces (JudgePieces3d, JudgeChange3d;
// position3d.h): the windows and the two halves each fitted alone and
// tested for agreement, and the scan for a position that moved.

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "src/analyse/agreement3d.h"
#include "src/analyse/change3d.h"
#include "src/analyse/position3d.h"
#include "src/tools/format.h"

namespace imusysid {
namespace internal {
namespace {

const char* const kPiecesAxisNames[3] = {"x", "y", "z"};

std::string PiecesMm(double metres) {
  return FormatFixed(metres * 1e3, 1, NonFiniteStyle::kPrintf);
}

}  // namespace

void JudgePieces3d(const EstimateResult& result,
                   const Preprocess3dResult& pre,
                   const Rigid3dReportOptions& options,
                   ImuPosition3d* report) {
  ImuPosition3d& out = *report;
  // Agreement of independent pieces of the flight, each fitted alone: the
  // windows, and the first and second halves of the fitted samples. One
  // rigid body with one position predicts that they agree within their own
  // σ̂; a chi-square test of their spread about their inverse-variance mean
  // that fails at p < 0.001, with a piece further than 5 mm from that mean,
  // withholds the axis (a payload that shifted, a bad stretch). Each piece's
  // σ̂ is its own: the whole fit's statistical σ̂ scaled by how much less
  // the piece's samples pin the axis down than all of them do (the ratio of
  // the white variances from the factors), so a short window poorly excited
  // gets the wide σ̂ it has. (Only where a piece can be fitted on its own,
  // by a model linear outright: the IMU-only model integrates across the
  // whole span.) Each window's estimate is kept for the report page, a
  // single window's too (it is the whole fit's data).
  if (pre.windows.size() == 1 && out.usable) {
    const Stretch3d& w = pre.windows.front();
    out.window_estimates.push_back(
        {w.t0, w.t1, w.samples, out.position_m, out.stderr_m});
  }
  Eigen::Vector3d statistical;
  for (int a = 0; a < 3; ++a) {
    statistical[a] =
        out.decisions[static_cast<std::size_t>(a)].stderr_statistical_m;
  }
  auto judge = [&](const std::vector<Piece>& pieces, const char* gate_name) {
    const std::vector<PieceEstimate> estimates = EstimatePieces(
        result.model, pre.data, pieces, statistical, options.fitted_model);
    if (estimates.size() < 2) return estimates;
    for (int a = 0; a < 3; ++a) {
      const auto i = static_cast<std::size_t>(a);
      const AgreementTest test = Agreement(estimates, a);
      if (test.dof < 1) continue;
      Rigid3dGate g;
      g.gate = gate_name;
      g.statistic = test.chi_square;
      g.threshold = test.critical;
      g.difference_m = test.worst_difference_m;
      g.min_difference_m = kAgreementMinDifferenceM;
      g.window_t0_s = estimates[test.worst].t0;
      g.window_t1_s = estimates[test.worst].t1;
      g.passed = !test.disagree;
      out.decisions[i].evidence.push_back(g);
      if (out.determined[i] && !g.passed) {
        const PieceEstimate& worst = estimates[test.worst];
        out.determined[i] = false;
        out.decisions[i].reason = gate_name;
        out.advice[i] =
            std::string(kPiecesAxisNames[a]) + " is withheld: the " +
            (std::string(gate_name) == "window_agreement" ? "windows"
                                                          : "two halves") +
            " of the flight disagree (chi-square " +
            FormatNumber(test.chi_square, 3) + " on " +
            std::to_string(test.dof) + " degree" + (test.dof == 1 ? "" : "s") +
            " of freedom); " + FormatNumber(worst.t0, 5) + "-" +
            FormatNumber(worst.t1, 5) + " s alone gives " +
            PiecesMm(worst.position_m[a]) + " +/- " +
            PiecesMm(worst.stderr_m[a]) + " mm against " +
            PiecesMm(test.mean_m) +
            " mm (did the payload or the mounting change during the "
            "flight? imusysid track follows the position through it)";
        out.warnings.push_back(out.advice[i]);
      }
    }
    return estimates;
  };
  if (out.usable && pre.windows.size() >= 2) {
    std::vector<Piece> windows;
    std::size_t start = 0;
    for (const Stretch3d& w : pre.windows) {
      windows.push_back({start, start + w.samples, w.t0, w.t1});
      start += w.samples;
    }
    for (const PieceEstimate& e : judge(windows, "window_agreement")) {
      out.window_estimates.push_back(
          {e.t0, e.t1, e.samples, e.position_m, e.stderr_m});
    }
  }
  const std::size_t n = pre.data.size();
  if (out.usable && n >= 2 * kMinPieceSamples) {
    const std::size_t half = n / 2;
    judge({{0, half, pre.data.t_s[0], pre.data.t_s[half - 1]},
           {half, n, pre.data.t_s[half], pre.data.t_s[n - 1]}},
          "halves_agreement");
  }
}

bool ChangeKeepsAxis(const PositionChange3d& scan, int axis) {
  const auto i = static_cast<std::size_t>(axis);
  return !scan.found || (scan.judged[i] &&
                         std::abs(scan.before_m[axis] - scan.after_m[axis]) <=
                             kChangeMinDifferenceM);
}

void JudgeChange3d(const EstimateResult& result,
                   const Preprocess3dResult& pre,
                   const Rigid3dReportOptions& options,
                   ImuPosition3d* report) {
  ImuPosition3d& out = *report;
  if (out.usable) {
    out.position_change =
        ScanForChange(result.model, pre.data, options.fitted_model);
    const PositionChange3d& scan = out.position_change;
    // A position that moved makes the whole flight's a blend of two: every
    // axis is withheld but those both sides pin down and that moved by no
    // more than a lever-arm correction can use.
    std::string sides;
    for (int a = 0; a < 3; ++a) {
      if (!scan.judged[static_cast<std::size_t>(a)]) continue;
      sides += std::string(sides.empty() ? "" : ", ") + kPiecesAxisNames[a] +
               " " + PiecesMm(scan.before_m[a]) + " +/- " +
               PiecesMm(scan.before_stderr_m[a]) + " -> " +
               PiecesMm(scan.after_m[a]) + " +/- " +
               PiecesMm(scan.after_stderr_m[a]);
    }
    const std::string moved =
        "the flight before and after " + FormatNumber(scan.t_s, 4) +
        " s disagrees on the position: fitted alone, the two give " + sides +
        " mm (chi-square " + FormatNumber(scan.chi_square, 3) + " on " +
        std::to_string(scan.dof) +
        " dof, p = " + FormatNumber(scan.p_value_adjusted, 2) + " over " +
        std::to_string(scan.splits) +
        " splits tried); the whole flight's position is a blend of the two "
        "(did a payload or the mounting change? imusysid track follows the "
        "position through it)";
    for (int a = 0; scan.tested && a < 3; ++a) {
      const auto i = static_cast<std::size_t>(a);
      Rigid3dGate g;
      g.gate = "position_change";
      g.statistic = scan.p_value_adjusted;
      g.threshold = kChangeAlpha;
      g.difference_m = scan.judged[i]
                           ? std::abs(scan.before_m[a] - scan.after_m[a])
                           : std::numeric_limits<double>::quiet_NaN();
      g.min_difference_m = kChangeMinDifferenceM;
      g.window_t0_s = scan.t_s;
      g.passed = ChangeKeepsAxis(scan, a);
      out.decisions[i].evidence.push_back(g);
      if (out.determined[i] && !g.passed) {
        out.determined[i] = false;
        out.decisions[i].reason = "position_change";
        out.advice[i] =
            std::string(kPiecesAxisNames[a]) + " is withheld: " + moved;
      }
    }
    if (scan.found) out.warnings.push_back(moved);
  }
}

}  // namespace internal
}  // namespace imusysid

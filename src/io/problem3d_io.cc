#include "src/io/problem3d_io.h"

#include <string>
#include <utility>
#include <vector>

#include "Eigen/Core"
#include "imusysid/extend/model.h"
#include "src/tools/format.h"

namespace imusysid {
namespace internal {
namespace {

// 17 significant digits identify every double: the file's least-squares
// solution is the fit's to rounding.
constexpr int kProblem3dDigits = 17;

// b's entry names: a parameter's own name where the coefficient is the
// parameter, else "<scale>*<name>" for a product (rigid3d's k·w_N, k·w_E).
StatusOr<std::vector<std::string>> Problem3dCoefficientNames(
    const Model& model, const LinearStructure& structure) {
  const std::vector<ParameterInfo>& info = model.parameter_info();
  const int m = structure.num_coefficients();
  std::vector<std::string> names(static_cast<std::size_t>(m));
  std::vector<bool> named(static_cast<std::size_t>(m), false);
  for (int p = 0; p < static_cast<int>(info.size()); ++p) {
    const int c = structure.CoefficientOfParameter(p);
    if (c >= 0 && c < m) {
      names[static_cast<std::size_t>(c)] =
          info[static_cast<std::size_t>(p)].name;
      named[static_cast<std::size_t>(c)] = true;
    }
  }
  // The coefficients no parameter maps to are, in rigid3d, the products of
  // the linear (rotor) drag with the parameters left over, in parameter
  // order: the wind enters only as k·w.
  std::string scale = "scale";
  for (const ParameterInfo& p : info) {
    if (p.role == ParameterRole::kLinearDrag) scale = p.name;
  }
  std::size_t next_free = 0;
  for (int p = 0; p < static_cast<int>(info.size()); ++p) {
    if (structure.CoefficientOfParameter(p) >= 0) continue;
    while (next_free < named.size() && named[next_free]) ++next_free;
    if (next_free == named.size()) break;
    names[next_free] = scale + "*" + info[static_cast<std::size_t>(p)].name;
    named[next_free] = true;
  }
  for (std::size_t c = 0; c < named.size(); ++c) {
    if (!named[c]) {
      return FailedPreconditionError("model " + std::string(model.name()) +
                                     ": coefficient " + std::to_string(c) +
                                     " has no parameter name");
    }
  }
  return names;
}

}  // namespace

StatusOr<std::string> FormatLinearProblem3dCsv(
    const std::string& model_name,
    std::shared_ptr<const ProblemData> data,
    const ProblemMetadata& metadata) {
  if (data == nullptr || data->motion.empty()) {
    return InvalidArgumentError(
        "a 3-D problem file needs the 3-D motion (ProblemData::motion)");
  }
  StatusOr<std::unique_ptr<Model>> model = CreateModel(model_name, data);
  if (!model.ok()) return model.status();
  const LinearStructure* structure = (*model)->linear_structure();
  if (structure == nullptr || !structure->nonlinear_parameters().empty()) {
    return FailedPreconditionError(
        "model " + model_name +
        " is not linear in all its coefficients, so its problem is not one "
        "linear system; export-problem writes rigid3d's");
  }
  Eigen::MatrixXd a;
  Eigen::VectorXd y;
  if (!structure->LinearSystem(nullptr, &a, &y, nullptr, nullptr)) {
    return FailedPreconditionError(
        data->source + ": model " + model_name +
        "'s linear system is not finite at these data");
  }
  StatusOr<std::vector<std::string>> names =
      Problem3dCoefficientNames(**model, *structure);
  if (!names.ok()) return names.status();
  const std::size_t n = data->size();
  const std::vector<unsigned char>& fitted = data->motion.fitted;
  // LinearSystem stacks the n x rows on the n y rows (Rigid3dModel).
  if (static_cast<std::size_t>(a.rows()) != 2 * n) {
    return FailedPreconditionError(
        "model " + model_name + ": " + std::to_string(a.rows()) + " rows for " +
        std::to_string(n) + " samples; expected " + std::to_string(2 * n));
  }
  std::size_t kept = 0;
  for (std::size_t k = 0; k < n; ++k) kept += fitted.empty() || fitted[k];

  std::string out =
      "# imusysid 3-D problem file: the rows of the model's linear system "
      "A b = y at the fitted samples (docs/problem-files.md)\n";
  for (const auto& [key, value] : metadata) {
    out += "# " + key + ": " + value + "\n";
  }
  out += "# model: " + model_name + "\n";
  out += "# samples: " + std::to_string(kept) + "\n";
  out += "# rows: " + std::to_string(2 * kept) + "\n";
  std::string joined;
  for (const std::string& name : *names) {
    joined += (joined.empty() ? "" : ",") + name;
  }
  out += "# coefficients: " + joined + "\n";
  out += "t,axis,y";
  for (const std::string& name : *names) out += ",a_" + name;
  out += "\n";
  out.reserve(out.size() + 2 * kept * (names->size() + 3) * 24);
  const auto half = static_cast<Eigen::Index>(n);
  for (std::size_t k = 0; k < n; ++k) {
    if (!fitted.empty() && !fitted[k]) continue;
    for (int axis = 0; axis < 2; ++axis) {
      const Eigen::Index row = static_cast<Eigen::Index>(k) + axis * half;
      AppendNumber(&out, data->t_s[k], kProblem3dDigits);
      out += axis == 0 ? ",0," : ",1,";
      AppendNumber(&out, y[row], kProblem3dDigits);
      for (Eigen::Index j = 0; j < a.cols(); ++j) {
        out += ',';
        AppendNumber(&out, a(row, j), kProblem3dDigits);
      }
      out += '\n';
    }
  }
  return out;
}

}  // namespace internal
}  // namespace imusysid

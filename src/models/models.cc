// The model factory: one line per built-in model.

#include <sstream>
#include <utility>

#include "imusysid/problem.h"
#include "src/models/consistent_model.h"
#include "src/models/paper_model.h"

namespace imusysid {

std::vector<std::string> ModelNames() { return {"paper", "consistent"}; }

StatusOr<std::unique_ptr<Model>> CreateModel(
    std::string_view name,
    std::shared_ptr<const ProblemData> data,
    const ModelOptions& options) {
  if (data == nullptr) return InvalidArgumentError("no problem data");
  IMUSYSID_RETURN_IF_ERROR(data->Validate());
  if (name == "paper") {
    return std::unique_ptr<Model>(new PaperModel(std::move(data)));
  }
  if (name == "consistent") {
    auto model = ConsistentModel::Create(std::move(data), options);
    if (!model.ok()) return model.status();
    return std::unique_ptr<Model>(std::move(model).value());
  }
  std::ostringstream msg;
  msg << "unknown model '" << name << "'; valid names:";
  for (const auto& n : ModelNames()) msg << " " << n;
  return NotFoundError(msg.str());
}

}  // namespace imusysid

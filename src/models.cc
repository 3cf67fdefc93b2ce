// The model factory: one line per built-in model.

#include <sstream>
#include <utility>

#include "src/paper_model.h"
#include "src/problem.h"

namespace imusysid {

std::vector<std::string> ModelNames() { return {"paper"}; }

StatusOr<std::unique_ptr<Model>> CreateModel(
    std::string_view name,
    std::shared_ptr<const ProblemData> data,
    const ModelOptions& options) {
  (void)options;
  if (data == nullptr) return InvalidArgumentError("no problem data");
  IMUSYSID_RETURN_IF_ERROR(data->Validate());
  if (name == "paper") {
    return std::unique_ptr<Model>(new PaperModel(std::move(data)));
  }
  std::ostringstream msg;
  msg << "unknown model '" << name << "'; valid names:";
  for (const auto& n : ModelNames()) msg << " " << n;
  return NotFoundError(msg.str());
}

}  // namespace imusysid

// What a user of the library needs to know about the registered models
// without building one: the options a model takes, its description and the
// names registered. The Model interface and the registry themselves are the
// extension API (imusysid/extend/model.h), for model authors.

#ifndef IMUSYSID_MODELS_H_
#define IMUSYSID_MODELS_H_

#include <string>
#include <string_view>
#include <vector>

#include "imusysid/status.h"

namespace imusysid {

struct ModelOptions {
  // consistent model: integrate v̇ = f_z·sin θ − μ v|v| with the measured z
  // specific force instead of assuming altitude hold (v̇ = g tan θ − μ v|v|).
  bool use_measured_fz = false;
};

// What a front end needs to know about a model before it has data to build
// one on.
struct ModelDescription {
  std::string summary;  // one line for --help
  // True when the prediction uses ProblemData::planar.v (the velocity
  // preprocessing made, or the log's); false when the model integrates its own
  // from the IMU and so needs the raw log behind the data.
  bool uses_data_velocity = true;
  // True when the model needs ProblemData::motion (Preprocess3d).
  bool needs_motion3d = false;
  // The estimator a fit uses unless told otherwise: the closed form where
  // the model is linear outright, variable projection where it is
  // separable, the paper's GA seeding LM otherwise.
  std::string default_estimator = "ga+lm";
  // A 3-D model that reads the autopilot's attitude and velocity
  // (Preprocess3d) rather than integrating them from the IMU
  // (Preprocess3dImuOnly); and the registered model to fit instead on a log
  // without them ("": refuse).
  bool needs_estimator_channels = false;
  std::string without_estimator_channels = "";
  // What the model takes its inputs from, for the note that says a fit
  // fell back to it ("attitude from the gyro, ...").
  std::string inputs = "";
};

// The built-in models' names, in registration order.
std::vector<std::string> ModelNames();

// The description of the built-in model `name`; NotFound, listing the valid
// names, for an unknown name.
StatusOr<ModelDescription> DescribeModel(std::string_view name);

}  // namespace imusysid

#endif  // IMUSYSID_MODELS_H_

// Every header of the user API in one include, with the version these
// headers belong to. Model and estimator authors add the extension API
// (imusysid/extend/*.h) themselves; this header includes none of it.

#ifndef IMUSYSID_IMUSYSID_H_
#define IMUSYSID_IMUSYSID_H_

#include "imusysid/autopilot.h"
#include "imusysid/covariance.h"
#include "imusysid/dataflash.h"
#include "imusysid/displacement.h"
#include "imusysid/estimator_options.h"
#include "imusysid/flight_plan.h"
#include "imusysid/identifiability.h"
#include "imusysid/identify.h"
#include "imusysid/log.h"
#include "imusysid/log_reader.h"
#include "imusysid/log_sanity.h"
#include "imusysid/models.h"
#include "imusysid/paper_reference.h"
#include "imusysid/parameter_info.h"
#include "imusysid/parameters.h"
#include "imusysid/plan3d.h"
#include "imusysid/pool3d.h"
#include "imusysid/predict3d.h"
#include "imusysid/preprocess.h"
#include "imusysid/preprocess3d.h"
#include "imusysid/problem_data.h"
#include "imusysid/problem_io.h"
#include "imusysid/report.h"
#include "imusysid/result.h"
#include "imusysid/rigid3d.h"
#include "imusysid/rigid3d_report.h"
#include "imusysid/segments.h"
#include "imusysid/simulate.h"
#include "imusysid/simulate3d.h"
#include "imusysid/status.h"
#include "imusysid/track3d.h"
#include "imusysid/ulog.h"
#include "imusysid/version.h"

#endif  // IMUSYSID_IMUSYSID_H_

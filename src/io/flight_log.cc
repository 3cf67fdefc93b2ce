// The FlightLog type every reader produces, and the frame names its files use.

#include <algorithm>
#include <string>

#include "imusysid/log.h"
#include "src/io/csv_text.h"

namespace imusysid {
namespace {

using internal::Quote;

bool EqualsIgnoreCase(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const char ca = a[i] >= 'A' && a[i] <= 'Z' ? a[i] - 'A' + 'a' : a[i];
    const char cb = b[i] >= 'A' && b[i] <= 'Z' ? b[i] - 'A' + 'a' : b[i];
    if (ca != cb) return false;
  }
  return true;
}

}  // namespace

const char* FrameToString(Frame frame) {
  switch (frame) {
    case Frame::kFlu:
      return "flu";
    case Frame::kFrd:
      return "frd";
  }
  return "unknown";
}

StatusOr<Frame> FrameFromString(std::string_view text) {
  if (EqualsIgnoreCase(text, "flu")) return Frame::kFlu;
  if (EqualsIgnoreCase(text, "frd")) return Frame::kFrd;
  return InvalidArgumentError("unknown frame " + Quote(text) +
                              "; expected 'flu' or 'frd'");
}

std::array<std::pair<const char*, std::vector<double>*>, 7>
FlightLog::Columns() {
  return {{{"t", &t_s},
           {"ax", &ax},
           {"ay", &ay},
           {"az", &az},
           {"gx", &gx},
           {"gy", &gy},
           {"gz", &gz}}};
}

std::array<std::pair<const char*, const std::vector<double>*>, 7>
FlightLog::Columns() const {
  return {{{"t", &t_s},
           {"ax", &ax},
           {"ay", &ay},
           {"az", &az},
           {"gx", &gx},
           {"gy", &gy},
           {"gz", &gz}}};
}

const Channel* FlightLog::FindChannel(std::string_view name) const {
  for (const Channel& channel : extra) {
    if (channel.name == name) return &channel;
  }
  return nullptr;
}

const std::string* FlightLog::FindMetadata(std::string_view key) const {
  for (const auto& entry : metadata) {
    if (entry.first == key) return &entry.second;
  }
  return nullptr;
}

double FlightLog::MedianDt() const {
  if (t_s.size() < 2) return 0.0;
  std::vector<double> dt(t_s.size() - 1);
  for (std::size_t i = 0; i + 1 < t_s.size(); ++i) dt[i] = t_s[i + 1] - t_s[i];
  const std::size_t mid = dt.size() / 2;
  std::nth_element(dt.begin(), dt.begin() + mid, dt.end());
  const double upper = dt[mid];
  if (dt.size() % 2 == 1) return upper;
  const double lower = *std::max_element(dt.begin(), dt.begin() + mid);
  return 0.5 * (lower + upper);
}

}  // namespace imusysid

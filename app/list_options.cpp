#include "app/list_options.h"

#include <cstdlib>
#include <sstream>
#include "render/core/error.h"

namespace vpl::app {

std::vector<std::string> splitCommas(const std::string& list) {
  std::vector<std::string> items;
  std::stringstream in(list);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) items.push_back(item);
  return items;
}

std::vector<SamplingMode> parseModes(const std::string& list, const std::string& flag) {
  std::vector<SamplingMode> modes;
  for (const std::string& name : splitCommas(list)) {
    const auto mode = parseMode(name);
    if (!mode) throw InputError(flag + ": unknown mode '" + name + "' (brdf, metropolis, mis, mixture, preview)");
    modes.push_back(*mode);
  }
  if (modes.empty()) throw InputError(flag + ": no mode given");
  return modes;
}

std::vector<double> parseTimes(const std::string& list, const std::string& flag) {
  std::vector<double> times;
  for (const std::string& item : splitCommas(list)) {
    char* end = nullptr;
    const double t = std::strtod(item.c_str(), &end);
    if (end == item.c_str() || *end != '\0' || !(t > 0.0) || !(t < 1e6))
      throw InputError(flag + ": '" + item + "' is not a positive number of seconds");
    times.push_back(t);
  }
  if (times.empty()) throw InputError(flag + ": no budget given");
  return times;
}

}  // namespace vpl::app

// Comma-separated lists on the command line (--modes, --times, sweep values).
#pragma once
#include <string>
#include <vector>
#include "render/integrator/sampling_mode.h"

namespace vpl::app {

std::vector<std::string> splitCommas(const std::string& list);
// Throw InputError naming `flag` on an unknown mode, a non-positive time or an empty list.
std::vector<SamplingMode> parseModes(const std::string& list, const std::string& flag = "--modes");
std::vector<double> parseTimes(const std::string& list, const std::string& flag = "--times");

}  // namespace vpl::app

// The sampling modes a user can pick (DESIGN.md §2 steps 5 and 8).
#pragma once
#include <optional>
#include <string>
#include <string_view>

namespace vpl {

enum class SamplingMode { Brdf, Metropolis, Mis, Mixture, Preview };

inline const char* modeName(SamplingMode m) {
  switch (m) {
    case SamplingMode::Brdf: return "brdf";
    case SamplingMode::Metropolis: return "metropolis";
    case SamplingMode::Mis: return "mis";
    case SamplingMode::Mixture: return "mixture";
    case SamplingMode::Preview: return "preview";
  }
  return "?";
}

// The modes that path trace with the VPL guide.
inline bool isGuided(SamplingMode m) {
  return m == SamplingMode::Metropolis || m == SamplingMode::Mis || m == SamplingMode::Mixture;
}

inline std::optional<SamplingMode> parseMode(std::string_view name) {
  for (SamplingMode m : {SamplingMode::Brdf, SamplingMode::Metropolis, SamplingMode::Mis, SamplingMode::Mixture,
                         SamplingMode::Preview})
    if (name == modeName(m)) return m;
  return std::nullopt;
}

}  // namespace vpl

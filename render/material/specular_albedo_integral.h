// The integral behind the specular albedo table (specular_albedo.h): E(mu, alpha) of the GGX lobe by
// 32 x 32 stratified visible-normal samples per entry, and its cosine-weighted average per row. A
// million samples take 0.04 s (0.19 s under ASan) at every start of a process, so the renderer reads
// the values embedded in specular_albedo_values.inc; tools/make_specular_albedo_table writes that
// file from this code, and a unit test holds the two to each other.
#pragma once
#include <array>
#include "render/material/specular_albedo.h"

namespace vpl {

struct SpecularAlbedoTable {
  static constexpr int kMu = 32, kAlpha = 32;  // columns uniform in mu, rows uniform in sqrt(alpha)
  std::array<AlbedoTerms, kMu * kAlpha> e;      // row-major: e[row * kMu + column]
  std::array<AlbedoTerms, kAlpha> average;      // 2 * integral E(mu) mu dmu per row
};

SpecularAlbedoTable integrateSpecularAlbedoTable();
// The embedded values the lookups of specular_albedo.h read.
const SpecularAlbedoTable& embeddedSpecularAlbedoTable();

}  // namespace vpl

// Small scenes built in code for tests whose answer is known analytically.
#pragma once
#include <cmath>
#include <numbers>
#include <vector>
#include "render/scene/scene_data.h"

namespace vpl::test {

// A pure Lambertian of albedo rho (no specular layer), two-sided.
inline Material lambertian(float rho) {
  Material m;
  m.baseColor = glm::vec3(rho);
  m.metallic = 0.0f;
  m.roughness = 1.0f;
  m.specularFactor = 0.0f;
  m.doubleSided = true;
  return m;
}

// An axis-aligned box [-h, h]^3 seen from inside: 12 triangles, one material.
inline MeshData insideBox(float h, uint32_t material) {
  MeshData m;
  m.name = "box";
  const glm::vec3 c[8] = {{-h, -h, -h}, {h, -h, -h}, {h, h, -h}, {-h, h, -h},
                          {-h, -h, h},  {h, -h, h},  {h, h, h},  {-h, h, h}};
  m.positions.assign(c, c + 8);
  // Wound so that the normals point into the box.
  const uint32_t faces[6][4] = {{0, 1, 2, 3}, {5, 4, 7, 6}, {4, 0, 3, 7}, {1, 5, 6, 2}, {4, 5, 1, 0}, {3, 2, 6, 7}};
  for (const auto& f : faces) {
    for (uint32_t i : {f[0], f[1], f[2], f[0], f[2], f[3]}) m.indices.push_back(i);
  }
  m.material = material;
  return m;
}

// A closed furnace: every wall is Lambertian with albedo rho and emits radiance le on both sides.
// Radiance everywhere inside is le / (1 - rho) (the Neumann series of a constant operator).
inline SceneData furnaceScene(float rho, float le, float halfSize = 1.0f) {
  SceneData s;
  Material wall = lambertian(rho);
  wall.emission = glm::vec3(le);
  s.materials.push_back(wall);
  s.meshes.push_back(insideBox(halfSize, 0));
  s.boundsMin = glm::vec3(-halfSize);
  s.boundsMax = glm::vec3(halfSize);
  CameraData cam;
  cam.eye = glm::vec3(0.0f);
  cam.target = glm::vec3(0, 0, -1);
  cam.yfov = 1.2f;
  s.camera = cam;
  return s;
}

// A globe of rings x segments latitude-longitude facets (2 segments (rings - 1) triangles), wound
// outwards: a tessellated lamp, as lamp_rooms has.
inline MeshData globe(const glm::dvec3& centre, double radius, int rings, int segments, uint32_t material) {
  MeshData m;
  m.name = "globe";
  const double pi = std::numbers::pi;
  for (int r = 0; r <= rings; ++r)
    for (int k = 0; k < segments; ++k) {
      const double theta = pi * r / rings, phi = 2.0 * pi * k / segments;
      m.positions.push_back(glm::vec3(centre + radius * glm::dvec3(std::sin(theta) * std::cos(phi), std::cos(theta),
                                                                    std::sin(theta) * std::sin(phi))));
    }
  for (int r = 0; r < rings; ++r)
    for (int k = 0; k < segments; ++k) {
      const uint32_t a = uint32_t(r * segments + k), b = uint32_t(r * segments + (k + 1) % segments);
      const uint32_t c = a + uint32_t(segments), d = b + uint32_t(segments);
      if (r > 0) m.indices.insert(m.indices.end(), {a, b, c});
      if (r + 1 < rings) m.indices.insert(m.indices.end(), {b, d, c});
    }
  m.material = material;
  return m;
}

// Irradiance at p (normal n) from a uniform Lambertian polygon of radiance 1, by Lambert's
// formula: (1/2) sum_i angle(a_i, a_i+1) n . unit(a_i x a_i+1), a_i the vertices minus p. Holds when
// the polygon lies wholly above p's tangent plane.
inline double polygonIrradiance(const std::vector<glm::dvec3>& vertices, const glm::dvec3& p, const glm::dvec3& n) {
  double sum = 0.0;
  for (size_t i = 0; i < vertices.size(); ++i) {
    const glm::dvec3 a = glm::normalize(vertices[i] - p), b = glm::normalize(vertices[(i + 1) % vertices.size()] - p);
    const glm::dvec3 c = glm::cross(a, b);
    sum += std::atan2(glm::length(c), glm::dot(a, b)) * glm::dot(n, glm::normalize(c));
  }
  return 0.5 * std::abs(sum);
}

// The irradiance at p (normal n) from a convex mesh of radiance 1 emitting from its outside, wholly
// above p's tangent plane: Lambert's formula over the facets that face p (a convex mesh hides none of
// them from another).
inline double convexMeshIrradiance(const MeshData& mesh, const glm::dvec3& p, const glm::dvec3& n) {
  double sum = 0.0;
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const std::vector<glm::dvec3> v = {glm::dvec3(mesh.positions[mesh.indices[t]]), glm::dvec3(mesh.positions[mesh.indices[t + 1]]),
                                       glm::dvec3(mesh.positions[mesh.indices[t + 2]])};
    if (glm::dot(glm::cross(v[1] - v[0], v[2] - v[0]), p - v[0]) > 0.0) sum += polygonIrradiance(v, p, n);
  }
  return sum;
}

}  // namespace vpl::test

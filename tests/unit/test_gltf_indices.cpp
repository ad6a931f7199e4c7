// Every index of a glTF file is range-checked from its JSON (render/scene/gltf_validate): one broken
// file per kind of index (tests/data/gltf_indices/, written by make_files.py from valid.gltf, each
// an error for the Khronos glTF-Validator: tests/e2e/gltf_validator.sh), each refused with exactly
// one line naming the JSON path and the value.
#include <filesystem>
#include <iterator>
#include <string>
#include "render/core/error.h"
#include "render/scene/gltf_loader.h"
#include "tests/unit/support.h"

namespace vpl {
namespace {

std::string dataFile(const std::string& name) { return test::sourceDir() + "/tests/data/gltf_indices/" + name; }

TEST(GltfIndices, TheFileEveryBrokenOneComesFromLoads) {
  const SceneData scene = loadGltf(dataFile("valid.gltf"));
  EXPECT_EQ(scene.triangleCount(), 1u);
  EXPECT_EQ(scene.lights.size(), 1u);
  EXPECT_TRUE(scene.camera.has_value());
  EXPECT_EQ(scene.textures.size(), 2u);  // image 0 as sRGB colour and as linear data; image 1 is a normal map
}

TEST(GltfIndices, AValidFileWithoutTrianglesLoadsWithANotice) {
  const SceneData scene = loadGltf(dataFile("no_triangles.gltf"));
  EXPECT_EQ(scene.triangleCount(), 0u);
  ASSERT_EQ(scene.notices.size(), 1u);
  EXPECT_EQ(scene.notices[0], "the scene instances no triangles: only the sky will be seen");
}

struct BrokenIndex {
  const char* file;
  const char* message;  // after "<path>: "
};

const BrokenIndex kBroken[] = {
    {"bad_scene.gltf", "scene: 1 is not a scene index"},
    {"bad_scene_node.gltf", "scenes[0].nodes[1]: 3 is not a node index"},
    {"bad_node_mesh.gltf", "nodes[1].mesh: -5 is not a mesh index"},
    {"bad_node_mesh.glb", "nodes[1].mesh: -5 is not a mesh index"},
    // tinygltf reads these three as "no mesh", "mesh 0" and "no mesh".
    {"bad_node_mesh_minus_one.gltf", "nodes[1].mesh: -1 is not a mesh index"},
    {"bad_node_mesh_2pow32.gltf", "nodes[1].mesh: 4294967296 is not a mesh index"},
    {"bad_node_mesh_fraction.gltf", "nodes[1].mesh: 0.5 is not a mesh index"},
    {"bad_node_camera.gltf", "nodes[0].camera: 1 is not a camera index"},
    {"bad_node_child.gltf", "nodes[0].children[0]: 7 is not a node index"},
    {"bad_node_skin.gltf", "nodes[1].skin: 1 is not a skin index"},
    {"bad_node_light.gltf", "nodes[2].extensions.KHR_lights_punctual.light: 1 is not a light index"},
    {"bad_primitive_indices.gltf", "meshes[0].primitives[0].indices: 9 is not an accessor index"},
    {"bad_primitive_attribute.gltf", "meshes[0].primitives[0].attributes.POSITION: 9 is not an accessor index"},
    {"bad_primitive_target.gltf", "meshes[0].primitives[0].targets[0].POSITION: -2 is not an accessor index"},
    {"bad_primitive_material.gltf", "meshes[0].primitives[0].material: 1 is not a material index"},
    {"bad_base_color_texture.gltf",
     "materials[0].pbrMetallicRoughness.baseColorTexture.index: 2 is not a texture index"},
    {"bad_metallic_roughness_texture.gltf",
     "materials[0].pbrMetallicRoughness.metallicRoughnessTexture.index: 2 is not a texture index"},
    {"bad_normal_texture.gltf", "materials[0].normalTexture.index: 2 is not a texture index"},
    {"bad_occlusion_texture.gltf", "materials[0].occlusionTexture.index: 2 is not a texture index"},
    {"bad_emissive_texture.gltf", "materials[0].emissiveTexture.index: -1 is not a texture index"},
    {"bad_specular_texture.gltf",
     "materials[0].extensions.KHR_materials_specular.specularTexture.index: 2 is not a texture index"},
    {"bad_specular_color_texture.gltf",
     "materials[0].extensions.KHR_materials_specular.specularColorTexture.index: -1 is not a texture index"},
    {"bad_texture_source.gltf", "textures[0].source: 2 is not an image index"},
    {"bad_texture_sampler.gltf", "textures[0].sampler: 1 is not a sampler index"},
    {"bad_image_buffer_view.gltf", "images[1].bufferView: 12 is not a bufferView index"},
    {"bad_accessor_buffer_view.gltf", "accessors[0].bufferView: 12 is not a bufferView index"},
    {"bad_sparse_indices_buffer_view.gltf", "accessors[1].sparse.indices.bufferView: 12 is not a bufferView index"},
    {"bad_sparse_values_buffer_view.gltf", "accessors[1].sparse.values.bufferView: -3 is not a bufferView index"},
    {"bad_buffer_view_buffer.gltf", "bufferViews[0].buffer: 1 is not a buffer index"},
    {"bad_skin_joint.gltf", "skins[0].joints[0]: 3 is not a node index"},
    {"bad_skin_skeleton.gltf", "skins[0].skeleton: -1 is not a node index"},
    {"bad_skin_inverse_bind_matrices.gltf", "skins[0].inverseBindMatrices: 9 is not an accessor index"},
    {"bad_animation_channel_sampler.gltf", "animations[0].channels[0].sampler: 1 is not an animation sampler index"},
    {"bad_animation_target_node.gltf", "animations[0].channels[0].target.node: 3 is not a node index"},
    {"bad_animation_input.gltf", "animations[0].samplers[0].input: 9 is not an accessor index"},
    {"bad_animation_output.gltf", "animations[0].samplers[0].output: -1 is not an accessor index"},
    // Valid for the JavaScript validator, refused here (README.md): tinygltf reads 0.0 as "no mesh".
    {"float_index.gltf", "nodes[1].mesh: 0.0 is not a mesh index"}};

class BrokenIndices : public ::testing::TestWithParam<BrokenIndex> {};

TEST_P(BrokenIndices, AreRefusedWithThePathAndTheValue) {
  const std::string path = dataFile(GetParam().file);
  try {
    loadGltf(path);
    ADD_FAILURE() << path << " loaded but should not";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), path + ": " + GetParam().message);
  }
}

INSTANTIATE_TEST_SUITE_P(
    OnePerKind, BrokenIndices, ::testing::ValuesIn(kBroken),
    [](const ::testing::TestParamInfo<BrokenIndex>& info) {
      std::string name = info.param.file;
      for (char& c : name)
        if (c == '.') c = '_';
      return name;
    });

// The data folder holds exactly the files above, the two valid ones and the generator: a file
// added to make_files.py without its expected message fails here.
TEST(GltfIndices, EveryBrokenFileHasAnExpectedMessage) {
  size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dataFile("")))
    files += entry.path().extension() == ".gltf" || entry.path().extension() == ".glb";
  EXPECT_EQ(files, std::size(kBroken) + 2);
}

}  // namespace
}  // namespace vpl

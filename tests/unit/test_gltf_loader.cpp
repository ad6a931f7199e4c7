// The glTF loader on real files: the public sample scenes, the built-in scenes, and broken files.
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sys/resource.h>
#include <unistd.h>
#include <stb_image.h>
#include <stb_image_write.h>
#include "render/core/error.h"
#include "render/scene/gltf_loader.h"
#include "tests/unit/support.h"

namespace vpl {
namespace {

namespace fs = std::filesystem;

struct SharedCase {
  const char* path;
  size_t triangles;
};

class SharedScenes : public ::testing::TestWithParam<SharedCase> {};

TEST_P(SharedScenes, LoadWithTheTriangleCountOfTheirReadme) {
  VPL_REQUIRE_SHARED_SCENE(path, GetParam().path);
  const SceneData scene = loadGltf(path);
  // The README counts instanced triangles; zero-area ones are dropped and counted in a notice.
  size_t dropped = 0;
  for (const std::string& n : scene.notices)
    if (n.find("degenerate") != std::string::npos) dropped = std::stoul(n);
  EXPECT_EQ(scene.triangleCount() + dropped, GetParam().triangles);
  EXPECT_FALSE(scene.materials.empty());
  EXPECT_LE(scene.boundsMin.x, scene.boundsMax.x);
  for (const MeshData& m : scene.meshes) {
    EXPECT_LT(m.material, scene.materials.size());
    for (uint32_t i : m.indices) ASSERT_LT(i, m.positions.size());
  }
}

INSTANTIATE_TEST_SUITE_P(
    Khronos, SharedScenes,
    ::testing::Values(SharedCase{"CornellBox/CornellBox-Original.gltf", 32},
                      SharedCase{"CornellBox/CornellBox-Original-emissive17.gltf", 32},
                      SharedCase{"EmissiveStrengthTest/glTF/EmissiveStrengthTest.gltf", 90},
                      SharedCase{"EmissiveStrengthTest/glTF-Binary/EmissiveStrengthTest.glb", 90},
                      SharedCase{"LightsPunctualLamp/glTF/LightsPunctualLamp.gltf", 6000},
                      SharedCase{"Cube/glTF/Cube.gltf", 12}, SharedCase{"BoxTextured/glTF/BoxTextured.gltf", 12},
                      SharedCase{"BoxTextured/glTF-Binary/BoxTextured.glb", 12}, SharedCase{"Triangle/glTF/Triangle.gltf", 1},
                      SharedCase{"Cameras/glTF/Cameras.gltf", 2}, SharedCase{"OrientationTest/glTF/OrientationTest.gltf", 524},
                      SharedCase{"NegativeScaleTest/glTF/NegativeScaleTest.gltf", 7724},
                      SharedCase{"TwoSidedPlane/glTF/TwoSidedPlane.gltf", 2},
                      SharedCase{"MetalRoughSpheresNoTextures/glTF/MetalRoughSpheresNoTextures.gltf", 1040409}));

TEST(GltfLoader, EmissiveStrengthScalesEmission) {
  VPL_REQUIRE_SHARED_SCENE(path, "CornellBox/CornellBox-Original-emissive17.gltf");
  const SceneData scene = loadGltf(path);
  float strongest = 0.0f;
  for (const Material& m : scene.materials) strongest = std::max(strongest, m.emission.x);
  EXPECT_NEAR(strongest, 17.0f, 1e-4f);
}

TEST(GltfLoader, PunctualLightsAndTexturesOfTheLamp) {
  VPL_REQUIRE_SHARED_SCENE(path, "LightsPunctualLamp/glTF/LightsPunctualLamp.gltf");
  const SceneData scene = loadGltf(path);
  EXPECT_EQ(scene.lights.size(), 5u);
  EXPECT_FALSE(scene.textures.empty());
  for (const PunctualLight& l : scene.lights) EXPECT_GT(l.intensity.x + l.intensity.y + l.intensity.z, 0.0f);
}

TEST(GltfLoader, FirstPerspectiveCamera) {
  VPL_REQUIRE_SHARED_SCENE(path, "Cameras/glTF/Cameras.gltf");
  const SceneData scene = loadGltf(path);
  ASSERT_TRUE(scene.camera.has_value());
  EXPECT_NEAR(scene.camera->yfov, 0.7f, 1e-5f);
  EXPECT_NEAR(scene.camera->eye.z, 3.0f, 1e-4f);
  EXPECT_LT(scene.camera->target.z, scene.camera->eye.z);  // looks down -Z
}

// The sRGB electro-optical transfer function (IEC 61966-2-1), in double: the reference the
// loader's 8-bit table must match.
double srgbByteToLinear(int byte) {
  const double c = byte / 255.0;
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

TEST(GltfLoader, SrgbBaseColorTextureIsDecodedToLinear) {
  VPL_REQUIRE_SHARED_SCENE(path, "BoxTextured/glTF/BoxTextured.gltf");
  const SceneData scene = loadGltf(path);
  ASSERT_EQ(scene.textures.size(), 1u);
  EXPECT_EQ(scene.materials[scene.meshes[0].material].baseColorTexture, 0);
  // The file's own bytes, decoded here: every texel's colour is the sRGB decode of its byte, alpha
  // stays linear. A loader that skipped the decode would give 0.502 for byte 128 instead of 0.216.
  int w = 0, h = 0, comp = 0;
  unsigned char* bytes = stbi_load((fs::path(path).parent_path() / "CesiumLogoFlat.png").c_str(), &w, &h, &comp, 4);
  ASSERT_NE(bytes, nullptr);
  const Texture& t = scene.textures[0];
  ASSERT_EQ(t.width, w);
  ASSERT_EQ(t.height, h);
  ASSERT_EQ(t.texels.size(), size_t(w) * size_t(h));
  size_t mid = 0;
  for (size_t p = 0; p < t.texels.size(); ++p) {
    const unsigned char* b = bytes + 4 * p;
    for (int c = 0; c < 3; ++c) {
      ASSERT_NEAR(t.texels[p][c], srgbByteToLinear(b[c]), 1e-5) << "texel " << p << " channel " << c << " byte " << int(b[c]);
      mid += b[c] >= 32 && b[c] <= 224;
    }
    ASSERT_NEAR(t.texels[p].w, b[3] / 255.0, 1e-6) << "texel " << p;
  }
  stbi_image_free(bytes);
  EXPECT_GT(mid, t.texels.size() / 10) << "too few mid-range bytes for the check to mean anything";
}

TEST(GltfLoader, BuiltInScenesHaveCamerasAndLights) {
  for (const char* name : {"cornell_box.gltf", "cornell_glossy.gltf", "two_rooms.gltf", "door_ajar.gltf"}) {
    const SceneData scene = loadGltf(test::sourceDir() + "/scenes/" + name);
    EXPECT_TRUE(scene.camera.has_value()) << name;
    bool emissive = false;
    for (const MeshData& m : scene.meshes) emissive |= scene.materials[m.material].isEmissive();
    EXPECT_TRUE(emissive) << name;
    EXPECT_TRUE(scene.notices.empty()) << name << ": " << scene.notices.front();
  }
}

// Inputs that once crashed, hung or tripped a sanitizer in fuzz/fuzz_gltf_loader (fuzz/regressions/,
// see fuzz/README.md): each is refused now, with the default limits too.
TEST(GltfLoader, FuzzRegressionsAreRefusedWithAnInputError) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(test::sourceDir() + "/fuzz/regressions")) {
    ++count;
    try {
      loadGltf(entry.path());
      ADD_FAILURE() << entry.path() << " loaded but should not";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
  }
  EXPECT_GT(count, 0);
}

// Broken files: one-line InputError naming the file, never a crash.
class BrokenFile : public ::testing::Test {
 protected:
  fs::path dir = fs::temp_directory_path() / ("vplview_loader_" + std::to_string(::getpid()));
  void SetUp() override { fs::create_directories(dir / "scene"); }
  void TearDown() override { fs::remove_all(dir); }
  fs::path write(const std::string& name, const std::string& text) {
    const fs::path p = dir / "scene" / name;
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
  void expectError(const fs::path& p, const std::string& fragment) {
    try {
      loadGltf(p);
      ADD_FAILURE() << p << " loaded but should not";
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(p.string()), std::string::npos) << msg;
      EXPECT_NE(msg.find(fragment), std::string::npos) << "expected '" << fragment << "' in: " << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
  }
  // A triangle with positions in a data URI; `accessorCount` may lie about the data.
  std::string triangleGltf(const std::string& bufferUri, int byteLength, int accessorCount, const std::string& extra = "") {
    return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
           R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)"
           R"("accessors":[{"bufferView":0,"componentType":5126,"count":)" + std::to_string(accessorCount) +
           R"(,"type":"VEC3"}],"bufferViews":[{"buffer":0,"byteLength":36}],)"
           R"("buffers":[{"byteLength":)" + std::to_string(byteLength) + R"(,"uri":")" + bufferUri + R"("}])" + extra + "}";
  }
  static std::string base64(const std::string& bytes) {
    static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    size_t i = 0;
    for (; i + 2 < bytes.size(); i += 3) {
      const uint32_t v = (uint8_t(bytes[i]) << 16) | (uint8_t(bytes[i + 1]) << 8) | uint8_t(bytes[i + 2]);
      out += {t[v >> 18], t[(v >> 12) & 63], t[(v >> 6) & 63], t[v & 63]};
    }
    if (i + 1 == bytes.size()) {
      const uint32_t v = uint8_t(bytes[i]) << 16;
      out += {t[v >> 18], t[(v >> 12) & 63], '=', '='};
    } else if (i + 2 == bytes.size()) {
      const uint32_t v = (uint8_t(bytes[i]) << 16) | (uint8_t(bytes[i + 1]) << 8);
      out += {t[v >> 18], t[(v >> 12) & 63], t[(v >> 6) & 63], '='};
    }
    return out;
  }
  static std::string floats(std::initializer_list<float> v) {
    std::string s(v.size() * 4, '\0');
    std::memcpy(s.data(), std::data(v), s.size());
    return s;
  }
};

TEST_F(BrokenFile, GoodTriangleLoads) {
  const std::string data = "data:application/octet-stream;base64," + base64(floats({0, 0, 0, 1, 0, 0, 0, 1, 0}));
  const SceneData s = loadGltf(write("ok.gltf", triangleGltf(data, 36, 3)));
  EXPECT_EQ(s.triangleCount(), 1u);
  EXPECT_TRUE(s.meshes[0].normals.empty());  // no NORMAL: geometric normals
}

TEST_F(BrokenFile, MissingFile) { expectError(dir / "scene" / "nope.gltf", "no such file"); }

TEST_F(BrokenFile, TruncatedJson) { expectError(write("t.gltf", R"({"asset":{"version":"2.0"},"buffers":[{"byteLe)"), "parse error"); }

TEST_F(BrokenFile, MissingBuffer) { expectError(write("m.gltf", triangleGltf("absent.bin", 36, 3)), "absent.bin"); }

TEST_F(BrokenFile, AccessorOutOfRange) {
  const std::string data = "data:application/octet-stream;base64," + base64(floats({0, 0, 0, 1, 0, 0, 0, 1, 0}));
  expectError(write("r.gltf", triangleGltf(data, 36, 4)), "do not fit");
}

TEST_F(BrokenFile, HugeAccessorClaimIsRefusedBeforeAllocating) {
  const std::string data = "data:application/octet-stream;base64," + base64(floats({0, 0, 0, 1, 0, 0, 0, 1, 0}));
  expectError(write("h.gltf", triangleGltf(data, 36, 2000000000)), "limit");
}

TEST_F(BrokenFile, NanPosition) {
  const std::string data = "data:application/octet-stream;base64," + base64(floats({0, 0, 0, NAN, 0, 0, 0, 1, 0}));
  expectError(write("n.gltf", triangleGltf(data, 36, 3)), "not finite");
}

TEST_F(BrokenFile, ZeroAreaTriangleIsDroppedWithANotice) {
  const std::string data = "data:application/octet-stream;base64," + base64(floats({0, 0, 0, 1, 0, 0, 2, 0, 0}));
  const SceneData s = loadGltf(write("z.gltf", triangleGltf(data, 36, 3)));
  EXPECT_EQ(s.triangleCount(), 0u);
  ASSERT_EQ(s.notices.size(), 2u);
  EXPECT_EQ(s.notices[0], "1 degenerate (zero-area) triangles skipped");
  EXPECT_EQ(s.notices[1], "the scene instances no triangles: only the sky will be seen");
}

TEST_F(BrokenFile, UriEscapingTheSceneFolderIsRefused) {
  std::ofstream(dir / "outside.bin", std::ios::binary) << floats({0, 0, 0, 1, 0, 0, 0, 1, 0});
  expectError(write("e.gltf", triangleGltf("../outside.bin", 36, 3)), "outside the scene's folder");
  expectError(write("a.gltf", triangleGltf((dir / "outside.bin").string(), 36, 3)), "outside the scene's folder");
}

TEST_F(BrokenFile, UnknownRequiredExtension) {
  const std::string data = "data:application/octet-stream;base64," + base64(floats({0, 0, 0, 1, 0, 0, 0, 1, 0}));
  expectError(write("x.gltf", triangleGltf(data, 36, 3, R"(,"extensionsUsed":["EXT_magic"],"extensionsRequired":["EXT_magic"])")),
              "EXT_magic");
}

// 15 bytes: shorter than the 20-byte GLB header and first chunk header.
TEST_F(BrokenFile, GarbageGlb) { expectError(write("g.glb", "glTF\x02\0\0\0garbage"), "Too short"); }

// Peak resident memory of this process so far, in MB.
double peakRssMb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss / 1024.0;
}

TEST_F(BrokenFile, AccessorClaimUnderTheLimitButBeyondItsDataIsRefusedBeforeAllocating) {
  // 125M VEC3 floats = 1.5 GB: under the default 2 GiB limit, but its bufferView holds 36 bytes.
  const std::string data = "data:application/octet-stream;base64," + base64(floats({0, 0, 0, 1, 0, 0, 0, 1, 0}));
  const double before = peakRssMb();
  expectError(write("b.gltf", triangleGltf(data, 36, 125'000'000)), "do not fit");
  EXPECT_LT(peakRssMb() - before, 256.0) << "the accessor's 1.5 GB were allocated before the check";
}

// A PNG signature and IHDR chunk saying w x h RGBA (stb_image skips the CRC), and no pixels.
std::string pngHeader(uint32_t w, uint32_t h) {
  std::string png = "\x89PNG\r\n\x1a\n" + std::string("\0\0\0\x0d", 4) + "IHDR";
  for (uint32_t v : {w, h})
    for (int shift = 24; shift >= 0; shift -= 8) png += char((v >> shift) & 0xff);
  // stb_image 2.30 reads the header up to the first IDAT (a tRNS may come before it): one follows,
  // with two bytes of a zlib stream and no more.
  return png + std::string("\x08\x06\0\0\0", 5) + "CRC!" + std::string("\0\0\0\x02", 4) + "IDATx\x9c" + "CRC!";
}

TEST_F(BrokenFile, ImageHeadersClaimingTooManyPixelsAreRefusedBeforeDecoding) {
  const std::string data = "data:application/octet-stream;base64," + base64(floats({0, 0, 0, 1, 0, 0, 0, 1, 0}));
  auto withImage = [&](uint32_t w, uint32_t h) {
    return triangleGltf(data, 36, 3, R"(,"images":[{"uri":"data:image/png;base64,)" + base64(pngHeader(w, h)) + R"("}])");
  };
  // 100000^2 RGBA is past stb_image's own 1 GiB header check; 16384^2 passes it and meets the
  // loader's limit (64 Mpixels by default).
  expectError(write("i.gltf", withImage(100000, 100000)), "image 0 is not a decodable PNG/JPEG");
  expectError(write("j.gltf", withImage(16384, 16384)), "image 0 claims 16384x16384 pixels, more than the limit");
}

TEST_F(BrokenFile, UrlEncodedUriEscapingTheSceneFolderIsRefused) {
  std::ofstream(dir / "outside.bin", std::ios::binary) << floats({0, 0, 0, 1, 0, 0, 0, 1, 0});
  expectError(write("p.gltf", triangleGltf("%2e%2e/outside.bin", 36, 3)), "outside the scene's folder");
  expectError(write("q.gltf", triangleGltf("%2E%2E%2Foutside.bin", 36, 3)), "outside the scene's folder");
}

TEST_F(BrokenFile, MissingBufferIsNotFoundRatherThanRefused) {
  // tinygltf also looks for it in the working directory; that probe must not turn into "refused".
  expectError(write("m.gltf", triangleGltf("absent.bin", 36, 3)), "not found");
}

TEST_F(BrokenFile, DataUriImageIsDecodedIntoATexture) {
  // One 4x2 image used twice: as the base colour (sRGB-encoded: decoded) and as metallic-roughness
  // (data: taken as is). Mid-range bytes, where decoding matters: 128 -> 0.2159, 188 -> 0.5029.
  // Alpha is linear in both.
  const unsigned char rgba[32] = {128, 188, 64, 128,  10, 1, 0, 255,   200, 100, 50, 25,  255, 230, 20, 0,
                                  0, 32, 96, 160,    160, 96, 32, 64,  3, 11, 40, 200,    250, 150, 75, 5};
  std::string png;
  stbi_write_png_to_func([](void* out, void* bytes, int n) { static_cast<std::string*>(out)->append(static_cast<char*>(bytes), size_t(n)); },
                         &png, 4, 2, 4, rgba, 16);
  const std::string data = "data:application/octet-stream;base64," + base64(floats({0, 0, 0, 1, 0, 0, 0, 1, 0}));
  std::string gltf = triangleGltf(data, 36, 3, R"(,"materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0},)"
                                               R"("metallicRoughnessTexture":{"index":0}}}],)"
                                               R"("textures":[{"source":0}],"images":[{"uri":"data:image/png;base64,)" + base64(png) + R"("}])");
  gltf.replace(gltf.find(R"({"POSITION":0})"), 14, R"({"POSITION":0},"material":0)");
  const SceneData s = loadGltf(write("d.gltf", gltf));
  ASSERT_EQ(s.textures.size(), 2u);
  const Material& m = s.materials[s.meshes[0].material];
  ASSERT_GE(m.baseColorTexture, 0);
  ASSERT_GE(m.metallicRoughnessTexture, 0);
  ASSERT_NE(m.baseColorTexture, m.metallicRoughnessTexture);
  const Texture& colour = s.textures[size_t(m.baseColorTexture)];
  const Texture& linear = s.textures[size_t(m.metallicRoughnessTexture)];
  ASSERT_EQ(colour.width, 4);
  ASSERT_EQ(colour.height, 2);
  ASSERT_EQ(colour.texels.size(), 8u);
  ASSERT_EQ(linear.texels.size(), 8u);
  for (size_t p = 0; p < 8; ++p) {
    for (int c = 0; c < 3; ++c) {
      const int byte = rgba[4 * p + size_t(c)];
      EXPECT_NEAR(colour.texels[p][c], srgbByteToLinear(byte), 1e-5) << "base colour texel " << p << " channel " << c << " byte " << byte;
      EXPECT_NEAR(linear.texels[p][c], byte / 255.0, 1e-6) << "metallic-roughness texel " << p << " channel " << c << " byte " << byte;
    }
    EXPECT_NEAR(colour.texels[p].w, rgba[4 * p + 3] / 255.0, 1e-6) << "texel " << p;
    EXPECT_NEAR(linear.texels[p].w, rgba[4 * p + 3] / 255.0, 1e-6) << "texel " << p;
  }
  // The anchors the issue names, against published values of the sRGB curve.
  EXPECT_NEAR(colour.texels[0].x, 0.21586, 2e-5);  // byte 128
  EXPECT_NEAR(colour.texels[0].y, 0.50289, 2e-5);  // byte 188
}

}  // namespace
}  // namespace vpl

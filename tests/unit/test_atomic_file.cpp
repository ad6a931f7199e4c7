// Atomic image writes (render/film/atomic_file): a failed write leaves the earlier file as it was and
// no temporary behind, and says why in one line. Failures that need another user or a file-size
// limit run in a forked child, so they cannot touch this process.
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include "render/core/error.h"
#include "render/film/atomic_file.h"
#include "render/film/image_io.h"
#include "tests/unit/support.h"

namespace vpl {
namespace {

namespace fs = std::filesystem;

class AtomicFile : public ::testing::Test {
 protected:
  fs::path dir = fs::temp_directory_path() / ("vplview_atomic_" + std::to_string(::getpid()));
  void SetUp() override {
    fs::create_directories(dir);
    fs::permissions(dir, fs::perms(0755));  // another user (below) must reach it
  }
  void TearDown() override {
    fs::permissions(dir, fs::perms(0755));
    fs::remove_all(dir);
  }
  static std::string read(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
  }
  static void put(const fs::path& p, const std::string& bytes) { std::ofstream(p, std::ios::binary) << bytes; }
  size_t entries() const { return size_t(std::distance(fs::directory_iterator(dir), fs::directory_iterator())); }
  // The message of the InputError `write` throws, or "" when it throws none.
  static std::string failure(const std::function<void()>& write) {
    try {
      write();
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }
  // Runs `body` in a child process; true when it exited 0 (it returns the check's verdict).
  static ::testing::AssertionResult inChild(const std::function<bool()>& body) {
    const pid_t pid = ::fork();
    if (pid == 0) ::_exit(body() ? 0 : 1);
    int status = 0;
    ::waitpid(pid, &status, 0);
    if (WIFSIGNALED(status)) return ::testing::AssertionFailure() << "the child was killed by signal " << WTERMSIG(status);
    if (WEXITSTATUS(status) != 0) return ::testing::AssertionFailure() << "the child's checks failed (exit " << WEXITSTATUS(status) << ")";
    return ::testing::AssertionSuccess();
  }
};

TEST_F(AtomicFile, WritesTheBytesAndLeavesOnlyTheTarget) {
  const fs::path target = dir / "a.bin";
  writeFileAtomically(target.string(), std::string("first"));
  writeFileAtomically(target.string(), std::string("second, longer"));
  EXPECT_EQ(read(target), "second, longer");
  EXPECT_EQ(entries(), 1u);
}

TEST_F(AtomicFile, ATargetThatIsADirectoryIsRefusedAndNoTemporaryStays) {
  const fs::path target = dir / "out.png";
  fs::create_directory(target);
  EXPECT_EQ(failure([&] { writeFileAtomically(target.string(), std::string("bytes")); }),
            target.string() + ": cannot write (Is a directory)");
  EXPECT_TRUE(fs::is_directory(target));
  EXPECT_EQ(entries(), 1u);
}

TEST_F(AtomicFile, AFolderThatDoesNotExistIsRefused) {
  const fs::path target = dir / "missing" / "out.exr";
  EXPECT_EQ(failure([&] { writeFileAtomically(target.string(), std::string("bytes")); }),
            target.string() + ": cannot write (No such file or directory)");
}

// chmod does not stop root: the child drops to user nobody (65534) first when it runs as root.
TEST_F(AtomicFile, AnUnwritableFolderIsRefusedAndTheEarlierFileSurvives) {
  const fs::path target = dir / "image.exr";
  put(target, "earlier image");
  fs::permissions(target, fs::perms(0666));
  fs::permissions(dir, fs::perms(0555));
  if (::geteuid() == 0 && !inChild([] { return ::setgid(65534) == 0 && ::setuid(65534) == 0; }))
    GTEST_SKIP() << "running as root and cannot switch to user nobody: chmod would not stop the write, test skipped";
  EXPECT_TRUE(inChild([&] {
    if (::geteuid() == 0 && (::setgid(65534) != 0 || ::setuid(65534) != 0)) return false;
    const std::string message = failure([&] { writeFileAtomically(target.string(), std::string("new image")); });
    return message == target.string() + ": cannot write (Permission denied)";
  }));
  EXPECT_EQ(read(target), "earlier image");
  EXPECT_EQ(entries(), 1u);
}

// A full disk, simulated by RLIMIT_FSIZE: past it write() fails with EFBIG, and SIGXFSZ, which
// would kill the process by default, must be ignored by the writer.
TEST_F(AtomicFile, AFullDiskLeavesTheEarlierFileAndNoTemporary) {
  const fs::path target = dir / "image.exr";
  put(target, "earlier image");
  EXPECT_TRUE(inChild([&] {
    const rlimit limit{4096, 4096};
    if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) return false;
    const std::string message = failure([&] { writeFileAtomically(target.string(), std::string(100000, 'x')); });
    return message == target.string() + ": cannot write (File too large)";
  }));
  EXPECT_EQ(read(target), "earlier image");
  EXPECT_EQ(entries(), 1u);
}

// The image writers go through it: a good EXR and PNG survive a failed overwrite and still read.
TEST_F(AtomicFile, AGoodImageSurvivesAFailedOverwrite) {
  Image image(64, 64);
  for (size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = glm::vec3(float(i % 7), 0.5f, float(i % 3));
  const fs::path exr = dir / "good.exr", png = dir / "good.png";
  writeExr(exr.string(), image);
  writePng(png.string(), image);
  const std::string exrBytes = read(exr), pngBytes = read(png);
  ASSERT_GT(exrBytes.size(), 100u);
  ASSERT_GT(pngBytes.size(), 100u);
  Image other(64, 64);  // all black: different bytes
  EXPECT_TRUE(inChild([&] {
    const rlimit limit{100, 100};  // smaller than either header
    if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) return false;
    return failure([&] { writeExr(exr.string(), other); }) == exr.string() + ": cannot write (File too large)" &&
           failure([&] { writePng(png.string(), other); }) == png.string() + ": cannot write (File too large)";
  }));
  EXPECT_EQ(read(exr), exrBytes);
  EXPECT_EQ(read(png), pngBytes);
  EXPECT_EQ(readExr(exr.string()).pixels[5].x, 5.0f);
  EXPECT_EQ(entries(), 2u);
}

}  // namespace
}  // namespace vpl

#include "render/film/atomic_file.h"

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <system_error>
#include <fcntl.h>
#include <unistd.h>
#include "render/core/error.h"

namespace vpl {

namespace {

// By default SIGXFSZ kills the process mid-write, before it could remove its temporary.
void ignoreFileSizeSignal() {
  static std::once_flag once;
  std::call_once(once, [] {
    struct sigaction current {};
    if (sigaction(SIGXFSZ, nullptr, &current) == 0 && current.sa_handler == SIG_DFL) std::signal(SIGXFSZ, SIG_IGN);
  });
}

[[noreturn]] void fail(const std::string& path, int error) {
  throw InputError(path + ": cannot write (" + std::generic_category().message(error) + ")");
}

// Opens a new, unique file beside the target (O_EXCL: never someone else's file).
int openTemporary(const std::filesystem::path& target, std::string& tmp) {
  static std::atomic<unsigned> counter{0};
  const std::filesystem::path dir = target.has_parent_path() ? target.parent_path() : std::filesystem::path(".");
  for (int attempt = 0; attempt < 100; ++attempt) {
    // ".NAME.PID.N.tmp", appended piece by piece: GCC 12 warns falsely (-Wrestrict) on "." + string.
    char suffix[48];
    std::snprintf(suffix, sizeof suffix, ".%ld.%u.tmp", long(::getpid()), counter++);
    std::string name(1, '.');
    name.append(target.filename().string()).append(suffix);
    tmp = (dir / name).string();
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);  // 0666 & ~umask, as fopen
    if (fd >= 0 || errno != EEXIST) return fd;
  }
  errno = EEXIST;
  return -1;
}

}  // namespace

void writeFileAtomically(const std::string& path, const void* data, size_t size) {
  ignoreFileSizeSignal();
  const std::filesystem::path target(path);
  if (!target.has_filename()) fail(path, EISDIR);
  std::string tmp;
  const int fd = openTemporary(target, tmp);
  if (fd < 0) fail(path, errno);
  auto abandon = [&](int error, bool open) {
    if (open) ::close(fd);
    ::unlink(tmp.c_str());
    fail(path, error);
  };
  const char* p = static_cast<const char*>(data);
  for (size_t left = size; left > 0;) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) abandon(n < 0 ? errno : EIO, true);
    p += n;
    left -= size_t(n);
  }
  // Without fsync a crash soon after the rename can leave an empty file under the name.
  if (::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) abandon(errno, true);  // EINVAL: cannot sync (pipe, ...)
  if (::close(fd) != 0) abandon(errno, false);
  if (::rename(tmp.c_str(), path.c_str()) != 0) abandon(errno, false);
}

}  // namespace vpl

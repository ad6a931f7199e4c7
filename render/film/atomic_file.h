// Whole-file writes that never leave a partial file where a good one stood: the bytes go to a
// temporary file in the target's folder, which replaces the target (rename, atomic within one file
// system) only after every write, the fsync and the close succeeded.
#pragma once
#include <cstddef>
#include <string>

namespace vpl {

// On failure throws InputError "<path>: cannot write (<reason>)"; the earlier file, if any, is
// untouched and the temporary is removed. A write past RLIMIT_FSIZE fails with "File too large"
// instead of killing the process: SIGXFSZ is ignored from the first call on, unless handled.
void writeFileAtomically(const std::string& path, const void* data, size_t size);
inline void writeFileAtomically(const std::string& path, const std::string& bytes) {
  writeFileAtomically(path, bytes.data(), bytes.size());
}

}  // namespace vpl

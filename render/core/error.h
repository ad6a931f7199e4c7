// Errors the user can fix (bad files, bad flags): the CLI prints them on one line and exits 2.
#pragma once
#include <stdexcept>
#include <string>

namespace vpl {

struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace vpl

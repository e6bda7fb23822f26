// Errors the user can fix: bad scene files, bad overrides, unwritable outputs.
// Every message is one line that names the file and, where there is one, the key.
#pragma once

#include <stdexcept>
#include <string>

namespace drape::scene {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace drape::scene

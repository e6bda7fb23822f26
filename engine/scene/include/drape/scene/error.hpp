// Errors the user can fix: bad scene files, bad overrides, unwritable outputs.
// Every message is one line that names the file and, where there is one, the key.
#pragma once

#include <stdexcept>
#include <string>

namespace drape::scene {

class InputError : public std::runtime_error {
 public:
  // Control characters (a key or file name with a newline in it) become '?': one line, always.
  explicit InputError(const std::string& message) : std::runtime_error(oneLine(message)) {}

 private:
  static std::string oneLine(std::string text) {
    for (char& c : text) {
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
    }
    return text;
  }
};

}  // namespace drape::scene

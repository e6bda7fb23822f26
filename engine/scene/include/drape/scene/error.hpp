// Errors the user can fix: bad scene files, bad overrides, unwritable outputs.
// Every message is one line that names the file and, where there is one, the key.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

namespace drape::scene {

// `text` as it may appear in a one-line message: bytes that are not printable ASCII or valid UTF-8
// (a newline, a stray byte of a binary file) become '?', and text longer than maxBytes is cut there
// with "...". For whatever a message quotes of the user's input: keys, values, paths.
std::string printable(std::string_view text, std::size_t maxBytes = 80);

class InputError : public std::runtime_error {
 public:
  // One line, always, and never more than a screenful: the parts quoting input are cut shorter
  // where they are made; this is the last line of defence.
  explicit InputError(const std::string& message) : std::runtime_error(printable(message, 2000)) {}
};

// Keys each valid alone that do not go together (sim::conflict: a max stretch with the seed's sweep,
// say). A study that sweeps every combination of some keys skips these and says which.
class KeyConflict : public InputError {
 public:
  using InputError::InputError;
};

}  // namespace drape::scene

#include "drape/scene/input.hpp"

#include <cerrno>
#include <cstring>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "drape/scene/error.hpp"

namespace drape::scene {

using nlohmann::json;

namespace {

// Closes the descriptor however the reader leaves.
struct Descriptor {
  int fd;
  ~Descriptor() {
    if (fd >= 0) ::close(fd);
  }
};

std::string sizeText(std::size_t bytes) {
  return bytes >= (std::size_t{1} << 20) ? std::to_string(bytes >> 20) + " MiB" : std::to_string(bytes) + " bytes";
}

// Builds the document as nlohmann's own DOM parser does, through its SAX interface, and also
// refuses duplicate keys and deep nesting. (nlohmann's callback parser could do the checks, but it
// rescans the enclosing array at the end of every element: 1,000,000 gesture events took 955 s.)
class StrictBuilder {
 public:
  explicit StrictBuilder(const std::string& source) : source_(source) {}

  json take() { return std::move(root_); }

  bool null() { return put(nullptr) != nullptr; }
  bool boolean(bool value) { return put(value) != nullptr; }
  bool number_integer(json::number_integer_t value) { return put(value) != nullptr; }
  bool number_unsigned(json::number_unsigned_t value) { return put(value) != nullptr; }
  bool number_float(json::number_float_t value, const std::string&) { return put(value) != nullptr; }
  bool string(json::string_t& value) { return put(std::move(value)) != nullptr; }
  bool binary(json::binary_t& value) { return put(json::binary(std::move(value))) != nullptr; }
  bool start_object(std::size_t) { return open(json::object()); }
  bool start_array(std::size_t) { return open(json::array()); }
  bool end_object() { return close(); }
  bool end_array() { return close(); }
  bool key(json::string_t& key) {
    // JSON allows a key twice in one object and keeps the last; a file that does so has a mistake
    // in it, so it is refused rather than silently half-read.
    if (open_.back()->contains(key)) {
      throw InputError(source_ + ": key \"" + printable(key) + "\" appears twice in one object");
    }
    key_ = std::move(key);
    return true;
  }
  bool parse_error(std::size_t, const std::string&, const json::exception& error) {
    // nlohmann's messages start with a tag: "[json.exception.parse_error.101] parse error at line 3, ..."
    std::string message = error.what();
    const std::size_t tagEnd = message.find("] ");
    if (tagEnd != std::string::npos) message = message.substr(tagEnd + 2);
    // The message quotes the last token read, which may be megabytes of anything.
    throw InputError(source_ + ": malformed JSON: " + printable(message, 200));
  }

 private:
  json* put(json value) {
    if (open_.empty()) {
      root_ = std::move(value);
      return &root_;
    }
    json& parent = *open_.back();
    if (parent.is_array()) {
      parent.push_back(std::move(value));
      return &parent.back();
    }
    json& slot = parent[key_];
    slot = std::move(value);
    return &slot;
  }
  bool open(json container) {
    // Deeper than any file of ours: refused before anything recursive (printing, copying) meets it.
    if (open_.size() >= static_cast<std::size_t>(kMaxJsonDepth)) {
      throw InputError(source_ + ": nested more than " + std::to_string(kMaxJsonDepth) + " levels deep");
    }
    open_.push_back(put(std::move(container)));
    return true;
  }
  bool close() {
    open_.pop_back();
    return true;
  }

  const std::string& source_;
  json root_;
  std::vector<json*> open_;  // the containers being filled, innermost last
  std::string key_;          // the key the next value of the innermost object goes to
};

}  // namespace

std::string printable(std::string_view text, std::size_t maxBytes) {
  std::string out;
  out.reserve(std::min(text.size(), maxBytes) + 3);
  std::size_t i = 0;
  while (i < text.size()) {
    if (out.size() >= maxBytes) {
      out += "...";
      break;
    }
    const auto byte = static_cast<unsigned char>(text[i]);
    // The length of a well-formed UTF-8 sequence starting here, or 0 (RFC 3629: no overlongs, no
    // surrogates, nothing past U+10FFFF).
    std::size_t length = 0;
    if (byte >= 0x20 && byte < 0x7f) {
      length = 1;
    } else if (byte >= 0xc2 && byte <= 0xf4) {
      length = byte < 0xe0 ? 2 : byte < 0xf0 ? 3 : 4;
      if (i + length > text.size()) length = 0;
      for (std::size_t k = 1; length && k < length; ++k) {
        if ((static_cast<unsigned char>(text[i + k]) & 0xc0) != 0x80) length = 0;
      }
      if (length) {
        const auto second = static_cast<unsigned char>(text[i + 1]);
        if ((byte == 0xe0 && second < 0xa0) || (byte == 0xed && second > 0x9f) || (byte == 0xf0 && second < 0x90) ||
            (byte == 0xf4 && second > 0x8f)) {
          length = 0;
        }
      }
    }
    if (length == 0) {
      out += '?';
      ++i;
    } else {
      out.append(text.substr(i, length));
      i += length;
    }
  }
  return out;
}

std::string readInputFile(const std::filesystem::path& file, std::string_view what, std::size_t maxBytes) {
  const std::string prefix = printable(file.string(), 200) + ": cannot open the " + std::string(what) + ": ";
  // Non-blocking, so that opening a FIFO with no writer returns at once (fstat then refuses it).
  const Descriptor in{::open(file.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY)};
  if (in.fd < 0) {
    const int error = errno;
    throw InputError(prefix + (error == ENOENT ? "it does not exist" : std::strerror(error)));
  }
  struct stat status {};
  if (::fstat(in.fd, &status) != 0) throw InputError(prefix + std::strerror(errno));
  if (S_ISDIR(status.st_mode)) throw InputError(prefix + "it is a folder");
  if (!S_ISREG(status.st_mode)) throw InputError(prefix + "it is not a regular file (a device, FIFO or socket)");
  if (static_cast<std::uintmax_t>(status.st_size) > maxBytes) {
    throw InputError(prefix + "it is larger than the limit of " + sizeText(maxBytes));
  }
  std::string text(static_cast<std::size_t>(status.st_size), '\0');
  std::size_t done = 0;
  while (true) {
    if (done == text.size()) {
      // The file may have grown since fstat: read on, within the limit.
      if (text.size() >= maxBytes + 1) break;
      text.resize(std::min(maxBytes + 1, std::max<std::size_t>(2 * text.size(), 4096)));
    }
    const ssize_t got = ::read(in.fd, text.data() + done, text.size() - done);
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) throw InputError(prefix + std::strerror(errno));
    if (got == 0) break;
    done += static_cast<std::size_t>(got);
  }
  if (done > maxBytes) throw InputError(prefix + "it is larger than the limit of " + sizeText(maxBytes));
  text.resize(done);
  return text;
}

json parseJson(std::string_view text, const std::string& source) {
  StrictBuilder builder(source);
  json::sax_parse(text, &builder);
  return builder.take();
}

}  // namespace drape::scene

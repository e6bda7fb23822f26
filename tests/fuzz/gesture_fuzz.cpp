// Fuzzes the gesture script reader: the input is a script's JSON text.
//
// A script that parses is also written back (gestureDocument, what the app records) and read
// again: a recorded script must load, with the same events. Expected failures of the first read:
// InputError and std::invalid_argument; anything else escapes, and libFuzzer reports it.
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "drape/scene/error.hpp"
#include "drape/scene/gesture.hpp"
#include "drape/scene/input.hpp"
#include "fuzz_support.hpp"

using namespace drape;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  interact::GestureScript script;
  try {
    script = scene::parseGesture(scene::parseJson(fuzz::text(data, size), "fuzz.json"), "fuzz.json");
  } catch (const scene::InputError&) {
    return 0;
  } catch (const std::invalid_argument&) {
    return 0;
  }
  try {
    const interact::GestureScript again = scene::parseGesture(scene::gestureDocument(script), "recorded.json");
    if (again.events.size() != script.events.size()) fuzz::broken("a recorded script reads back with other events");
  } catch (const scene::InputError& error) {
    fuzz::broken("a recorded script does not read back:", error.what());
  } catch (const std::invalid_argument& error) {
    fuzz::broken("a recorded script does not read back:", error.what());
  }
  return 0;
}

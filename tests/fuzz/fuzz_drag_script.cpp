// libFuzzer target for quiver-view's drag scripts, under AddressSanitizer and UBSan. A
// std::runtime_error is the only acceptable failure; an accepted script must answer at() for any
// frame with a cursor inside the window.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "apps/view/drag_script.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  quiver::app::DragScript script;
  try {
    script = quiver::app::DragScript::parse(std::string(reinterpret_cast<const char*>(data), size), "fuzz.txt");
  } catch (const std::runtime_error&) {
    return 0;
  }
  for (int frame : {0, 1, 7, 100, 1 << 20, 2147483647}) {
    const quiver::app::ScriptedCursor c = script.at(frame);
    if (!(c.x >= 0 && c.x <= 1 && c.y >= 0 && c.y <= 1)) std::abort();
  }
  return 0;
}

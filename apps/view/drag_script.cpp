#include "apps/view/drag_script.h"

#include <sstream>
#include <stdexcept>

#include "formats/mesh/read_mesh.h"

namespace quiver::app {

DragScript DragScript::parse(const std::string& text, const std::string& fileName) {
  DragScript script;
  std::istringstream lines(text);
  std::string line;
  bool down = false;
  for (int number = 1; std::getline(lines, line); ++number) {
    const auto fail = [&](const std::string& what) {
      throw std::runtime_error(fileName + ":" + std::to_string(number) + ": " + what);
    };
    line = line.substr(0, line.find('#'));
    std::istringstream words(line);
    std::string frameText, action;
    if (!(words >> frameText)) continue;
    Event e{0, Action::Move, 0, 0};
    size_t used = 0;
    try {
      e.frame = std::stoi(frameText, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != frameText.size() || e.frame < 0) fail("'" + frameText + "' is not a frame number (0, 1, 2, ...)");
    if (!script.events_.empty() && e.frame < script.events_.back().frame)
      fail("frame " + frameText + " comes before the previous event's frame " + std::to_string(script.events_.back().frame));
    if (!(words >> action)) fail("an action is missing after the frame: press X Y, move X Y or release");
    if (action == "press" || action == "move") {
      e.action = action == "press" ? Action::Press : Action::Move;
      if (!(words >> e.x >> e.y)) fail(action + " needs X Y, window fractions from the top-left corner");
      if (!(e.x >= 0 && e.x <= 1 && e.y >= 0 && e.y <= 1)) fail("X and Y are fractions of the window: between 0 and 1");
      if (e.action == Action::Press && down) fail("press while the button is already pressed");
      down = down || e.action == Action::Press;
    } else if (action == "release") {
      if (!down) fail("release without a press before it");
      e.action = Action::Release;
      down = false;
    } else {
      fail("unknown action '" + action + "': press X Y, move X Y or release");
    }
    std::string extra;
    if (words >> extra) fail("unexpected '" + extra + "' after the event");
    script.events_.push_back(e);
  }
  return script;
}

DragScript DragScript::load(const std::string& path) { return parse(readFileBytes(path), path); }

ScriptedCursor DragScript::at(int frame) const {
  ScriptedCursor cursor;
  const Event* last = nullptr;  // the latest event with a position at or before `frame`
  for (const Event& e : events_) {
    if (e.frame > frame) {
      // Glide toward the next point while the button is held.
      if (e.action == Action::Move && last && cursor.down) {
        const double s = static_cast<double>(frame - last->frame) / (e.frame - last->frame);
        cursor.x = last->x + s * (e.x - last->x);
        cursor.y = last->y + s * (e.y - last->y);
      }
      break;
    }
    if (e.action == Action::Release) {
      cursor.down = false;
      continue;
    }
    cursor.down = cursor.down || e.action == Action::Press;
    cursor.x = e.x;
    cursor.y = e.y;
    last = &e;
  }
  return cursor;
}

} // namespace quiver::app

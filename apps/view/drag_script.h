#pragma once
// A scripted mouse for the viewer (`quiver-view --drag-script FILE`), on the model and the panel
// alike, so that tests and recordings act the same way every run. One event per line, frames in
// order, '#' starts a comment:
//
//   # frame  action   x     y      (x, y: fractions of the window, from its top-left corner)
//   10       press    0.80  0.45
//   40       move     0.80  0.75   # the cursor glides from the previous point over frames 10..40
//   90       release
#include <string>
#include <vector>

namespace quiver::app {

struct ScriptedCursor {
  bool down = false;
  double x = 0.5, y = 0.5;  // window fractions
};

class DragScript {
public:
  // Throws std::runtime_error naming the file, the line and what is wrong.
  static DragScript parse(const std::string& text, const std::string& fileName);
  static DragScript load(const std::string& path);

  // Where the cursor is, and whether the button is held, at `frame`.
  ScriptedCursor at(int frame) const;

private:
  enum class Action { Press, Move, Release };
  struct Event {
    int frame;
    Action action;
    double x, y;
  };
  std::vector<Event> events_;
};

} // namespace quiver::app

#pragma once
// Where `quiver render` puts its pictures, chosen by the output path:
//   NAME.png         one picture (the last frame given)
//   NAME_%04d.png    an image sequence, one file per frame numbered from 0 (%d or %0Nd, N <= 9)
//   NAME.gif         an animated GIF, looping, played back at the simulation's own speed
// Every file is written atomically; a GIF appears only once it is complete.
#include <memory>
#include <string>

#include "apps/render/software_renderer.h"

namespace quiver::app {

class FrameWriter {
public:
  // `frameSeconds`: the time a frame stands for, which sets the GIF's frame delays (GIF counts in
  // hundredths of a second, and browsers slow anything under 0.02 s, so a delay is at least that).
  // Throws if the path's kind cannot be told (a pattern holds one %d or %0Nd field and ends in .png).
  FrameWriter(const std::string& path, double frameSeconds);
  ~FrameWriter();
  FrameWriter(const FrameWriter&) = delete;
  FrameWriter& operator=(const FrameWriter&) = delete;

  // True when every frame is kept (sequence or GIF); a single picture only needs the last one.
  bool animated() const;
  void add(const Image& frame);
  // Writes what is pending (the picture or the GIF).
  void finish();

private:
  struct Gif;
  enum class Kind { Picture, Sequence, Gif } kind_;
  std::string path_;
  double frameSeconds_;
  int frames_ = 0;
  long shownCentiseconds_ = 0;  // GIF: the delays written so far
  std::unique_ptr<Image> last_;
  std::unique_ptr<Gif> gif_;
};

} // namespace quiver::app

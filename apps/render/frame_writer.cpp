#include "apps/render/frame_writer.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <unordered_map>
#include <vector>

#include <gif_lib.h>

#include "formats/atomic_file.h"

namespace quiver::app {

namespace {

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// One %d or %0Nd field (N from 1 to 9) and no other '%': patterns snprintf fills safely, into names
// without spaces.
bool isFramePattern(const std::string& path) {
  const size_t at = path.find('%');
  if (at == std::string::npos || path.find('%', at + 1) != std::string::npos) return false;
  const std::string field = path.substr(at + 1, 3);
  return field.rfind("d", 0) == 0 ||
         (field.size() == 3 && field[0] == '0' && field[1] >= '1' && field[1] <= '9' && field[2] == 'd');
}

} // namespace

// The GIF is encoded into memory as frames arrive, each with its own 256-colour table.
struct FrameWriter::Gif {
  std::string bytes;
  GifFileType* file = nullptr;
  int width = 0, height = 0;

  static int append(GifFileType* g, const GifByteType* data, int size) {
    static_cast<Gif*>(g->UserData)->bytes.append(reinterpret_cast<const char*>(data), static_cast<size_t>(size));
    return size;
  }
  void fail(const std::string& path, const char* what, int code) {
    throw std::runtime_error(path + ": GIF encoding failed " + what + " (" + GifErrorString(code) + ")");
  }
  void start(const std::string& path, int w, int h) {
    int error = 0;
    file = EGifOpen(this, append, &error);
    if (!file) fail(path, "at the start", error);
    width = w;
    height = h;
    EGifSetGifVersion(file, true);
    if (EGifPutScreenDesc(file, w, h, 8, 0, nullptr) == GIF_ERROR) fail(path, "in the header", file->Error);
    // NETSCAPE2.0 application block: loop forever.
    const GifByteType app[] = {'N', 'E', 'T', 'S', 'C', 'A', 'P', 'E', '2', '.', '0'}, loop[] = {1, 0, 0};
    if (EGifPutExtensionLeader(file, APPLICATION_EXT_FUNC_CODE) == GIF_ERROR ||
        EGifPutExtensionBlock(file, sizeof app, app) == GIF_ERROR || EGifPutExtensionBlock(file, sizeof loop, loop) == GIF_ERROR ||
        EGifPutExtensionTrailer(file) == GIF_ERROR)
      fail(path, "in the loop block", file->Error);
  }
  void add(const std::string& path, const Image& image, long centiseconds) {
    std::vector<GifColorType> table(256);
    std::vector<GifByteType> indices;
    if (!exactColours(image, table, indices)) quantize(path, image, table, indices);
    ColorMapObject* map = GifMakeMapObject(256, table.data());
    GraphicsControlBlock control{DISPOSAL_UNSPECIFIED, false, static_cast<int>(std::min(centiseconds, 65535L)),
                                 NO_TRANSPARENT_COLOR};
    GifByteType extension[4];
    EGifGCBToExtension(&control, extension);
    const bool ok = EGifPutExtension(file, GRAPHICS_EXT_FUNC_CODE, sizeof extension, extension) != GIF_ERROR &&
                    EGifPutImageDesc(file, 0, 0, width, height, false, map) != GIF_ERROR;
    GifFreeMapObject(map);
    if (!ok) fail(path, "in a frame header", file->Error);
    for (int y = 0; y < height; ++y)
      if (EGifPutLine(file, &indices[static_cast<size_t>(y) * width], width) == GIF_ERROR) fail(path, "in a frame", file->Error);
  }
  // A shaded model on a plain background has a few hundred colours at most: keep them exact when they fit.
  static bool exactColours(const Image& image, std::vector<GifColorType>& table, std::vector<GifByteType>& indices) {
    std::unordered_map<uint32_t, GifByteType> index;
    indices.resize(image.rgb.size() / 3);
    for (size_t i = 0; i < indices.size(); ++i) {
      const uint8_t* c = &image.rgb[3 * i];
      const uint32_t key = uint32_t(c[0]) << 16 | uint32_t(c[1]) << 8 | c[2];
      auto [at, added] = index.try_emplace(key, static_cast<GifByteType>(index.size()));
      if (added) {
        if (index.size() > 256) return false;
        table[at->second] = GifColorType{c[0], c[1], c[2]};
      }
      indices[i] = at->second;
    }
    return true;
  }
  void quantize(const std::string& path, const Image& image, std::vector<GifColorType>& table,
                std::vector<GifByteType>& indices) const {
    const size_t n = static_cast<size_t>(width) * height;
    std::vector<GifByteType> r(n), g(n), b(n);
    for (size_t i = 0; i < n; ++i) {
      r[i] = image.rgb[3 * i];
      g[i] = image.rgb[3 * i + 1];
      b[i] = image.rgb[3 * i + 2];
    }
    int colours = 256;
    if (GifQuantizeBuffer(width, height, &colours, r.data(), g.data(), b.data(), indices.data(), table.data()) == GIF_ERROR)
      throw std::runtime_error(path + ": GIF colour quantization failed");
  }
  void close(const std::string& path) {
    int error = 0;
    GifFileType* f = file;
    file = nullptr;
    if (EGifCloseFile(f, &error) == GIF_ERROR) fail(path, "at the end", error);
    writeFileAtomically(path, bytes);
  }
  ~Gif() {
    int error = 0;
    if (file) EGifCloseFile(file, &error);
  }
};

FrameWriter::FrameWriter(const std::string& path, double frameSeconds) : path_(path), frameSeconds_(frameSeconds) {
  if (path.find('%') != std::string::npos) {
    if (!isFramePattern(path) || !endsWith(path, ".png"))
      throw std::runtime_error("-o " + path + ": an image sequence needs one %d or %0Nd field (such as %04d) and a .png name");
    kind_ = Kind::Sequence;
  } else if (endsWith(path, ".gif")) {
    kind_ = Kind::Gif;
  } else if (endsWith(path, ".png")) {
    kind_ = Kind::Picture;
  } else {
    throw std::runtime_error("-o " + path + ": write a .png picture, a .gif animation or a NAME_%04d.png sequence");
  }
}

FrameWriter::~FrameWriter() = default;

bool FrameWriter::animated() const { return kind_ != Kind::Picture; }

void FrameWriter::add(const Image& frame) {
  switch (kind_) {
  case Kind::Picture:
    last_ = std::make_unique<Image>(frame);
    break;
  case Kind::Sequence: {
    std::vector<char> name(static_cast<size_t>(std::snprintf(nullptr, 0, path_.c_str(), frames_)) + 1);
    std::snprintf(name.data(), name.size(), path_.c_str(), frames_);
    writePng(name.data(), frame);
    break;
  }
  case Kind::Gif:
    if (!gif_) {
      gif_ = std::make_unique<Gif>();
      gif_->start(path_, frame.width, frame.height);
    }
    {
      // Whole hundredths per frame, with the rounding carried over, so the animation keeps time.
      const long delay = std::max(2L, std::lround(100 * frameSeconds_ * (frames_ + 1)) - shownCentiseconds_);
      gif_->add(path_, frame, delay);
      shownCentiseconds_ += delay;
    }
    break;
  }
  ++frames_;
}

void FrameWriter::finish() {
  if (kind_ == Kind::Picture && last_) writePng(path_, *last_);
  if (kind_ == Kind::Gif && gif_) gif_->close(path_);
}

} // namespace quiver::app

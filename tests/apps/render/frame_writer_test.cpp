// FrameWriter: the output path chooses a picture, an image sequence or a GIF; files are complete
// or absent. The GIF is read back with giflib's decoder, independently of how it was encoded.
#include <gtest/gtest.h>

#include <filesystem>

#include <gif_lib.h>

#include "apps/render/frame_writer.h"
#include "tests/support/test_support.h"

namespace fs = std::filesystem;
using quiver::app::FrameWriter;
using quiver::app::Image;

namespace {

Image frame(int w, int h, unsigned char shade) {
  Image im(w, h);
  im.rgb.assign(3 * static_cast<size_t>(w) * h, shade);
  return im;
}

struct FrameWriterTest : ::testing::Test {
  fs::path dir = quiver::test::tempDir(::testing::UnitTest::GetInstance()->current_test_info()->name());
};

} // namespace

TEST_F(FrameWriterTest, APictureKeepsOnlyTheLastFrame) {
  const fs::path p = dir / "shot.png";
  FrameWriter w(p.string(), 1.0 / 60);
  EXPECT_FALSE(w.animated());
  w.add(frame(8, 4, 10));
  w.add(frame(8, 4, 200));
  EXPECT_FALSE(fs::exists(p)) << "nothing is written before finish()";
  w.finish();
  ASSERT_TRUE(fs::exists(p));
  std::FILE* f = std::fopen(p.c_str(), "rb");
  unsigned char sig[8] = {};
  ASSERT_EQ(std::fread(sig, 1, 8, f), 8u);
  std::fclose(f);
  EXPECT_EQ(sig[1], 'P');
  EXPECT_EQ(sig[2], 'N');
  EXPECT_EQ(sig[3], 'G');
}

TEST_F(FrameWriterTest, ASequenceNumbersEveryFrameFromZero) {
  FrameWriter w((dir / "f_%03d.png").string(), 0.1);
  EXPECT_TRUE(w.animated());
  for (int i = 0; i < 3; ++i) w.add(frame(4, 4, static_cast<unsigned char>(50 * i)));
  w.finish();
  for (const char* name : {"f_000.png", "f_001.png", "f_002.png"}) EXPECT_TRUE(fs::exists(dir / name)) << name;
  EXPECT_FALSE(fs::exists(dir / "f_003.png"));
}

TEST_F(FrameWriterTest, AGifLoopsAndKeepsSimulationTime) {
  const fs::path p = dir / "anim.gif";
  {
    FrameWriter w(p.string(), 0.05);  // 5 hundredths a frame
    for (int i = 0; i < 4; ++i) w.add(frame(6, 5, static_cast<unsigned char>(60 * i)));
    EXPECT_FALSE(fs::exists(p)) << "a GIF appears only once complete";
    w.finish();
  }
  int error = 0;
  GifFileType* gif = DGifOpenFileName(p.c_str(), &error);
  ASSERT_NE(gif, nullptr) << GifErrorString(error);
  ASSERT_EQ(DGifSlurp(gif), GIF_OK);
  EXPECT_EQ(gif->SWidth, 6);
  EXPECT_EQ(gif->SHeight, 5);
  ASSERT_EQ(gif->ImageCount, 4);
  int total = 0;
  for (int i = 0; i < gif->ImageCount; ++i) {
    GraphicsControlBlock gcb;
    ASSERT_EQ(DGifSavedExtensionToGCB(gif, i, &gcb), GIF_OK);
    total += gcb.DelayTime;
    // One flat shade per frame, reproduced exactly through the palette.
    const SavedImage& im = gif->SavedImages[i];
    const ColorMapObject* map = im.ImageDesc.ColorMap ? im.ImageDesc.ColorMap : gif->SColorMap;
    ASSERT_NE(map, nullptr);
    EXPECT_EQ(map->Colors[im.RasterBits[0]].Red, 60 * i);
  }
  EXPECT_EQ(total, 20) << "4 frames of 0.05 s are 20 hundredths";
  DGifCloseFile(gif, &error);
}

TEST_F(FrameWriterTest, PathsWhoseKindCannotBeToldAreRefused) {
  for (const char* bad : {"x.jpg", "x_%d_%d.png", "x_%s.png", "x_%10d.png", "x_%d.gif", "x"})
    EXPECT_THROW(FrameWriter((dir / bad).string(), 0.1), std::runtime_error) << bad;
}

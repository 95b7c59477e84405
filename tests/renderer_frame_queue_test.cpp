// The renderer's writer thread (frame_queue.hpp): every frame written, in order, when skipping is
// not allowed (lockstep); frames skipped and counted, never reordered, when the writer is behind
// in rate mode; a write failure reaches the receiving thread.
#include <gtest/gtest.h>

#include <filesystem>

#include "frame_queue.hpp"

namespace dlslot::renderer {
namespace {

std::string freshDir(const std::string& name) {
  const std::string dir = (std::filesystem::temp_directory_path() / ("dlslot_frame_queue_" + name)).string();
  std::filesystem::remove_all(dir);
  return dir;
}

RenderInput frame(int i) {
  RenderInput in;
  in.frame = i;
  in.has_tracks = i % 2 == 0;
  return in;
}

TEST(RendererFrameQueue, LockstepWritesEveryFrameInOrder) {
  const std::string dir = freshDir("lockstep");
  FrameWriter writer(dir, RendererConfig());
  FrameQueue queue(writer, 2, false);
  for (int i = 0; i < 8; ++i) EXPECT_TRUE(queue.submit(frame(i)));  // far faster than drawing
  queue.finish();
  const std::vector<FrameQueue::Written> written = queue.takeWritten();
  ASSERT_EQ(written.size(), 8u);
  for (int i = 0; i < 8; ++i) {
    EXPECT_EQ(written[i].frame, i);
    EXPECT_EQ(written[i].has_tracks, i % 2 == 0);
    EXPECT_GT(written[i].ms, 0.0);
    EXPECT_TRUE(std::filesystem::exists(writer.framePath(i))) << writer.framePath(i);
  }
  EXPECT_EQ(queue.skipped(), 0);
  std::filesystem::remove_all(dir);
}

TEST(RendererFrameQueue, RateModeSkipsAndCountsWhenBehind) {
  const std::string dir = freshDir("rate");
  FrameWriter writer(dir, RendererConfig());
  FrameQueue queue(writer, 2, true);
  int accepted = 0;
  for (int i = 0; i < 30; ++i) accepted += queue.submit(frame(i));  // 30 frames in well under a draw
  queue.finish();
  const std::vector<FrameQueue::Written> written = queue.takeWritten();
  EXPECT_EQ(static_cast<int>(written.size()), accepted);
  EXPECT_EQ(queue.skipped(), 30 - accepted);
  EXPECT_GT(queue.skipped(), 0);
  EXPECT_GE(accepted, 2);  // the first frames always fit
  for (size_t i = 1; i < written.size(); ++i) EXPECT_LT(written[i - 1].frame, written[i].frame);
  int files = 0;
  for (int i = 0; i < 30; ++i) files += std::filesystem::exists(writer.framePath(i));
  EXPECT_EQ(files, accepted);
  std::filesystem::remove_all(dir);
}

TEST(RendererFrameQueue, AWriteFailureReachesTheCaller) {
  const std::string dir = freshDir("failure");
  FrameWriter writer(dir, RendererConfig());
  std::filesystem::create_directories(writer.framePath(0) + ".part");  // the PNG cannot be written
  FrameQueue queue(writer, 2, false);
  queue.submit(frame(0));
  queue.finish();
  EXPECT_THROW(queue.takeWritten(), std::runtime_error);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace dlslot::renderer

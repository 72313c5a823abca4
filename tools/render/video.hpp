// The frames of a run assembled into DIR/video.mp4 (H.264, yuv420p, one video frame per
// frame of the run at output.video_fps), when ffmpeg is on the PATH. Without it
// the run says so once and carries on: the video is a convenience, the frames are the output.
#pragma once
#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>

#include "tools/frame_sink.hpp"

namespace papertear::render {

// The first executable called `name` in the ':'-separated directories of `path`.
std::optional<std::filesystem::path> find_on_path(const std::string& name, const std::string& path);

class VideoSink final : public io::FrameSink {
 public:
  // frames_dir holds PREFIX_NNNN.png; the video goes to out_dir/video.mp4. `search_path` is
  // where ffmpeg is looked for (the PATH); notices go to `log`.
  VideoSink(std::filesystem::path frames_dir, std::string prefix, std::filesystem::path out_dir, int fps,
            std::string search_path, std::ostream& log);
  void on_frame(const Simulation&, int, int, const Metrics&) override {}
  void on_finish(const Simulation& sim, const io::RunRecord& record) override;

 private:
  std::filesystem::path frames_dir_, out_dir_;
  std::string prefix_, search_path_;
  int fps_;
  std::ostream& log_;
};

}  // namespace papertear::render

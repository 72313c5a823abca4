#include "tools/render/video.hpp"

#include <ostream>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

extern char** environ;

namespace papertear::render {

std::optional<std::filesystem::path> find_on_path(const std::string& name, const std::string& path) {
  std::size_t begin = 0;
  while (begin <= path.size()) {
    const std::size_t end = std::min(path.find(':', begin), path.size());
    const std::filesystem::path candidate = std::filesystem::path(path.substr(begin, end - begin)) / name;
    if (end > begin && ::access(candidate.c_str(), X_OK) == 0) return candidate;
    begin = end + 1;
  }
  return std::nullopt;
}

VideoSink::VideoSink(std::filesystem::path frames_dir, std::string prefix, std::filesystem::path out_dir,
                     int fps, std::string search_path, std::ostream& log)
    : frames_dir_(std::move(frames_dir)), out_dir_(std::move(out_dir)), prefix_(std::move(prefix)),
      search_path_(std::move(search_path)), fps_(fps), log_(log) {}

namespace {

// Runs argv without a shell (no quoting problems with odd directory names); true on exit 0.
bool run_program(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid;
  if (posix_spawn(&pid, argv[0], nullptr, nullptr, argv.data(), environ) != 0) return false;
  int status = 0;
  if (waitpid(pid, &status, 0) < 0) return false;
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

}  // namespace

void VideoSink::on_finish(const Simulation&, const io::RunRecord&) {
  const auto ffmpeg = find_on_path("ffmpeg", search_path_);
  if (!ffmpeg) {
    log_ << "papertear: ffmpeg is not on the PATH, so no video was made (the frames are in "
         << frames_dir_.string() << ")\n";
    return;
  }
  // Written under a temporary name and renamed, like every output: never a half video.
  // H.264 in yuv420p with the index at the front: what browsers play, as they download it.
  const std::filesystem::path video = out_dir_ / "video.mp4", partial = out_dir_ / ".video.mp4.partial";
  const bool ok = run_program({ffmpeg->string(), "-loglevel", "error", "-y", "-framerate", std::to_string(fps_),
                               "-i", (frames_dir_ / (prefix_ + "_%04d.png")).string(), "-vf",
                               "scale=trunc(iw/2)*2:trunc(ih/2)*2", "-c:v", "libx264", "-pix_fmt", "yuv420p",
                               "-movflags", "+faststart", "-f", "mp4", partial.string()});
  std::error_code ec;
  if (ok) std::filesystem::rename(partial, video, ec);
  if (!ok || ec) {
    std::filesystem::remove(partial, ec);
    log_ << "papertear: ffmpeg could not assemble the frames into a video; the frames are in "
         << frames_dir_.string() << "\n";
  }
}

}  // namespace papertear::render

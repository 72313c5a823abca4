#!/usr/bin/env bash
# Video client test: ffprobe_check.sh VIDEO FRAMES
# video.mp4 must be H.264 in yuv420p (what browsers play) with one video frame per frame of
# the run.
set -euo pipefail
video="$1" frames="$2"
read -r codec pix count < <(ffprobe -v error -select_streams v:0 -count_frames \
  -show_entries stream=codec_name,pix_fmt,nb_read_frames -of default=noprint_wrappers=1 "$video" |
  awk -F= '{v[$1]=$2} END {print v["codec_name"], v["pix_fmt"], v["nb_read_frames"]}')
echo "ffprobe_check: $video: codec $codec, pixels $pix, $count frames (want h264, yuv420p, $frames)"
[[ "$codec" == h264 && "$pix" == yuv420p && "$count" == "$frames" ]]

#!/usr/bin/env python3
"""swim animate on a short run: DIR/animation.mp4 is an H.264 video of fps x duration frames at
1280x720 (ffprobe counts the decoded frames), with a still DIR/animation.png; progress goes to
stderr; a directory without a run and bad options exit 2 without a video."""
import os
import subprocess
import sys

import swimtest
from swimtest import check


def animate(d, *args):
    return subprocess.run([swimtest.SWIM, "animate", d, *args], capture_output=True, text=True,
                          cwd=swimtest.ROOT)


def probe(path):
    p = subprocess.run(["ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0",
                        "-show_entries", "stream=codec_name,width,height,nb_read_frames",
                        "-of", "default=noprint_wrappers=1", path], capture_output=True, text=True)
    return dict(line.split("=", 1) for line in p.stdout.split() if "=" in line)


def test_short_run():
    p, rows, _ = swimtest.run("models/example3.toml", "anim", "--t-end", "1.5")
    d = os.path.join(swimtest.TMP, "anim")
    check(p.returncode == 0, "swim run failed: %s" % p.stderr)
    q = animate(d, "--fps", "10", "--duration", "1.2")
    check(q.returncode == 0, "swim animate failed (%d): %s" % (q.returncode, q.stderr[-500:]))
    mp4 = os.path.join(d, "animation.mp4")
    check(os.path.exists(mp4) and os.path.getsize(mp4) > 5000, "animation.mp4 missing or tiny")
    info = probe(mp4)
    check(info.get("codec_name") == "h264", "codec %s" % info.get("codec_name"))
    check(info.get("width") == "1280" and info.get("height") == "720",
          "frame size %sx%s" % (info.get("width"), info.get("height")))
    check(info.get("nb_read_frames") == "12", "frames %s, want 12 (10 fps x 1.2 s)"
          % info.get("nb_read_frames"))
    check("frame 12 / 12" in q.stderr, "no progress on stderr: %r" % q.stderr[-200:])
    png = os.path.join(d, "animation.png")
    check(os.path.exists(png) and os.path.getsize(png) > 5000, "animation.png missing or tiny")
    check(not [f for f in os.listdir(d) if "part" in f or f.startswith("frames-")],
          "temporary files left in %s: %s" % (d, os.listdir(d)))


def test_bad_input():
    d = os.path.join(swimtest.TMP, "anim_bad")
    os.makedirs(d, exist_ok=True)
    q = animate(d)
    check(q.returncode != 0 and not os.path.exists(os.path.join(d, "animation.mp4")),
          "animate of an empty directory: status %d" % q.returncode)
    for args, msg in ((["--fps", "0"], "--fps"), (["--duration", "x"], "--duration"),
                      (["--speed", "2"], "unknown option")):
        q = animate(d, *args)
        check(q.returncode == 2 and msg in q.stderr, "animate %s: %d %r" % (args, q.returncode, q.stderr))


if __name__ == "__main__":
    sys.exit(swimtest.main(globals(), "test_animate"))

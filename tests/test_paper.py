#!/usr/bin/env python3
"""The companion page in a real browser: build a reduced page (Examples 1 and 3, t_end = 4,
2-second animations) with the same builder as `make paper`, check its sections, then load it in
headless Chromium (tools/paper/browser_check.py): no console error, every image and video
loads with a non-zero size, nothing fetched from the network, a screenshot written
(build/paper-test/screenshot.png). The checker itself is checked on a broken copy of the page
(an empty image, a console error, a remote image), where it must report all three."""
import os
import re
import shutil
import subprocess
import sys

import swimtest
from swimtest import check

sys.path.insert(0, os.path.join(swimtest.ROOT, "tools", "paper"))
import browser_check  # noqa: E402

OUT = os.path.join(swimtest.ROOT, "build", "paper-test")


def test_1_page():
    env = dict(os.environ, SWIM_BIN=swimtest.SWIM)
    p = subprocess.run([os.environ.get("PYTHON", "/usr/bin/python3"),
                        os.path.join(swimtest.ROOT, "tools", "paper", "build_paper.py"),
                        "--scenes", "example1,example3", "--t-end", "4", "--duration", "2",
                        "--out", OUT], capture_output=True, text=True, env=env)
    check(p.returncode == 0, "build_paper failed: %s" % p.stderr[-800:])
    page = os.path.join(OUT, "index.html")
    with open(page) as fh:
        text = fh.read()
    ids = re.findall(r'<section id="fig([0-9.\-]+)"', text)
    # Fig. 4.8 needs the four instants; the reduced run (t_end 4) may miss one, so it is optional
    want = ["4.1", "4.2", "4.3", "4.4", "4.9", "4.10", "4.11", "4.12"]
    check(all(w in ids for w in want), "sections %s, want at least %s" % (ids, want))
    check(text.count("<video") == 2, "%d videos, want one per scene" % text.count("<video"))
    check("Work-precision" in text, "no work-precision section")
    check(not re.search(r'(src|href)="(https?:)?//', text), "the page links to the network")
    shot = os.path.join(OUT, "screenshot.png")
    if os.path.exists(shot):
        os.remove(shot)
    report = browser_check.check_page(page, shot, None, check)
    check(report is not None and len(report["images"]) >= 9 and len(report["videos"]) == 2,
          "browser saw %r" % ((report and (len(report["images"]), len(report["videos"]))),))
    check(os.path.exists(shot), "no screenshot")


def test_2_checker_catches_faults():
    src = os.path.join(OUT, "index.html")
    if not os.path.exists(src):
        check(False, "no page to break (test_1_page failed)")
        return
    bad = os.path.join(OUT, "broken.html")
    with open(src) as fh:
        text = fh.read()
    img = re.search(r'<img src="([^"]+)"', text).group(1)
    shutil.copy(os.path.join(OUT, img), os.path.join(OUT, "empty.png"))
    open(os.path.join(OUT, "empty.png"), "w").close()
    text = text.replace('<img src="%s"' % img, '<img src="empty.png"', 1)
    text = text.replace("</main>", "<script>console.error('planted')</script>"
                        '<img src="http://192.0.2.1/x.png"></main>')
    with open(bad, "w") as fh:
        fh.write(text)
    fails = []
    browser_check.check_page(bad, None, None, lambda ok, what: fails.append(what) if not ok else 0)
    joined = " | ".join(fails)
    check("empty.png" in joined, "empty image not reported: %s" % joined[:500])
    check("planted" in joined, "console error not reported: %s" % joined[:500])
    check("192.0.2.1" in joined, "remote image not reported: %s" % joined[:500])
    os.remove(bad)
    os.remove(os.path.join(OUT, "empty.png"))


if __name__ == "__main__":
    sys.exit(swimtest.main(globals(), "test_paper"))

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


def test_3_instants_from_events_csv():
    """The page takes Fig. 4.8's instants from DIR/events.csv (t,column,kind,value) when the run
    has one -- here a synthetic file -- and falls back to the rows only without it."""
    import build_paper
    d = os.path.join(swimtest.TMP, "ev3")
    p, rows, _ = swimtest.run("models/example3.toml", "ev3", "--t-end", "10")
    r = build_paper.SceneRun("example3", swimtest.TMP, {}, False)
    r.dir = d
    r.rows = rows
    r.events, r.events_source = [], None
    from_rows = build_paper.fig48_marks(r)
    check(from_rows is not None and max(abs(a - b) for a, b in
                                        zip(from_rows, [3.17, 3.95, 6.07, 9.50])) < 0.01,
          "Fig. 4.8 instants from the rows: %s" % from_rows)
    planted = [3.1701, 3.9502, 6.0703, 9.5004]
    with open(os.path.join(d, "events.csv"), "w") as fh:
        fh.write("t,column,kind,value\n")
        for t, (_, col, kind) in zip(planted, build_paper.FIG48):
            fh.write("%r,%s,%s,0\n" % (t, col, kind))
        fh.write("20.0,kinetic_rigid,max,0\n")
    r.events = build_paper.plot_run.read_events(os.path.join(d, "events.csv"))
    r.events_source = "events.csv"
    check(build_paper.fig48_marks(r) == planted, "instants not from events.csv: %s"
          % build_paper.fig48_marks(r))
    check(r.find_events("potential", "zero") == [],
          "with events.csv, a kind it lacks must not fall back to the rows")
    check(build_paper.strokes(r) is None, "strokes found without a_-1 events in events.csv")


if __name__ == "__main__":
    sys.exit(swimtest.main(globals(), "test_paper"))

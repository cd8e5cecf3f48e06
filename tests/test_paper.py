#!/usr/bin/env python3
"""The companion page in a real browser: build a reduced page (Examples 1 and 3, t_end = 4,
2-second animations, the prescribed stroke models/stroke_loop.toml, the family of Fig. 4.2
through its make target, 10 Example 1 members, and a quick work-precision measurement of
Examples 1 and 3) with the same builder as `make paper`, check its sections, then load it in
headless Chromium (tools/paper/browser_check.py): no console error, every image and video
loads with a non-zero size, nothing fetched from the network, the page's promises (every
figure section a numbers table with a difference column or the no-numbers statement, every
scene its section, models/hard/ listed), a screenshot written (build/paper-test/screenshot.png).
The checker itself is checked on broken copies of the page (an empty image, a console error, a
remote image; a figure section without numbers or statement, a scene section removed), where it
must report each."""
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
                        "--scenes", "example1,example3,stroke_loop", "--t-end", "4",
                        "--duration", "2", "--families", "fig-4-2", "--work-precision", "quick",
                        "--out", OUT],
                       capture_output=True, text=True, env=env)
    check(p.returncode == 0, "build_paper failed: %s" % p.stderr[-800:])
    page = os.path.join(OUT, "index.html")
    with open(page) as fh:
        text = fh.read()
    ids = re.findall(r'<section id="fig([0-9.\-]+)"', text)
    # Fig. 4.8 needs the four instants; the reduced run (t_end 4) may miss one, so it is optional
    want = ["4.1", "4.2", "4.3", "4.4", "4.9", "4.10", "4.11", "4.12"]
    check(all(w in ids for w in want), "sections %s, want at least %s" % (ids, want))
    check(text.count("<video") == 3, "%d videos, want one per scene" % text.count("<video"))
    check_family_section(text)
    check_instants_from_events(text)
    check_numbers_and_scenes(text)
    check("Work-precision" in text, "no work-precision section")
    check(not re.search(r'(src|href)="(https?:)?//', text), "the page links to the network")
    shot = os.path.join(OUT, "screenshot.png")
    if os.path.exists(shot):
        os.remove(shot)
    report = browser_check.check_page(page, shot, None, check)
    check(report is not None and len(report["images"]) >= 9 and len(report["videos"]) == 3,
          "browser saw %r" % ((report and (len(report["images"]), len(report["videos"]))),))
    check(os.path.exists(shot), "no screenshot")


def check_family_section(text):
    """Fig. 4.2 is the family's section: its figure from the sweep, the sweep's summary (members,
    RHS evaluations, time) matching members.csv, and a caption with the family's numbers."""
    import csv
    m = re.search(r'<section id="fig4\.2" class="paperfig">(.*?)</section>', text, re.S)
    check(m is not None, "no section for Fig. 4.2")
    if m is None:
        return
    sec = m.group(1)
    check('src="families/fig4_2/family.png"' in sec, "Fig. 4.2 does not show the family figure")
    check("<code>make fig-4-2</code>" in sec, "the make target is not named")
    check(re.search(r"<pre class=\"cmd\">[^<]*swim sweep models/example1.toml --out [^<]*fig4_2[^<]*"
                    r"--vary shape.dc0.bm2=[^<]*-0.707", sec) is not None,
          "the sweep's command is not shown whole")
    with open(os.path.join(OUT, "families", "fig4_2", "members.csv")) as fh:
        rows = list(csv.DictReader(fh))
    check(len(rows) == 10 and all(r["status"] == "completed" for r in rows),
          "the family's members: %d rows" % len(rows))
    rhs = sum(int(r["rhs_evaluations"]) for r in rows)
    check("<th>members</th><td>10 (10 completed, 0 failed)</td>" in sec, "members not summarised")
    check(("<td>%d in all," % rhs) in sec, "RHS evaluations %d not in the summary" % rhs)
    check(re.search(r"<th>sweep</th><td>[0-9.]+ s with \d+ jobs</td>", sec) is not None,
          "the sweep's time is missing")
    ys = sorted(float(r["y"]) for r in rows)
    cap = re.search(r"<figcaption>(.*?)</figcaption>", sec, re.S).group(1)
    check("y(30) runs from %.4g" % ys[0] in cap and "to %.4g" % ys[-1] in cap,
          "caption lacks the range of y(30) [%g, %g]: %s" % (ys[0], ys[-1], cap[:300]))
    check("0.5093" in cap, "caption lacks the displacement per period: %s" % cap[:400])
    check('<section id="fig4.1" class="paperfig">' in text and "families/fig4_1" not in text,
          "Fig. 4.1 without its family must fall back to the single run")


def check_instants_from_events(text):
    """Fig. 4.4's dashed instant is the first minimum of the rigid kinetic energy in the run's
    events.csv (value 0); the stroke period of Example 3 is summary.json's periodic entry."""
    import json
    ev = os.path.join(OUT, "runs", "example1", "events.csv")
    check(os.path.exists(ev), "swim run wrote no events.csv for Example 1")
    if not os.path.exists(ev):
        return
    with open(ev) as fh:
        rows = [ln.split(",") for ln in fh.read().split()[1:]]
    tk = [float(r[0]) for r in rows if r[1] == "kinetic_rigid" and r[2] == "min"
          and float(r[0]) > 1e-6]
    cap = re.search(r'<section id="fig4\.4" class="paperfig">.*?<figcaption>(.*?)</figcaption>', text, re.S)
    check(tk and cap and ("t† = %.8g" % tk[0]) in cap.group(1) and "events.csv" in cap.group(1),
          "Fig. 4.4's instant is not the first kinetic_rigid min of events.csv (%s): %s"
          % (tk[:1], cap and cap.group(1)[:300]))
    with open(os.path.join(OUT, "runs", "example3", "summary.json")) as fh:
        per = [p for p in json.load(fh).get("periodic", []) if p["column"] == "am1"]
    cap = re.search(r'<section id="fig4\.9" class="paperfig">.*?<figcaption>(.*?)</figcaption>', text, re.S)
    check(per and cap and ("period %.6g" % per[0]["period"]) in cap.group(1)
          and ("Δy = %.6g" % per[0]["displacement_per_period"]["y"]) in cap.group(1),
          "Fig. 4.9's caption lacks summary.json's stroke period: %s" % (cap and cap.group(1)))


def check_numbers_and_scenes(text):
    """Every figure section: the paper's caption quoted, then a numbers table (the paper, ours,
    difference) or the statement; Fig. 4.2's table carries the family's largest |y(30)|; the
    scene sections carry summary.json's numbers (the stroke's displacement per stroke); hard/
    listed; the work-precision figure regenerated now, at the page's width."""
    import csv
    import json
    secs = re.findall(r'<section id="(fig[^"]+)" class="paperfig">(.*?)</section>', text, re.S)
    check(len(secs) >= 8, "%d figure sections" % len(secs))
    for sid, body in secs:
        table = re.search(r'<table class="cmp"><tr><th>quantity</th><th>the paper</th>'
                          r'<th>ours</th><th>difference</th></tr>(.*?)</table>', body, re.S)
        stated = "The paper gives no numbers for this figure; compare by eye." in body or \
            "this shortened run does not reach them" in body
        check(bool(table) != stated, "%s: table %s, statement %s" % (sid, bool(table), stated))
        check('<p class="paper"><b>The paper, Fig.' in body, "%s: no paper caption" % sid)
        srcs = re.findall(r'<img src="([^"]+)"', body)
        made = [x for x in srcs if os.path.isfile(os.path.join(OUT, x))
                and os.path.getsize(os.path.join(OUT, x)) > 5000]
        check(bool(made), "%s: no figure image made (img %s)" % (sid, srcs))
    sec43 = dict(secs).get("fig4.3", "")
    check('src="runs/example1/fig4_3.png"' in sec43,
          "Fig. 4.3 does not show its screenshot panels: %s" % sec43[:300])
    no_numbers = [sid for sid, body in secs if "gives no numbers" in body]
    check("fig4.9" in no_numbers and "fig4.10" in no_numbers,
          "Figs 4.9, 4.10 (pictures only) lack the statement: %s" % no_numbers)
    sec42 = dict(secs).get("fig4.2", "")
    with open(os.path.join(OUT, "families", "fig4_2", "members.csv")) as fh:
        big = max(abs(float(r["y"])) for r in csv.DictReader(fh))
    check(("<td>%.4g</td>" % big) in sec42 and "inside" in sec42,
          "Fig. 4.2's table lacks the largest |y(30)| %.4g" % big)
    sec44 = dict(secs).get("fig4.4", "")
    check("<td>rigid kinetic energy at t†</td><td>0 (rigid velocity null)</td>" in sec44,
          "Fig. 4.4's table lacks the rigid kinetic energy at t†")
    for name in ("example1", "example3", "stroke_loop"):
        m = re.search(r'<section id="scene-%s" class="scene">(.*?)</section>' % name, text, re.S)
        check(m is not None, "no section for scene %s" % name)
    m = re.search(r'<section id="scene-stroke_loop" class="scene">(.*?)</section>', text, re.S)
    if m:
        with open(os.path.join(OUT, "runs", "stroke_loop", "summary.json")) as fh:
            sk = json.load(fh)["stroke"]
        check("Not one of the paper" in m.group(1) and "stroke.png" in m.group(1),
              "stroke_loop's section lacks its note or stroke figure")
        if sk["strokes"]:
            check(("%.6g" % sk["strokes"][0]["dy"]) in m.group(1),
                  "stroke_loop's section lacks summary.json's displacement per stroke")
    hard = sorted(f[:-5] for f in os.listdir(os.path.join(swimtest.ROOT, "models", "hard"))
                  if f.endswith(".toml"))
    check(all('<tr id="scene-hard-%s">' % h in text for h in hard), "models/hard/ not all listed")
    png = os.path.join(OUT, "work_precision", "work_precision.png")
    check(os.path.exists(png) and os.path.exists(os.path.join(OUT, "work_precision",
                                                              "accuracy.csv")),
          "the work-precision figure was not measured and drawn for the page")
    if os.path.exists(png):
        import matplotlib.image
        w = matplotlib.image.imread(png).shape[1]
        check(w == 1100, "work-precision figure %d px wide, want the page's 1100" % w)
        check("quick measurement made for this page" in text, "work-precision source not said")


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
    # the page's promises: a figure section stripped of its numbers, a scene section removed
    with open(src) as fh:
        text = fh.read()
    text = re.sub(r'(<section id="fig4\.9" class="paperfig">.*?)<p class="nonumbers">.*?</p>',
                  r"\1", text, count=1, flags=re.S)
    text = re.sub(r'(<section id="fig4\.4" class="paperfig">.*?)<table class="cmp">.*?</table>',
                  r"\1", text, count=1, flags=re.S)
    text = re.sub(r'<section id="scene-stroke_loop" class="scene">.*?</section>', "", text,
                  count=1, flags=re.S)
    text = text.replace('<tr id="scene-hard-stiff_n7">', '<tr id="x">')
    text = re.sub(r'(<section id="fig4\.3" class="paperfig">.*?)<figure><img [^>]*></figure>',
                  r"\1", text, count=1, flags=re.S)
    with open(bad, "w") as fh:
        fh.write(text)
    fails = []
    browser_check.check_page(bad, None, None, lambda ok, what: fails.append(what) if not ok else 0)
    joined = " | ".join(fails)
    check("Fig. 4.9" in joined and "no-numbers statement" in joined,
          "a figure section without numbers not reported: %s" % joined[:600])
    check("Fig. 4.4 —" in joined and "tables []" in joined,
          "Fig. 4.4 without its table not reported: %s" % joined[:600])
    check("stroke_loop.toml has no section" in joined, "a missing scene section not reported: %s"
          % joined[:600])
    check("Fig. 4.3 —" in joined and "promises a figure" in joined,
          "Fig. 4.3 without its image not reported: %s" % joined[:600])
    check("hard/stiff_n7.toml is not listed" in joined, "an unlisted hard scene not reported: %s"
          % joined[:600])
    os.remove(bad)


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


def test_4_missing_image_recorded():
    """A figure section's image that was not made (absent or empty) is recorded, so that
    build_paper fails instead of dropping it from the page."""
    import build_paper
    d = os.path.join(swimtest.TMP, "promised")
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, "made.png"), "wb") as fh:
        fh.write(b"x" * 100)
    open(os.path.join(d, "empty.png"), "w").close()
    missing = []
    got = build_paper.promised_images(d, "runs/x", ["made.png", "empty.png", "absent.png"],
                                      "Fig. 9.9", missing)
    check(got == ["runs/x/made.png"], "images kept: %s" % got)
    check(len(missing) == 2 and all(m.startswith("Fig. 9.9: ") for m in missing)
          and "empty.png" in missing[0] and "absent.png" in missing[1],
          "missing images recorded: %s" % missing)


if __name__ == "__main__":
    sys.exit(swimtest.main(globals(), "test_paper"))

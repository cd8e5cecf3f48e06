#!/usr/bin/env python3
"""Load a static page in headless Chromium and check it as a reader's browser would.

Usage: browser_check.py PAGE.html [--screenshot FILE] [--chromium PATH]

Drives Chromium through the DevTools protocol (a small WebSocket client on the standard
library: no Node, no Python packages). Checks, each printed as a FAIL line when it fails:
  * no console error, no uncaught exception, no log entry of level error (a resource that fails
    to load is one);
  * every <img> decodes with a non-zero natural size; every <video> loads its metadata and has a
    non-zero frame size and duration;
  * no request leaves the machine (only file: and data: URLs);
  * every relative link and source names a non-empty file;
  * the companion page keeps its promises (when the page says it is one, <meta name="swim-page">):
    every paper-figure section (class paperfig) quotes the paper's caption and has either a
    numbers table (table.cmp: quantity, the paper, ours, difference, every row filled) or the
    statement "The paper gives no numbers for this figure; compare by eye.", and shows at
    least one loaded image of non-trivial size (both sides >= MIN_FIGURE_PX); every scene of
    models/*.toml and models/control/*.toml has its section (id scene-NAME, with the key numbers
    of its summary.json and a video) -- on a reduced page (--scenes) every scene the page names
    in <meta name="swim-scenes">, and only scenes of models/; every models/hard/*.toml has its row
    in the section scenes-hard; the work-precision section shows its figure (a reduced page
    may leave the section out).
Then writes a screenshot of the top of the page at a laptop width (1366 px).
Last line: "browser_check: P passed, F failed"; exit status 1 if any failed, 2 on bad use.
"""
import base64
import html.parser
import json
import os
import shutil
import socket
import struct
import subprocess
import sys
import tempfile
import time
import urllib.parse
import urllib.request

WIDTH, HEIGHT = 1366, 850
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
         "--disable-component-update", "--disable-sync", "--no-first-run",
         "--disable-default-apps", "--mute-audio", "--autoplay-policy=no-user-gesture-required"]


class WebSocket:
    """Just enough of RFC 6455 for a DevTools session: text frames, client masking."""

    def __init__(self, url, timeout=60):
        u = urllib.parse.urlparse(url)
        self.sock = socket.create_connection((u.hostname, u.port), timeout=timeout)
        key = base64.b64encode(os.urandom(16)).decode()
        req = ("GET %s HTTP/1.1\r\nHost: %s:%d\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
               "Sec-WebSocket-Key: %s\r\nSec-WebSocket-Version: 13\r\n\r\n"
               % (u.path, u.hostname, u.port, key))
        self.sock.sendall(req.encode())
        head = b""
        while b"\r\n\r\n" not in head:
            chunk = self.sock.recv(4096)
            if not chunk:
                raise ConnectionError("DevTools closed the connection during the handshake")
            head += chunk
        head, self.buf = head.split(b"\r\n\r\n", 1)
        if b" 101 " not in head.split(b"\r\n")[0]:
            raise ConnectionError("WebSocket handshake refused: %r" % head[:200])

    def send(self, text):
        data = text.encode()
        n = len(data)
        hdr = bytes([0x81])
        if n < 126:
            hdr += bytes([0x80 | n])
        elif n < 65536:
            hdr += bytes([0x80 | 126]) + struct.pack(">H", n)
        else:
            hdr += bytes([0x80 | 127]) + struct.pack(">Q", n)
        mask = os.urandom(4)
        self.sock.sendall(hdr + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(data)))

    def _read(self, n):
        while len(self.buf) < n:
            chunk = self.sock.recv(1 << 20)
            if not chunk:
                raise ConnectionError("DevTools closed the connection")
            self.buf += chunk
        out, self.buf = self.buf[:n], self.buf[n:]
        return out

    def recv(self):
        message = b""
        while True:
            b0, b1 = self._read(2)
            n = b1 & 0x7F
            if n == 126:
                n = struct.unpack(">H", self._read(2))[0]
            elif n == 127:
                n = struct.unpack(">Q", self._read(8))[0]
            payload = self._read(n)
            op = b0 & 0x0F
            if op == 8:
                raise ConnectionError("DevTools closed the WebSocket")
            if op in (0, 1, 2):
                message += payload
                if b0 & 0x80:
                    return message.decode("utf-8", "replace")
            # ping/pong frames are ignored (DevTools does not send pings)


class DevTools:
    def __init__(self, ws):
        self.ws = ws
        self.next_id = 0
        self.events = []

    def call(self, method, timeout=60, **params):
        self.next_id += 1
        mid = self.next_id
        self.ws.send(json.dumps({"id": mid, "method": method, "params": params}))
        end = time.time() + timeout
        while time.time() < end:
            msg = json.loads(self.ws.recv())
            if msg.get("id") == mid:
                if "error" in msg:
                    raise RuntimeError("%s: %s" % (method, msg["error"]))
                return msg.get("result", {})
            if "method" in msg:
                self.events.append(msg)
        raise TimeoutError(method)

    def wait_event(self, name, timeout=60):
        end = time.time() + timeout
        for e in self.events:
            if e["method"] == name:
                return e
        while time.time() < end:
            msg = json.loads(self.ws.recv())
            if "method" in msg:
                self.events.append(msg)
                if msg["method"] == name:
                    return msg
        raise TimeoutError(name)


class Links(html.parser.HTMLParser):
    def __init__(self):
        super().__init__()
        self.urls = []

    def handle_starttag(self, tag, attrs):
        for k, v in attrs:
            if k in ("src", "href") and v:
                self.urls.append((tag, k, v))


# Runs in the page: waits for every image and video, then reports their sizes.
CHECK_JS = r"""
(async () => {
  const wait = (el, ok, bad, ms) => new Promise(res => {
    const t = setTimeout(() => res('timeout'), ms);
    el.addEventListener(ok, () => { clearTimeout(t); res('ok'); }, {once: true});
    el.addEventListener(bad, () => { clearTimeout(t); res('error'); }, {once: true});
  });
  const imgs = [...document.images];
  await Promise.all(imgs.map(im => {
    if (im.complete) return 'ok';
    im.loading = 'eager';
    return wait(im, 'load', 'error', 30000);
  }));
  const vids = [...document.querySelectorAll('video')];
  await Promise.all(vids.map(v => {
    if (v.readyState >= 1) return 'ok';
    const p = wait(v, 'loadedmetadata', 'error', 30000);
    v.preload = 'metadata'; v.load();
    return p;
  }));
  return JSON.stringify({
    images: imgs.map(im => ({src: im.getAttribute('src'), w: im.naturalWidth, h: im.naturalHeight})),
    videos: vids.map(v => ({src: v.getAttribute('src'), w: v.videoWidth, h: v.videoHeight,
                            duration: v.duration, error: v.error ? v.error.code : 0})),
    height: document.documentElement.scrollHeight, title: document.title,
    meta: Object.fromEntries([...document.querySelectorAll('meta[name]')].map(
      m => [m.getAttribute('name'), m.getAttribute('content')])),
    sections: [...document.querySelectorAll('section')].map(sec => ({
      id: sec.id, cls: sec.className,
      h2: (sec.querySelector('h2') || {}).textContent || '',
      paper: [...sec.querySelectorAll('.paper')].map(p => p.textContent.trim()),
      tables: [...sec.querySelectorAll('table.cmp')].map(t => ({
        head: [...t.querySelectorAll('tr:first-child th')].map(h => h.textContent.trim()),
        rows: [...t.querySelectorAll('tr')].slice(1).map(
          tr => [...tr.querySelectorAll('td')].map(td => td.textContent.trim()))})),
      nonumbers: [...sec.querySelectorAll('.nonumbers')].map(p => p.textContent.trim()),
      keys: sec.querySelectorAll('table.keys tr').length,
      videos: sec.querySelectorAll('video').length,
      images: sec.querySelectorAll('img').length,
      sizes: [...sec.querySelectorAll('img')].map(im => [im.naturalWidth, im.naturalHeight]),
      rows: [...sec.querySelectorAll('tr[id]')].map(tr => tr.id)}))});
})()
"""


ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
# a figure worth the name: a decoded image at least this many pixels on each side (an empty or
# placeholder PNG is smaller)
MIN_FIGURE_PX = 100
NO_NUMBERS = "The paper gives no numbers for this figure; compare by eye."
SHORTENED = "The paper gives numbers for this figure, but this shortened run does not reach them"


def models_scenes(models, folder):
    d = os.path.join(models, folder)
    if not os.path.isdir(d):
        return []
    return sorted((folder + "/" if folder else "") + f[:-5] for f in os.listdir(d)
                  if f.endswith(".toml"))


def check_promises(report, check, models=None):
    """The companion page's own promises, on what the browser shows (see the module doc)."""
    meta = report.get("meta", {})
    kind = meta.get("swim-page")
    if kind is None:
        return                      # not a companion page: nothing promised
    models = models or os.path.join(ROOT, "models")
    secs = report.get("sections", [])
    by_id = {s["id"]: s for s in secs}
    figs = [s for s in secs if "paperfig" in s["cls"].split()]
    check(len(figs) > 0, "no paper-figure section")
    for s in figs:
        what = s["h2"][:40] or s["id"]
        check(any(p.startswith("The paper, Fig.") and len(p) > 40 for p in s["paper"]),
              "%s: no quote of the paper's caption" % what)
        good_tables = [t for t in s["tables"]
                       if [h.lower() for h in t["head"]] == ["quantity", "the paper", "ours",
                                                             "difference"]
                       and t["rows"] and all(len(r) == 4 and all(r) for r in t["rows"])]
        stated = [n for n in s["nonumbers"] if n.startswith(NO_NUMBERS) or
                  (kind == "reduced" and n.startswith(SHORTENED))]
        big = [wh for wh in s.get("sizes", []) if min(wh) >= MIN_FIGURE_PX]
        check(bool(big), "%s: promises a figure but shows no loaded image of at least %d px "
              "(images %s)" % (what, MIN_FIGURE_PX, s.get("sizes")))
        check(bool(good_tables) != bool(stated),
              "%s: wants a numbers table with a difference column or the no-numbers statement "
              "(tables %s, statements %s)" % (what, s["tables"], s["nonumbers"]))
    on_page = [x for x in (meta.get("swim-scenes") or "").split(",") if x]
    expected = models_scenes(models, "") + models_scenes(models, "control")
    want = expected if kind == "full" else on_page
    check(kind == "full" or all(n in expected for n in on_page),
          "the page names scenes not in models/: %s" % [n for n in on_page if n not in expected])
    check(kind != "full" or sorted(on_page) == sorted(expected),
          "a full page must run every scene of models/ and models/control/: missing %s"
          % [n for n in expected if n not in on_page])
    for n in want:
        s = by_id.get("scene-" + n.replace("/", "-"))
        check(s is not None, "scene models/%s.toml has no section" % n)
        if s is not None:
            check(s["keys"] >= 8 and s["videos"] == 1 and s["images"] >= 1,
                  "scene %s: section without its key numbers (%d rows), video (%d) or figure (%d)"
                  % (n, s["keys"], s["videos"], s["images"]))
    hard = models_scenes(models, "hard")
    rows = (by_id.get("scenes-hard") or {}).get("rows", [])
    for n in hard:
        check("scene-" + n.replace("/", "-") in rows, "models/%s.toml is not listed" % n)
    wp = by_id.get("work-precision")
    if kind == "full" or wp is not None:    # a reduced page may leave it out (--work-precision none)
        check(wp is not None and wp["images"] == 1, "no work-precision figure")


def start_chromium(exe, profile):
    proc = subprocess.Popen([exe] + FLAGS + ["--user-data-dir=" + profile,
                                             "--remote-debugging-port=0",
                                             "--window-size=%d,%d" % (WIDTH, HEIGHT),
                                             "about:blank"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    port_file = os.path.join(profile, "DevToolsActivePort")
    end = time.time() + 60
    while time.time() < end:
        if os.path.exists(port_file):
            with open(port_file) as fh:
                lines = fh.read().split()
            if lines:
                return proc, int(lines[0])
        if proc.poll() is not None:
            raise RuntimeError("chromium exited (status %d): %s" % (
                proc.returncode, proc.stderr.read().decode(errors="replace")[-500:]))
        time.sleep(0.1)
    proc.kill()
    raise RuntimeError("chromium did not open its DevTools port within 60 s")


def check_page(page, screenshot=None, chromium=None, check=None):
    """Runs the checks; `check(cond, what)` counts them. Returns the in-page report."""
    page = os.path.abspath(page)
    exe = chromium or shutil.which("chromium") or "/usr/bin/chromium"
    # static links: relative, non-empty files, nothing remote
    parser = Links()
    with open(page, encoding="utf-8") as fh:
        parser.feed(fh.read())
    base = os.path.dirname(page)
    for tag, attr, url in parser.urls:
        if url.startswith("#"):
            continue
        u = urllib.parse.urlparse(url)
        check(not u.scheme and not u.netloc, "%s %s=%s is not a relative link" % (tag, attr, url))
        if not u.scheme:
            path = os.path.join(base, urllib.parse.unquote(u.path))
            check(os.path.isfile(path) and os.path.getsize(path) > 0,
                  "%s %s=%s: missing or empty file" % (tag, attr, url))
    profile = tempfile.mkdtemp(prefix="chromium-profile-")
    proc = None
    try:
        proc, port = start_chromium(exe, profile)
        with urllib.request.urlopen("http://127.0.0.1:%d/json/list" % port, timeout=30) as r:
            targets = json.load(r)
        target = next(t for t in targets if t.get("type") == "page")
        dt = DevTools(WebSocket(target["webSocketDebuggerUrl"]))
        for domain in ("Page", "Runtime", "Log", "Network"):
            dt.call(domain + ".enable")
        dt.call("Emulation.setDeviceMetricsOverride", width=WIDTH, height=HEIGHT,
                deviceScaleFactor=1, mobile=False)
        dt.call("Page.navigate", url="file://" + urllib.parse.quote(page))
        dt.wait_event("Page.loadEventFired", timeout=120)
        res = dt.call("Runtime.evaluate", timeout=120, expression=CHECK_JS, awaitPromise=True,
                      returnByValue=True)
        if "exceptionDetails" in res:
            check(False, "page check script failed: %s" % res["exceptionDetails"])
            return None
        report = json.loads(res["result"]["value"])
        for im in report["images"]:
            check(im["w"] > 0 and im["h"] > 0, "image %s did not load (%dx%d)" % (
                im["src"], im["w"], im["h"]))
        for v in report["videos"]:
            check(v["w"] > 0 and v["h"] > 0 and (v["duration"] or 0) > 0 and not v["error"],
                  "video %s did not load (%sx%s, duration %s, error %s)" % (
                      v["src"], v["w"], v["h"], v["duration"], v["error"]))
        check_promises(report, check)
        time.sleep(0.5)   # let late console messages arrive
        dt.call("Runtime.evaluate", expression="1")
        errors = []
        for e in dt.events:
            m, p = e["method"], e.get("params", {})
            if m == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
                errors.append("console.%s: %s" % (p["type"], [a.get("value") for a in p.get("args", [])]))
            elif m == "Runtime.exceptionThrown":
                errors.append("exception: %s" % p.get("exceptionDetails", {}).get("text"))
            elif m == "Log.entryAdded" and p.get("entry", {}).get("level") == "error":
                errors.append("log: %s %s" % (p["entry"].get("text"), p["entry"].get("url", "")))
            elif m == "Network.requestWillBeSent":
                url = p.get("request", {}).get("url", "")
                check(url.startswith(("file:", "data:", "about:")),
                      "request leaves the machine: %s" % url)
        check(not errors, "console errors: %s" % "; ".join(errors)[:1000])
        if screenshot:
            shot = dt.call("Page.captureScreenshot", timeout=120, format="png",
                           captureBeyondViewport=True,
                           clip={"x": 0, "y": 0, "width": WIDTH,
                                 "height": min(report["height"], 2400), "scale": 1})
            with open(screenshot, "wb") as fh:
                fh.write(base64.b64decode(shot["data"]))
            check(os.path.getsize(screenshot) > 10000, "screenshot %s is (nearly) empty" % screenshot)
        return report
    finally:
        if proc is not None:
            proc.terminate()
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                proc.kill()
        shutil.rmtree(profile, ignore_errors=True)


def main(argv):
    page, shot, exe = None, None, None
    i = 0
    while i < len(argv):
        if argv[i] == "--screenshot" and i + 1 < len(argv):
            shot = argv[i + 1]
            i += 2
        elif argv[i] == "--chromium" and i + 1 < len(argv):
            exe = argv[i + 1]
            i += 2
        elif page is None and not argv[i].startswith("--"):
            page = argv[i]
            i += 1
        else:
            print(__doc__.strip(), file=sys.stderr)
            return 2
    if page is None or not os.path.isfile(page):
        print("browser_check: no page to check (%s)" % page, file=sys.stderr)
        return 2
    counts = [0, 0]

    def check(cond, what):
        counts[0 if cond else 1] += 1
        if not cond:
            print("FAIL:", what)

    try:
        report = check_page(page, shot, exe, check)
        if report:
            print("browser_check: %d images, %d videos, page height %d px%s" % (
                len(report["images"]), len(report["videos"]), report["height"],
                (", screenshot " + shot) if shot else ""))
    except Exception as e:  # noqa: BLE001 - any failure to drive the browser is a failed check
        check(False, "browser: %s: %s" % (type(e).__name__, e))
    print("browser_check: %d passed, %d failed" % tuple(counts))
    return 1 if counts[1] else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

#!/usr/bin/env python3
"""Outputs named by the user that are not regular files: a device node, a FIFO, a full device,
a folder. `swim flow --out` and `swim animate --out` must write a device or FIFO in place (it
stays what it was), report a write error on a full device with exit 1, and refuse a folder or a
missing folder with exit 2 before any work. The device nodes are the test's own (mknod of the
null and full devices in a temporary folder, root only), never /dev/null itself, so that a
build which renames over its target cannot damage the machine. Prints
"test_trust_devices: P passed, F failed".
"""

import os
import shutil
import stat
import subprocess
import sys
import threading

from swimtest import ROOT, SWIM, TMP, check, main

IS_ROOT = os.geteuid() == 0
_run = {}


def run_dir():
    if "dir" not in _run:
        out = os.path.join(TMP, "run")
        p = subprocess.run([SWIM, "run", "models/example3.toml", "--out", out, "--t-end", "1", "--quiet"],
                           capture_output=True, text=True, cwd=ROOT)
        check(p.returncode == 0, "the run for the outputs: exit %d %s" % (p.returncode, p.stderr))
        _run["dir"] = out
    return _run["dir"]


def device(name, minor):
    """A character device of the memory driver (1, minor): 3 is null, 7 is full. None if not root."""
    if not IS_ROOT:
        return None
    path = os.path.join(TMP, name)
    if os.path.lexists(path):
        os.remove(path)
    os.mknod(path, 0o666 | stat.S_IFCHR, os.makedev(1, minor))
    return path


def is_char_device(path):
    return os.path.lexists(path) and stat.S_ISCHR(os.lstat(path).st_mode)


def command(kind, target):
    if kind == "flow":
        return [SWIM, "flow", run_dir(), "--frames", "2", "--out", target]
    return [SWIM, "animate", run_dir(), "--duration", "0.4", "--fps", "5", "--out", target]


def kinds():
    return ["flow"] + (["animate"] if shutil.which("ffmpeg") else [])


def test_null_device_stays_a_device():
    for kind in kinds():
        null = device("null-" + kind, 3)
        if null is None:
            print("skipped: device nodes need root (mknod)")
            return
        p = subprocess.run(command(kind, null), capture_output=True, text=True, cwd=ROOT)
        check(p.returncode == 0, "%s --out DEVICE: exit %d %s" % (kind, p.returncode, p.stderr))
        check(is_char_device(null), "%s --out DEVICE: the device node was replaced by a regular file" % kind)
        poster = os.path.splitext(null)[0] + ".png"
        check(not os.path.exists(null + ".png") and not (kind == "animate" and os.path.exists(poster)
                                                          and poster != null),
              "%s --out DEVICE: a poster file was made beside the device" % kind)
        check(not [f for f in os.listdir(TMP) if ".part" in f], "%s --out DEVICE: a .part file was left" % kind)


def test_full_device_is_a_write_error():
    for kind in kinds():
        full = device("full-" + kind, 7)
        if full is None:
            return
        p = subprocess.run(command(kind, full), capture_output=True, text=True, cwd=ROOT)
        check(p.returncode == 1 and "No space left" in p.stderr and full in p.stderr,
              "%s --out FULL DEVICE: exit %d, want 1 naming it: %s" % (kind, p.returncode, p.stderr))
        check(is_char_device(full), "%s --out FULL DEVICE: the device node was replaced" % kind)


def test_fifo_is_written_in_place():
    """A FIFO (mkfifo, no root needed): the reader gets the whole output, the FIFO stays one."""
    for kind in kinds():
        fifo = os.path.join(TMP, "fifo-" + kind)
        if os.path.lexists(fifo):
            os.remove(fifo)
        os.mkfifo(fifo)
        got = {}

        def reader():
            with open(fifo, "rb") as fh:
                got["data"] = fh.read()
        th = threading.Thread(target=reader, daemon=True)
        th.start()
        p = subprocess.run(command(kind, fifo), capture_output=True, text=True, cwd=ROOT, timeout=120)
        if th.is_alive():            # nothing opened the FIFO: release the reader
            with open(fifo, "wb"):
                pass
        th.join(10)
        check(p.returncode == 0, "%s --out FIFO: exit %d %s" % (kind, p.returncode, p.stderr))
        check(stat.S_ISFIFO(os.lstat(fifo).st_mode), "%s --out FIFO: the FIFO was replaced by a regular file" % kind)
        data = got.get("data", b"")
        whole = data.startswith(b"[") and data.rstrip().endswith(b"]") if kind == "flow" else b"ftyp" in data[:16]
        check(whole, "%s --out FIFO: the reader got %d bytes, not the whole output" % (kind, len(data)))


def test_folder_or_missing_folder_refused_before_work():
    for kind in kinds():
        for target, what in ((TMP, "a folder"), (os.path.join(TMP, "no", "such", "x.out"), "a missing folder")):
            p = subprocess.run(command(kind, target), capture_output=True, text=True, cwd=ROOT)
            check(p.returncode == 2 and target in p.stderr and "computing" not in p.stderr,
                  "%s --out %s: exit %d, want 2 before any work: %s" % (kind, what, p.returncode, p.stderr))


def test_regular_file_still_replaced_whole():
    out = os.path.join(TMP, "snap.json")
    with open(out, "w") as fh:
        fh.write("old")
    p = subprocess.run(command("flow", out), capture_output=True, text=True, cwd=ROOT)
    with open(out) as fh:
        text = fh.read()
    check(p.returncode == 0 and text.startswith("[") and text.rstrip().endswith("]"),
          "flow --out FILE: exit %d, file starts %r" % (p.returncode, text[:20]))
    check(stat.S_ISREG(os.lstat(out).st_mode), "flow --out FILE: not a regular file afterwards")


if __name__ == "__main__":
    sys.exit(main(globals(), "test_trust_devices"))

#!/usr/bin/env python3
"""The kernel cache as a hostile local user, a careless admin and an impatient user meet it.

A cached kernel.so is code that swim runs, so these tests plant one whose constructor leaves a
marker file, in every place another user could prepare (a fixed folder under /tmp when HOME is
unset, a cache folder that belongs to someone else or that everyone can write, an entry file of
another owner, a symbolic link), with a manifest that matches it, and check that it never runs.
They also overwrite a kernel.so in place while a run uses it, interrupt a kernel's generation,
and use a cache that cannot be written. Ownership by another user needs root (chown); those
cases say "skipped" elsewhere. Prints "test_trust_cache: P passed, F failed".
"""

import glob
import os
import shutil
import signal
import subprocess
import sys
import time

from swimtest import ROOT, SWIM, TMP, check, main

SCENE = os.path.join(ROOT, "models", "example3.toml")
NOBODY = 65534
IS_ROOT = os.geteuid() == 0
PLANT_C = r"""
#include <stdio.h>
#include <stdlib.h>
__attribute__((constructor)) static void planted(void)
{
    const char *p = getenv("SWIM_TEST_MARKER");
    FILE *f = p ? fopen(p, "w") : NULL;
    if (f) { fputs("planted code ran\n", f); fclose(f); }
}
"""


def fnv1a(data):
    h = 1469598103934665603
    for b in data:
        h ^= b
        h = (h * 1099511628211) & 0xFFFFFFFFFFFFFFFF
    return h


def env_with(**kw):
    env = {k: v for k, v in os.environ.items() if k not in ("SWIM_CACHE", "XDG_CACHE_HOME", "HOME")}
    env.update({k: v for k, v in kw.items() if v is not None})
    return env


def swim_run(name, env, *extra):
    out = os.path.join(TMP, name)
    return subprocess.run([SWIM, "run", SCENE, "--out", out, "--quiet", "--t-end", "0.5", *extra],
                          capture_output=True, text=True, cwd=ROOT, env=env), out


_legit = {}


def legit_entry():
    """A sound cache entry of example3's scene kernel (built once): its folder."""
    if "dir" not in _legit:
        cache = os.path.join(TMP, "legit-cache")
        p, _ = swim_run("legit", env_with(SWIM_CACHE=cache, HOME=os.environ.get("HOME")))
        entries = [d for d in glob.glob(os.path.join(cache, "*")) if os.path.exists(os.path.join(d, "manifest"))]
        check(p.returncode == 0 and len(entries) == 1, "legit entry: exit %d, %d entries" % (p.returncode, len(entries)))
        _legit["dir"] = entries[0] if entries else None
    return _legit["dir"]


def planted_so():
    path = os.path.join(TMP, "planted.so")
    if not os.path.exists(path):
        src = os.path.join(TMP, "planted.c")
        with open(src, "w") as fh:
            fh.write(PLANT_C)
        subprocess.run(["cc", "-shared", "-fPIC", "-o", path, src], check=True)
    return path


def plant(root, owner=None, mode=None):
    """Copies the legit entry under `root` with a planted kernel.so and a manifest that matches
    it; chowns the copy to `owner` and chmods the root to `mode` when given. The entry folder."""
    src = legit_entry()
    dst = os.path.join(root, os.path.basename(src))
    shutil.rmtree(root, ignore_errors=True)
    os.makedirs(dst)
    for f in ("kernel.c", "structure.json"):
        shutil.copy(os.path.join(src, f), dst)
    so = open(planted_so(), "rb").read()
    with open(os.path.join(dst, "kernel.so"), "wb") as fh:
        fh.write(so)
    lines = open(os.path.join(src, "manifest")).read().split("\n")
    lines[2] = "so %d %016x" % (len(so), fnv1a(so))
    with open(os.path.join(dst, "manifest"), "w") as fh:
        fh.write("\n".join(lines))
    if owner is not None:
        for d, _, files in os.walk(root):
            os.chown(d, owner, owner)
            for f in files:
                os.chown(os.path.join(d, f), owner, owner)
    if mode is not None:
        os.chmod(root, mode)
    return dst


def marker(name):
    path = os.path.join(TMP, "marker-" + name)
    if os.path.exists(path):
        os.remove(path)
    return path


def private_leftovers(tmpdir):
    """Private folders left in the run's own TMPDIR. /tmp is not looked at: other test programs
    running beside this one make (and remove) private folders there, so a folder in /tmp is not
    evidence against this run; the fixed folders a careless fallback would use are planted and
    checked by the callers instead."""
    return glob.glob(os.path.join(tmpdir, "swim-cache-*"))


def fresh_tmpdir(name):
    d = os.path.join(TMP, "tmpdir-" + name)
    os.makedirs(d, exist_ok=True)
    return d


# ---- code from someone else's folder ----------------------------------------------------------

def test_planted_entry_is_loaded_when_trusted():
    """The control: the planted entry does run when it sits in a cache of one's own. Without it
    the tests below could pass because the plant was wrong."""
    root = os.path.join(TMP, "own-cache")
    plant(root)
    m = marker("own")
    p, _ = swim_run("own", env_with(SWIM_CACHE=root, SWIM_TEST_MARKER=m))
    check(os.path.exists(m), "control: the planted kernel.so in one's own cache was not loaded "
                             "(the plant is wrong, so the other cases prove nothing): " + p.stderr)


def test_home_unset_uses_no_fixed_shared_folder():
    """HOME unset: the cache is the user's home folder from the password database, never a fixed
    folder under /tmp that another user could have made first."""
    planted = [] if os.path.exists("/tmp/.cache") else ["/tmp/.cache"]
    for root in ("/tmp/.cache/swim", "/tmp/swim", "/tmp/swim-cache"):
        if not os.path.exists(root):
            plant(root, owner=NOBODY if IS_ROOT else None)
            planted.append(root)
    m = marker("nohome")
    tmpdir = fresh_tmpdir("nohome")
    try:
        p, out = swim_run("nohome", env_with(SWIM_TEST_MARKER=m, TMPDIR=tmpdir))
        check(p.returncode == 0, "HOME unset: exit %d: %s" % (p.returncode, p.stderr))
        check(not os.path.exists(m), "HOME unset: a kernel.so planted under /tmp was loaded")
        check(not private_leftovers(tmpdir), "HOME unset: a private folder was left behind")
    finally:
        for root in planted:
            shutil.rmtree(root, ignore_errors=True)


def test_cache_of_another_user():
    if not IS_ROOT:
        print("skipped: a cache folder of another user needs root (chown)")
        return
    root = os.path.join(TMP, "other-cache")
    plant(root, owner=NOBODY)
    m = marker("other")
    tmpdir = fresh_tmpdir("other")
    p, out = swim_run("other", env_with(SWIM_CACHE=root, SWIM_TEST_MARKER=m, TMPDIR=tmpdir))
    check(not os.path.exists(m), "a kernel.so in another user's cache folder was loaded")
    check(p.returncode == 0 and os.path.exists(os.path.join(out, "summary.json")),
          "another user's cache: the run should still complete (private kernels): exit %d %s" % (p.returncode, p.stderr))
    check("another user" in p.stderr and root in p.stderr, "another user's cache: stderr should say why it is not used: " + p.stderr)
    check(not private_leftovers(tmpdir), "another user's cache: the private folder was left behind")


def test_cache_everyone_can_write():
    root = os.path.join(TMP, "open-cache")
    plant(root, mode=0o777)
    m = marker("open")
    p, _ = swim_run("open", env_with(SWIM_CACHE=root, SWIM_TEST_MARKER=m, TMPDIR=fresh_tmpdir("open")))
    check(not os.path.exists(m), "a kernel.so in a world-writable cache folder was loaded")
    check(p.returncode == 0, "world-writable cache: exit %d %s" % (p.returncode, p.stderr))
    check("every user" in p.stderr, "world-writable cache: stderr should say why it is not used: " + p.stderr)
    # the same folder under a parent that everyone can write (no sticky bit)
    parent = os.path.join(TMP, "open-parent")
    os.makedirs(parent, exist_ok=True)
    os.chmod(parent, 0o777)
    root2 = os.path.join(parent, "cache")
    plant(root2)
    m = marker("open-parent")
    p, _ = swim_run("open-parent", env_with(SWIM_CACHE=root2, SWIM_TEST_MARKER=m, TMPDIR=fresh_tmpdir("open-parent")))
    check(not os.path.exists(m), "a cache under a world-writable parent (no sticky bit) was used")


def test_group_writable_entry_file():
    root = os.path.join(TMP, "gw-cache")
    entry = plant(root)
    os.chmod(os.path.join(entry, "kernel.so"), 0o775)
    m = marker("gw")
    p, _ = swim_run("gw", env_with(SWIM_CACHE=root, SWIM_TEST_MARKER=m))
    check(not os.path.exists(m), "a group-writable kernel.so was loaded")
    check(p.returncode == 0, "group-writable kernel.so: the run should rebuild it: exit %d %s" % (p.returncode, p.stderr))


def test_entry_file_of_another_user():
    if not IS_ROOT:
        print("skipped: an entry file of another user needs root (chown)")
        return
    root = os.path.join(TMP, "foreign-file-cache")
    entry = plant(root)
    for f in ("kernel.so", "manifest"):
        os.chown(os.path.join(entry, f), NOBODY, NOBODY)
    m = marker("foreign")
    p, _ = swim_run("foreign", env_with(SWIM_CACHE=root, SWIM_TEST_MARKER=m))
    check(not os.path.exists(m), "a kernel.so owned by another user was loaded from one's own cache")
    check(p.returncode == 0, "foreign kernel.so: exit %d %s" % (p.returncode, p.stderr))


def test_symlinked_kernel():
    root = os.path.join(TMP, "link-cache")
    entry = plant(root)
    target = os.path.join(TMP, "elsewhere.so")
    shutil.move(os.path.join(entry, "kernel.so"), target)
    os.symlink(target, os.path.join(entry, "kernel.so"))
    m = marker("link")
    p, _ = swim_run("link", env_with(SWIM_CACHE=root, SWIM_TEST_MARKER=m))
    check(not os.path.exists(m), "a kernel.so that is a symbolic link was loaded")
    check(p.returncode == 0, "symlinked kernel.so: exit %d %s" % (p.returncode, p.stderr))


# ---- a cache that cannot be written ------------------------------------------------------------

def test_unwritable_cache_leaves_nothing():
    """A cache that cannot be written (here a path through /dev/null): kernels are built in a
    private folder, which is gone when the run ends."""
    tmpdir = fresh_tmpdir("unwritable")
    for i in range(2):
        p, out = swim_run("unwritable%d" % i, env_with(SWIM_CACHE="/dev/null/swim", TMPDIR=tmpdir))
        check(p.returncode == 0, "unwritable cache: exit %d %s" % (p.returncode, p.stderr))
    check(not private_leftovers(tmpdir), "unwritable cache: left %s" % private_leftovers(tmpdir))


# ---- a cached kernel changed under a running run ---------------------------------------------

def test_kernel_overwritten_while_running():
    """truncate + new bytes over the cached kernel.so while a run executes it: the run is not
    killed by SIGBUS; it finishes and writes its summary."""
    cache = os.path.join(TMP, "overwrite-cache")
    shutil.rmtree(cache, ignore_errors=True)
    env = env_with(SWIM_CACHE=cache)
    p, _ = swim_run("overwrite-warm", env)             # the entry exists before the long run
    sos = glob.glob(os.path.join(cache, "*", "kernel.so"))
    check(p.returncode == 0 and len(sos) == 1, "overwrite: no cache entry was made")
    if not sos:
        return
    out = os.path.join(TMP, "overwrite")
    proc = subprocess.Popen([SWIM, "run", SCENE, "--out", out, "--quiet", "--t-end", "4000", "--summary-only"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT, env=env)
    time.sleep(0.5)
    with open(sos[0], "r+b") as fh:                    # in place, as cp and truncate do
        fh.truncate(0)
        fh.write(b"\0" * 100)
    try:
        _, err = proc.communicate(timeout=5)
    except subprocess.TimeoutExpired:                  # a long run: stop it, it must still report
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=30)
    check(proc.returncode in (0, 1), "overwritten kernel.so: the run died with %d: %s" % (proc.returncode, err))
    check(os.path.exists(os.path.join(out, "summary.json")), "overwritten kernel.so: no summary.json")
    # and the damaged entry is noticed and rebuilt by the next run
    p, _ = swim_run("overwrite-after", env)
    check(p.returncode == 0 and "damaged" in p.stderr, "the damaged entry should be rebuilt: %d %s" % (p.returncode, p.stderr))


def test_file_size_limit_smaller_than_the_kernel():
    """RLIMIT_FSIZE below kernel.so's size (it applies to the private copy too): a sound entry
    still loads, and is neither called damaged nor rebuilt."""
    import resource
    cache = os.path.join(TMP, "fsize-cache")
    shutil.rmtree(cache, ignore_errors=True)
    env = env_with(SWIM_CACHE=cache)
    swim_run("fsize-warm", env)

    def limit():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (8192, 8192))
    out = os.path.join(TMP, "fsize")
    p = subprocess.run([SWIM, "run", SCENE, "--out", out, "--quiet", "--t-end", "0.1", "--summary-only"],
                       capture_output=True, text=True, cwd=ROOT, env=env, preexec_fn=limit)
    check(p.returncode == 0 and "damaged" not in p.stderr, "kernel under a file-size limit: exit %d %s" % (p.returncode, p.stderr))


# ---- interrupted builds ------------------------------------------------------------------------

def children_of(pid):
    kids = []
    for status in glob.glob("/proc/[0-9]*/status"):
        try:
            fields = dict(l.split(":\t", 1) for l in open(status).read().splitlines() if ":\t" in l)
        except OSError:
            continue
        if fields.get("PPid", "").strip() == str(pid):
            kids.append(int(status.split("/")[2]))
    return kids


def alive(pid):
    try:
        with open("/proc/%d/status" % pid) as fh:
            return "\nState:\tZ" not in fh.read()
    except OSError:
        return False


def start_generation(name, sig):
    """swim inspect of N = 11 in a fresh cache (a generation of several seconds), sent `sig`
    while its generator runs. (process, generator pid, cache)."""
    cache = os.path.join(TMP, "gen-" + name)
    shutil.rmtree(cache, ignore_errors=True)
    shape = ",".join(["1"] + ["0"] * 23)
    # SIGINT at its default action, as in a terminal (a shell's background job inherits it ignored)
    proc = subprocess.Popen([SWIM, "inspect", "--modes", "11", "--shape", shape], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd=ROOT, env=env_with(SWIM_CACHE=cache),
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    gen = None
    # the generator itself (python .../generate.py), not an earlier short child such as the
    # compiler's --version for the cache key: the signal must land while generation runs, however
    # slowly a loaded machine starts it
    deadline = time.time() + 60
    while gen is None and time.time() < deadline and proc.poll() is None:
        gen = next((k for k in children_of(proc.pid) if b"generate.py" in cmdline(k)), None)
        time.sleep(0.05)
    time.sleep(0.3)
    proc.send_signal(sig)
    return proc, gen, cache


def cmdline(pid):
    try:
        with open("/proc/%d/cmdline" % pid, "rb") as fh:
            return fh.read()
    except OSError:
        return b""


def test_ctrl_c_during_generation():
    proc, gen, cache = start_generation("int", signal.SIGINT)
    check(gen is not None, "interrupted generation: the generator was never seen running")
    err = ""
    try:
        _, err = proc.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        proc.kill()
        check(False, "SIGINT during generation: swim did not end")
    time.sleep(0.2)
    check(gen is None or not alive(gen), "SIGINT during generation: the generator keeps running")
    check(proc.returncode == -signal.SIGINT, "SIGINT during generation: exit %s, want death by SIGINT "
          "(stderr: %s)" % (proc.returncode, (err or "").strip()[-400:]))
    left = [f for f in glob.glob(os.path.join(cache, "*", "*")) if ".tmp" in os.path.basename(f)]
    check(not left, "SIGINT during generation: temporary files left: %s" % left)
    check(not glob.glob(os.path.join(cache, "*", "manifest")), "SIGINT during generation: an entry was recorded")


def test_kill_during_generation():
    """SIGKILL cannot be caught: the generator must still end with swim."""
    proc, gen, cache = start_generation("kill", signal.SIGKILL)
    proc.communicate(timeout=30)
    deadline = time.time() + 10
    while gen is not None and alive(gen) and time.time() < deadline:
        time.sleep(0.1)
    check(gen is None or not alive(gen), "SIGKILL during generation: the generator outlived swim")


def test_stale_temporary_files_removed():
    """What an interrupted build left is removed by the next build of that entry."""
    src = legit_entry()
    cache = os.path.join(TMP, "stale-cache")
    shutil.rmtree(cache, ignore_errors=True)
    entry = os.path.join(cache, os.path.basename(src))
    os.makedirs(entry)
    for name in ("kernel.c.tmp99999", "kernel.so.tmp99998"):
        with open(os.path.join(entry, name), "w") as fh:
            fh.write("half")
    p, _ = swim_run("stale", env_with(SWIM_CACHE=cache))
    left = [f for f in os.listdir(entry) if ".tmp" in f]
    check(p.returncode == 0 and not left, "stale temporary files: exit %d, left %s" % (p.returncode, left))


if __name__ == "__main__":
    sys.exit(main(globals(), "test_trust_cache"))

#!/usr/bin/env python3
"""An animation of one `swim run` output directory: DIR/animation.mp4.

Usage: animate_run.py DIR [--fps F] [--duration S] [--out FILE]

Left: the body coloured by its density rho0/J, the fluid velocity around it (arrows), the path
of the centre of mass so far. Right: the energy distribution (stacked) with a time cursor.
Frames are evenly spaced in simulated time over the rows of DIR/trajectory.csv; the body and
flow of each frame come from `swim flow DIR --frames K` ($SWIM_BIN, or bin/swim of this tree).
Each frame is drawn by matplotlib (Agg) into a raw RGB buffer piped to ffmpeg (H.264, yuv420p,
playable by browsers). Progress goes to stderr.

Also writes a still (the frame at one third) next to the video: DIR/animation.png.
Defaults: 25 frames per second, duration = simulated time clamped to [4, 20] s.
Exit status: 0 written, 1 failed (ffmpeg missing, swim flow failed), 2 bad arguments.
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import plot_run  # noqa: E402  (the readers and the density drawing are shared)

WIDTH, HEIGHT, DPI = 1280, 720, 100


def fail(msg, status=1):
    print("swim animate: " + msg, file=sys.stderr)
    sys.exit(status)


def parse_args(argv):
    usage = "usage: swim animate DIR [--fps F] [--duration S] [--out FILE]"
    opts = {"fps": None, "duration": None, "out": None}
    outdir = None
    i = 0
    while i < len(argv):
        a = argv[i]
        if a in ("-h", "--help"):
            print(__doc__.strip())
            sys.exit(0)
        if a.startswith("--"):
            name, eq, val = a[2:].partition("=")
            if name not in opts:
                fail("unknown option '--%s' (%s)" % (name, usage), 2)
            if not eq:
                if i + 1 >= len(argv):
                    fail("option '--%s' needs a value" % name, 2)
                i += 1
                val = argv[i]
            opts[name] = val
        elif outdir is None:
            outdir = a
        else:
            fail("unexpected argument '%s' (%s)" % (a, usage), 2)
        i += 1
    if outdir is None:
        fail(usage, 2)
    for name, lo, hi in (("fps", 1, 120), ("duration", 0.1, 3600)):
        if opts[name] is not None:
            try:
                v = float(opts[name])
            except ValueError:
                fail("--%s: '%s' is not a number" % (name, opts[name]), 2)
            if not (lo <= v <= hi):
                fail("--%s: %s is out of range %g..%g" % (name, opts[name], lo, hi), 2)
            opts[name] = v
    return outdir, opts


def energy_parts(cols):
    parts = []
    for name, label, colour in (("kinetic_fluid", "kinetic, fluid", "tab:blue"),
                                ("kinetic_shape", "kinetic, deformations", "tab:orange"),
                                ("kinetic_rigid", "kinetic, rigid motion", "tab:green")):
        if name in cols:
            parts.append((label, cols[name], colour))
    w2 = cols.get("w2")
    if "w1" in cols and w2 is not None and plot_run.absmax(w2) > 0:
        parts.append(("potential W1", cols["w1"], "tab:purple"))
        parts.append(("barrier W2", w2, "tab:brown"))
    elif "potential" in cols:
        parts.append(("potential", cols["potential"], "tab:purple"))
    return parts


def window(snaps, path_xy, size):
    """Fixed view containing every body and the path when it is compact, else None (follow)."""
    xs = np.concatenate([s["boundary"][0] for s in snaps if s["boundary"] is not None] + [path_xy[0]])
    ys = np.concatenate([s["boundary"][1] for s in snaps if s["boundary"] is not None] + [path_xy[1]])
    xs, ys = xs[np.isfinite(xs)], ys[np.isfinite(ys)]
    if max(plot_run.span(xs), plot_run.span(ys)) > 3.5 * size:
        return None
    m = 0.3 * size
    cx, cy = 0.5 * (xs.min() + xs.max()), 0.5 * (ys.min() + ys.max())
    half = 0.5 * max(plot_run.span(xs), plot_run.span(ys)) + m
    return (cx - half, cx + half, cy - half, cy + half)


def reuse_mesh(mesh, density):
    """Moves the Gouraud mesh of the previous frame to this frame's grid, which has the same
    shape (creating a new QuadMesh costs as much as drawing it). False when it cannot."""
    if mesh is None or density is None or getattr(mesh, "_shading", None) != "gouraud":
        return False
    X, Y, R = density
    coords = getattr(mesh, "_coordinates", None)
    if coords is None or coords.shape != X.shape + (2,) or not np.isfinite(R).all():
        return False
    coords[..., 0] = X
    coords[..., 1] = Y
    mesh.set_array(R.ravel() if np.ndim(mesh.get_array()) == 1 else R)
    mesh.stale = True
    return True


def main(argv):
    outdir, opts = parse_args(argv)
    if shutil.which("ffmpeg") is None:
        fail("ffmpeg not found (Debian package ffmpeg; `make deps-media` installs it)")
    run = plot_run.Run(outdir)
    if run.cols is None or "t" not in run.cols or len(run.cols["t"]) < 2:
        fail("%s: no usable trajectory.csv (%s)" % (outdir, run.csv_error or "fewer than 2 rows"))
    cols = run.cols
    t = cols["t"]
    ok = np.isfinite(t)
    t0, t1 = float(t[ok][0]), float(t[ok][-1])
    fps = opts["fps"] or 25.0
    duration = opts["duration"] or min(max(t1 - t0, 4.0), 20.0)
    frames = max(2, int(round(fps * duration)))
    out = opts["out"] or os.path.join(outdir, "animation.mp4")
    # A target that exists and is no regular file (/dev/null, a FIFO) is written in place once
    # the video is whole: renaming over it would turn the device into a regular file. Such a
    # target has no poster beside it.
    if os.path.isdir(out):
        fail("--out: cannot write '%s': it is a folder" % out, 2)
    in_place = os.path.exists(out) and not os.path.isfile(out)
    target_dir = os.path.dirname(os.path.abspath(out))
    if in_place and not os.access(out, os.W_OK) or not in_place and not os.access(target_dir, os.W_OK):
        fail("--out: cannot write '%s': %s" % (out, "permission denied" if os.path.isdir(target_dir)
                                                 else "no folder " + target_dir), 2)
    work_dir = tempfile.mkdtemp(prefix="swim-animate-") if in_place else None
    part = os.path.join(work_dir, "animation.mp4") if in_place else out + ".part.mp4"
    poster = None if in_place else os.path.splitext(out)[0] + ".png"
    clock = time.time()

    print("swim animate: computing %d flow frames (swim flow)" % frames, file=sys.stderr)
    fd, tmp = tempfile.mkstemp(suffix=".json", prefix="frames-", dir=outdir)
    os.close(fd)
    try:
        p = subprocess.run([plot_run.swim_binary(), "flow", outdir, "--frames", str(frames),
                            "--out", tmp], capture_output=True, text=True)
        if p.returncode != 0:
            fail("swim flow failed: " + p.stderr.strip()[:400])
        with open(tmp) as fh:
            snaps = plot_run.parse_snapshots(json.load(fh))
    finally:
        os.remove(tmp)
    if len(snaps) != frames:
        fail("swim flow returned %d frames, expected %d" % (len(snaps), frames))

    # shared scales: density colours, arrow length, view
    norm = plot_run.density_norm(snaps)
    size = max(max(plot_run.span(s["boundary"][0]), plot_run.span(s["boundary"][1]))
               for s in snaps if s["boundary"] is not None)
    speeds = np.concatenate([np.hypot(s["arrows"][2], s["arrows"][3])
                             for s in snaps if s["arrows"] is not None] or [np.zeros(0)])
    speeds = speeds[np.isfinite(speeds)]
    vref = float(np.percentile(speeds, 98)) if speeds.size else 0.0
    x, y = cols.get("x", np.zeros_like(t)), cols.get("y", np.zeros_like(t))
    view = window(snaps, (x, y), size)
    width = (view[1] - view[0]) if view else 2.6 * size
    qscale = vref / (0.08 * width) if vref > 0 else 1.0

    fig = plt.figure(figsize=(WIDTH / DPI, HEIGHT / DPI), dpi=DPI)
    axb = fig.add_axes((0.04, 0.08, 0.46, 0.82))
    axe = fig.add_axes((0.62, 0.30, 0.36, 0.58))
    fig.suptitle(run.name(), fontsize=12)
    axb.set_aspect("equal")
    axb.set_xlabel(plot_run.with_unit("$x$", plot_run.LENGTH))
    axb.set_ylabel(plot_run.with_unit("$y$", plot_run.LENGTH))
    axb.grid(alpha=0.25)
    parts = energy_parts(cols)
    lower = np.zeros_like(t)
    for label, v, colour in parts:
        axe.fill_between(t, lower, lower + v, color=colour, alpha=0.75, lw=0, label=label)
        lower = lower + v
    if "energy" in cols:
        axe.plot(t, cols["energy"], color="k", lw=1.2, label="total energy")
    axe.set_xlim(t0, t1)
    axe.set_xlabel(plot_run.T_LABEL)
    axe.set_ylabel(plot_run.with_unit("energy", newline=True))
    axe.set_title("distribution of energy", fontsize=10)
    axe.grid(alpha=0.3)
    axe.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2, fontsize=8, frameon=False)
    cursor = axe.axvline(t0, color="k", lw=1.5)
    sm = plt.cm.ScalarMappable(norm=norm, cmap="viridis")
    cax = fig.add_axes((0.505, 0.15, 0.01, 0.6))
    fig.colorbar(sm, cax=cax).set_label(plot_run.with_unit(r"density $\rho_0/J$"), fontsize=9)
    cax.tick_params(labelsize=7)
    (outline,) = axb.plot([], [], color="k", lw=1.2)
    (trail,) = axb.plot([], [], color="k", ls="--", lw=1.0)
    (dot,) = axb.plot([], [], "o", color="k", ms=4, zorder=6)
    stamp = axb.text(0.02, 0.97, "", transform=axb.transAxes, va="top", fontsize=10)
    a0 = snaps[0]["arrows"]
    quiv = None
    if a0 is not None:
        quiv = axb.quiver(a0[0], a0[1], a0[2], a0[3], color="tab:green", angles="xy",
                          scale_units="xy", scale=qscale, width=0.004, zorder=4)
        axb.quiverkey(quiv, 0.80, 0.03, vref, "fluid speed %.2g" % vref, labelpos="E",
                      coordinates="axes", fontproperties={"size": 8})
    if view:
        axb.set_xlim(view[0], view[1])
        axb.set_ylim(view[2], view[3])

    cmd = ["ffmpeg", "-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgba",
           "-s", "%dx%d" % (WIDTH, HEIGHT), "-r", "%g" % fps, "-i", "-", "-an",
           "-c:v", "libx264", "-preset", "ultrafast", "-crf", "26", "-pix_fmt", "yuv420p",
           "-movflags", "+faststart", part]
    enc = subprocess.Popen(cmd, stdin=subprocess.PIPE)
    mesh = None
    last = 0.0
    # Blitting: with a fixed view everything but the moving artists is drawn once and restored
    # from a saved image for each frame (about 3x faster than a full redraw).
    moving = [outline, trail, dot, stamp, cursor] + ([quiv] if quiv is not None else [])
    background = None
    if view:
        for a in moving:
            a.set_animated(True)
        fig.canvas.draw()
        background = fig.canvas.copy_from_bbox(fig.bbox)
    try:
        for i, s in enumerate(snaps):
            if not reuse_mesh(mesh, s["density"]):
                if mesh is not None:
                    mesh.remove()
                    mesh = None
                if s["density"] is not None:
                    mesh = plot_run.draw_density(axb, s["density"], norm)
                    if mesh is not None and background is not None:
                        mesh.set_animated(True)
            if s["boundary"] is not None:
                bx, by = s["boundary"]
                outline.set_data(np.append(bx, bx[:1]), np.append(by, by[:1]))
            m = t <= s["t"] + 1e-12
            trail.set_data(x[m], y[m])
            px, py = s["pos"]
            dot.set_data([px], [py])
            if quiv is not None and s["arrows"] is not None:
                X, Y, U, V = s["arrows"]
                quiv.set_offsets(np.column_stack([X, Y]))
                quiv.set_UVC(U, V)
            if not view:
                axb.set_xlim(px - 1.3 * size, px + 1.3 * size)
                axb.set_ylim(py - 1.3 * size, py + 1.3 * size)
            cursor.set_xdata([s["t"], s["t"]])
            stamp.set_text("t = %.2f" % s["t"])
            if background is not None:
                fig.canvas.restore_region(background)
                for a in ([mesh] if mesh is not None else []) + moving:
                    a.axes.draw_artist(a)
            else:
                fig.canvas.draw()
            enc.stdin.write(fig.canvas.buffer_rgba())
            if i == frames // 3 and poster:   # a still for the page (<video poster>) and for a quick look
                plt.imsave(poster, np.asarray(fig.canvas.buffer_rgba()))
            now = time.time()
            if now - last > 1.0 or i == frames - 1:
                print("\rswim animate: frame %d / %d (t = %.3g)   " % (i + 1, frames, s["t"]),
                      end="", file=sys.stderr)
                last = now
        enc.stdin.close()
        rc = enc.wait()
    except BrokenPipeError:
        rc = enc.wait() or 1
    print("", file=sys.stderr)
    try:
        if rc != 0:
            fail("ffmpeg failed (exit status %d)" % rc)
        if in_place:
            with open(part, "rb") as src, open(out, "wb") as dst:
                shutil.copyfileobj(src, dst)
        else:
            os.replace(part, out)
    except OSError as exc:
        fail("--out: cannot write '%s': %s" % (out, exc.strerror or exc))
    finally:
        if os.path.exists(part):
            os.remove(part)
        if work_dir:
            shutil.rmtree(work_dir, ignore_errors=True)
    print(out)
    print("swim animate: %d frames at %g fps (%.1f s of video for t = %.4g..%.4g) in %.1f s"
          % (frames, fps, frames / fps, t0, t1, time.time() - clock), file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

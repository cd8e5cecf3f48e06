#!/usr/bin/env python3
"""swim generator: derive the N-mode model with SymPy and write specialized C kernels.

    generate.py --modes 0 1 2 7 --out generated        kernels (the contract they implement is
                                                       the hand-written runtime/kernel/swim_kernel.h)
    generate.py --table 0 1 2 7 --out build/table.c    the table of kernels linked into a build
    generate.py --scene structure.json --out k.c       a kernel specialized to one scene structure
    generate.py --stroke structure.json --out k.c      the laws of a prescribed stroke and their
                                                       exact derivatives (swimgen/stroke.py)

Output is deterministic: the same SymPy version writes byte-identical files.
"""

import argparse
import json
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from swimgen.emit import kernel_source, scene_kernel_source, table_source  # noqa: E402
from swimgen.law import LawError  # noqa: E402
from swimgen.stroke import stroke_kernel_source  # noqa: E402

MAX_MODES = 32   # SWIM_KERNEL_MAX_MODES in runtime/kernel/swim_kernel.h


def write_if_changed(path, text):
    old = None
    if os.path.exists(path):
        with open(path, encoding="utf-8") as fh:
            old = fh.read()
    if old != text:   # written under a temporary name, then renamed: never a partial file
        tmp = "%s.tmp%d" % (path, os.getpid())
        with open(tmp, "w", encoding="utf-8") as fh:
            fh.write(text)
        os.replace(tmp, path)


# Exit status of --stroke when a law is valid but cannot be a stroke (runtime/codegen/codegen.c).
STROKE_LAW_REFUSED = 3


def _stroke(args):
    try:
        with open(args.stroke, encoding="utf-8") as fh:
            structure = json.load(fh)
        text = stroke_kernel_source(structure, "generator/generate.py --stroke %s --out %s"
                                    % (os.path.basename(args.stroke), os.path.basename(args.out)))
    except LawError as exc:
        # exit 3 and the coordinate's index: bin/swim names the scene's key and refuses the scene
        index = getattr(exc, "index", None)
        if index is not None:
            print("refused law %d: %s" % (index, exc), file=sys.stderr)
            return STROKE_LAW_REFUSED
        print("generate.py: --stroke %s: stroke law: %s" % (args.stroke, exc), file=sys.stderr)
        return 2
    except (OSError, ValueError, KeyError, TypeError) as exc:
        print("generate.py: --stroke %s: %s" % (args.stroke, exc), file=sys.stderr)
        return 2
    write_if_changed(args.out, text)
    return 0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--modes", type=int, nargs="*", default=[], help="mode counts N to generate")
    ap.add_argument("--table", type=int, nargs="*", help="write the kernel table for these N")
    ap.add_argument("--scene", help="scene structure (JSON written by bin/swim) to specialize")
    ap.add_argument("--stroke", help="stroke structure (JSON written by bin/swim) to emit")
    ap.add_argument("--out", required=True, help="output folder (or file, with --table)")
    ap.add_argument("--quiet", action="store_true")
    args = ap.parse_args(argv)

    for k in args.modes + (args.table or []):
        if not 0 <= k <= MAX_MODES:
            print("generate.py: --modes: N = %d is out of range 0..%d" % (k, MAX_MODES),
                  file=sys.stderr)
            return 2

    if args.stroke:
        return _stroke(args)

    if args.scene:
        try:
            with open(args.scene, encoding="utf-8") as fh:
                structure = json.load(fh)
            text = scene_kernel_source(structure, "generator/generate.py --scene %s --out %s"
                                       % (os.path.basename(args.scene), os.path.basename(args.out)))
        except LawError as exc:
            print("generate.py: --scene %s: forcing law: %s" % (args.scene, exc), file=sys.stderr)
            return 2
        except (OSError, ValueError, KeyError, TypeError) as exc:
            print("generate.py: --scene %s: %s" % (args.scene, exc), file=sys.stderr)
            return 2
        write_if_changed(args.out, text)
        return 0

    if args.table is not None:
        cmd = "generator/generate.py --table %s --out %s" % (
            " ".join(map(str, args.table)), args.out)
        os.makedirs(os.path.dirname(args.out) or ".", exist_ok=True)
        write_if_changed(args.out, table_source(sorted(set(args.table)), cmd))
        return 0

    os.makedirs(args.out, exist_ok=True)
    for k in args.modes:
        t0 = time.perf_counter()
        cmd = "generator/generate.py --modes %d --out %s" % (k, args.out)
        text = kernel_source(k, cmd)
        path = os.path.join(args.out, "swim_kernel_n%d.c" % k)
        write_if_changed(path, text)
        if not args.quiet:
            print("%s: %d lines, %.2f s" % (path, text.count("\n"), time.perf_counter() - t0))
    return 0


if __name__ == "__main__":
    sys.exit(main())

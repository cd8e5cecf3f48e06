#!/usr/bin/env python3
"""The `swim sweep` arguments for initial data on the curve (4.17) of the paper (Examples 1, 2):

  c(t) = (1, 0, g cos b, 0, 0, g sin b / sqrt 2, 0, ...),  so at t = 0
  c0:  a_-1 = g cos b0,           b_-2 = g sin b0 / sqrt 2
  c'0: a'_-1 = -g sin b0 * b'0,   b'_-2 = g cos b0 * b'0 / sqrt 2   (ERRATA D1; G1 and G2 hold)

Usage: reduction_members.py --gamma G --beta0 B0 --betadot V1,V2,... [--beta0 B0' --betadot ...]
Each --beta0 pairs with the --betadot list that follows it; values may use `pi` (e.g. pi/3).
Prints `--zip --vary shape.c0.am1=... --vary shape.c0.bm2=... --vary shape.dc0.am1=...
--vary shape.dc0.bm2=...` (17 significant digits) for the command line of swim sweep."""
import math
import sys


def number(text):
    return float(eval(text, {"__builtins__": {}}, {"pi": math.pi, "sqrt": math.sqrt}))


def main(argv):
    gamma, pairs, b0 = None, [], None
    i = 1
    while i < len(argv):
        opt, val = argv[i], argv[i + 1] if i + 1 < len(argv) else None
        if val is None:
            break
        if opt == "--gamma":
            gamma = number(val)
        elif opt == "--beta0":
            b0 = number(val)
        elif opt == "--betadot" and b0 is not None:
            pairs += [(b0, number(v)) for v in val.split(",")]
        else:
            break
        i += 2
    if gamma is None or not pairs or i != len(argv):
        print(__doc__, file=sys.stderr)
        return 2
    s2 = math.sqrt(2.0)
    cols = {"shape.c0.am1": [gamma * math.cos(b) for b, _ in pairs],
            "shape.c0.bm2": [gamma * math.sin(b) / s2 for b, _ in pairs],
            "shape.dc0.am1": [-gamma * math.sin(b) * v for b, v in pairs],
            "shape.dc0.bm2": [gamma * math.cos(b) * v / s2 for b, v in pairs]}
    print("--zip " + " ".join("--vary %s=%s" % (k, ",".join("%.17g" % x for x in v)) for k, v in cols.items()))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))

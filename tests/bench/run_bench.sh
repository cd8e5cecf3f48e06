#!/usr/bin/env bash
# Runs every benchmark program in turn; each prints its own table and writes its
# results under build/bench/. Medians and ratios are computed inside each program.
set -eu
mkdir -p build/bench
for prog in "$@"; do
    echo "== $prog"
    case "$prog" in
        *.py) "${PYTHON:-/usr/bin/python3}" "$prog" ;;
        *) "$prog" ;;
    esac
done

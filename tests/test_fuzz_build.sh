#!/usr/bin/env bash
# `make fuzz` can build on this machine: every source of every fuzz target compiles under clang
# (the runtime is written for gcc and clang alike), and a target links with libFuzzer and the
# sanitizer runtimes and runs (tests/fuzz/run_fuzz.sh --check; the campaign itself is make fuzz).
set -u
cd "$(dirname "$0")/.."
pass=0; fail=0
ok() { pass=$((pass+1)); }
bad() { echo "FAIL: $*"; fail=$((fail+1)); }
work=$(mktemp -d /tmp/swim-fuzz-XXXXXX)
trap 'rm -rf "$work"' EXIT
if FUZZ_OUT="$work" bash tests/fuzz/run_fuzz.sh --check >"$work/check.log" 2>&1; then ok; else
    bad "run_fuzz.sh --check: $(tail -5 "$work/check.log")"; fi
n=$(ls tests/fuzz/fuzz_*.c | wc -l)
[ "$n" -ge 5 ] && ok || bad "only $n fuzz targets in tests/fuzz"
grep -q "clang compiles the [0-9]* sources" "$work/check.log" && ok || bad "no compile check in the log"
[ -x "$work/fuzz_toml" ] && ok || bad "fuzz_toml not built"
# a seed that is not valid TOML is not a crash: the target exits 0 on it
printf 'a = [1, 2\n[b\n' >"$work/bad.toml"
"$work/fuzz_toml" "$work/bad.toml" >/dev/null 2>&1 && ok || bad "fuzz_toml crashed on a malformed seed"
cat "$work/check.log" | grep -v warning | grep -E "^(clang|fuzz_toml)" || true
echo "test_fuzz_build: $pass passed, $fail failed"
[ "$fail" -eq 0 ]

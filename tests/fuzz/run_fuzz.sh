#!/usr/bin/env bash
# Fuzz the TOML reader with libFuzzer (clang, ASan + UBSan).
#   bash tests/fuzz/run_fuzz.sh [SECONDS]      (default 30)
# Seeds: models/*.toml and tests/fuzz/corpus/*; the working corpus, a dictionary and any crash
# artifacts go to build/fuzz/. Exits non-zero if the fuzzer finds a crash, leak or invariant
# failure (the reproducer is left in build/fuzz/artifacts/; rerun it with
#   build/fuzz/fuzz_toml build/fuzz/artifacts/<file>).
set -euo pipefail
secs="${1:-30}"
case "$secs" in ''|*[!0-9]*) echo "usage: $0 [seconds]" >&2; exit 2 ;; esac
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
cd "$root"
CLANG="${CLANG:-clang}"
command -v "$CLANG" >/dev/null || CLANG=/usr/bin/clang
out=build/fuzz
mkdir -p "$out/corpus" "$out/artifacts"

"$CLANG" -g -O1 -std=c11 -D_POSIX_C_SOURCE=200809L -fsanitize=fuzzer,address,undefined \
    -fno-sanitize-recover=undefined -Iruntime \
    tests/fuzz/fuzz_toml.c runtime/scene/toml.c -o "$out/fuzz_toml" -lm

# fresh seeds each run (the working corpus keeps what earlier runs found)
for f in models/*.toml tests/fuzz/corpus/*; do
    [ -f "$f" ] && cp -f "$f" "$out/corpus/seed_$(basename "$f")"
done

cat > "$out/toml.dict" <<'DICT'
"="
"."
","
"["
"]"
"[["
"]]"
"{"
"}"
"#"
"\""
"'"
"\"\"\""
"'''"
"\\u00e9"
"\\U0001F600"
"\\n"
"true"
"false"
"inf"
"-inf"
"nan"
"0x"
"0o"
"0b"
"1e-3"
"_"
"\x0a"
"\x0d\x0a"
"[a.b]"
"[[a]]"
"a.b = 1"
"{ a = 1 }"
"9223372036854775807"
"-9223372036854775808"
"1979-05-27"
DICT

echo "fuzzing for ${secs}s: $out/fuzz_toml"
set +e
"$out/fuzz_toml" "$out/corpus" -dict="$out/toml.dict" -max_total_time="$secs" \
    -max_len=4096 -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
    -artifact_prefix="$out/artifacts/" 2>"$out/fuzz.log"
rc=$?
set -e
grep -E '^(#[0-9]+ +DONE|stat::number_of_executed_units|stat::peak_rss_mb|Done )' "$out/fuzz.log" || true
if [ "$rc" -ne 0 ]; then
    echo "fuzzer FAILED (exit $rc); last lines of $out/fuzz.log:" >&2
    tail -n 40 "$out/fuzz.log" >&2
    ls -1 "$out/artifacts" >&2 || true
    exit 1
fi
echo "fuzzer: no crashes"

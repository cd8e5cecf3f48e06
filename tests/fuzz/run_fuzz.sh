#!/usr/bin/env bash
# Fuzz the TOML reader, the whole scene reader, the command-line arguments, the quoting of user
# text in messages and the run-settings check with libFuzzer
# (clang, ASan + UBSan); each target (tests/fuzz/fuzz_*.c) runs for SECONDS (default 30).
#   bash tests/fuzz/run_fuzz.sh [SECONDS]
#   bash tests/fuzz/run_fuzz.sh --check   (what make test runs: every source of every target
#       compiles under clang, and the TOML target builds with libFuzzer and runs 500 inputs)
# Seeds: models/*.toml and tests/fuzz/corpus/*; the working corpus, a dictionary and any crash
# artifacts go to build/fuzz/ ($FUZZ_OUT). Exits non-zero if the fuzzer finds a crash, leak or
# invariant failure (the reproducer is left in build/fuzz/artifacts/; rerun it with
#   build/fuzz/fuzz_toml build/fuzz/artifacts/<file>).
set -euo pipefail
secs="${1:-30}"
case "$secs" in --check) ;; ''|*[!0-9]*) echo "usage: $0 [seconds | --check]" >&2; exit 2 ;; esac
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
cd "$root"
CLANG="${CLANG:-clang}"
command -v "$CLANG" >/dev/null || CLANG=/usr/bin/clang
if ! command -v "$CLANG" >/dev/null; then
    echo "make fuzz needs clang with libFuzzer: apt-get install clang libclang-rt-14-dev (make fuzz does it)" >&2
    exit 1
fi
out="${FUZZ_OUT:-build/fuzz}"
mkdir -p "$out/corpus" "$out/artifacts"
targets=$(ls tests/fuzz/fuzz_*.c | sed -E 's#.*/fuzz_(.*)\.c#\1#')

SAN=(-g -O1 -std=c11 -D_XOPEN_SOURCE=700 -fsanitize=address,undefined -fno-sanitize-recover=undefined
     -Wno-psabi -Iruntime -I/usr/include/sundials -I/usr/include/hdf5/serial)
# The TOML target needs the TOML reader only; the others link the runtime with the committed
# kernels (N = 0..7; bin/swim-mpi is built by make mpi).
"${PYTHON:-/usr/bin/python3}" generator/generate.py --table 0 1 2 3 4 5 6 7 --out "$out/kernel_table.c"
# (runtime/export/'s other .c files are copied into exported trees, not linked into swim)
srcs="$(ls runtime/*/*.c generated/swim_kernel_n[0-7].c | grep -v -e 'runtime/cli/main.c' -e 'runtime/mpi/' \
        -e 'runtime/export/simulate.c' -e 'runtime/export/kernels.c' -e 'runtime/export/no_cvode.c') $out/kernel_table.c"

if [ "$secs" = --check ]; then
    n=0
    for f in $srcs tests/fuzz/fuzz_*.c; do
        "$CLANG" "${SAN[@]}" -fsyntax-only "$f" || { echo "clang cannot compile $f" >&2; exit 1; }
        n=$((n + 1))
    done
    echo "clang compiles the $n sources of the fuzz targets"
    "$CLANG" "${SAN[@]}" -fsanitize=fuzzer tests/fuzz/fuzz_toml.c runtime/scene/toml.c -o "$out/fuzz_toml" -lm
    cp -f models/*.toml "$out/corpus/"
    "$out/fuzz_toml" "$out/corpus" -runs=500 -max_len=4096 -timeout=10 -close_fd_mask=3 \
        -artifact_prefix="$out/artifacts/toml-" 2>"$out/fuzz_toml.log" \
        || { echo "fuzz_toml failed:" >&2; tail -n 20 "$out/fuzz_toml.log" >&2; exit 1; }
    echo "fuzz_toml built with libFuzzer and ran 500 inputs"
    exit 0
fi

# The runtime is compiled once, instrumented for coverage and the sanitizers
# (fuzzer-no-link), and each target links it with libFuzzer's main.
rm -rf "$out/obj" && mkdir -p "$out/obj"
export CLANG out
printf '%s\n' $srcs | xargs -P "$(nproc)" -I{} sh -c \
    'o="$out/obj/$(echo "{}" | tr / _).o"; "$CLANG" '"${SAN[*]}"' -fsanitize=fuzzer-no-link -c "{}" -o "$o"'
libs=(-ldl -lgsl -llapacke -llapack -lblas -lsundials_cvode -lsundials_nvecserial -ljansson -lquadmath -lm
      -L/usr/lib/x86_64-linux-gnu/hdf5/serial -lhdf5)
for t in $targets; do
    if [ "$t" = toml ]; then
        "$CLANG" "${SAN[@]}" -fsanitize=fuzzer tests/fuzz/fuzz_toml.c runtime/scene/toml.c -o "$out/fuzz_toml" -lm
    else
        "$CLANG" "${SAN[@]}" -fsanitize=fuzzer "tests/fuzz/fuzz_$t.c" "$out"/obj/*.o -o "$out/fuzz_$t" "${libs[@]}"
    fi
done

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

# Corpora: TOML seeds for the two parsers (the scene target starts from the paper's scenes),
# argument lists for the CLI target.
mkdir -p "$out/corpus_scene" "$out/corpus_cli" "$out/corpus_quote" "$out/corpus_settings"
cp -f models/*.toml models/hard/*.toml "$out/corpus_scene/" 2>/dev/null || true
cp -f tests/fuzz/corpus_cli/* "$out/corpus_cli/"
# quote: a title with an escape sequence, a newline, invalid UTF-8; settings: example3's values
# (t_end 30, output_step 0.05, rtol 1e-10, atol 1e-12) with a law singular at t = 1.
printf 'ti\x1b[2Jtle\nnext \xff\xc2\x9b \xe2\x80\xae' > "$out/corpus_quote/seed_escape"
"${PYTHON:-/usr/bin/python3}" -c "import struct,sys; sys.stdout.buffer.write(struct.pack('<4d', 30, 0.05, 1e-10, 1e-12) + b'\x03' + b'1/(t-1)')" \
    > "$out/corpus_settings/seed_example3"

status=0
for t in $targets; do
    corpus="$out/corpus"
    [ "$t" != toml ] && corpus="$out/corpus_$t"
    dict=()
    [ "$t" = toml ] || [ "$t" = scene ] && dict=(-dict="$out/toml.dict")
    echo "fuzzing $t for ${secs}s"
    set +e
    "$out/fuzz_$t" "$corpus" "${dict[@]}" -max_total_time="$secs" -max_len=4096 -timeout=10 \
        -rss_limit_mb=2048 -print_final_stats=1 -close_fd_mask=3 -artifact_prefix="$out/artifacts/$t-" 2>"$out/fuzz_$t.log"
    rc=$?
    set -e
    grep -E '^stat::number_of_executed_units' "$out/fuzz_$t.log" | sed "s/^/  $t: /" || true
    if [ "$rc" -ne 0 ]; then
        echo "fuzzer $t FAILED (exit $rc); last lines of $out/fuzz_$t.log:" >&2
        tail -n 40 "$out/fuzz_$t.log" >&2
        status=1
    fi
done
if [ "$status" -ne 0 ]; then
    ls -1 "$out/artifacts" >&2 || true
    exit 1
fi
echo "fuzz: $(wc -w <<<"$targets") passed, 0 failed"

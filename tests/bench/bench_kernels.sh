#!/usr/bin/env bash
# Kernel benchmark: for each N, generator seconds, emitted C lines, gcc -O2 seconds,
# and ns per evaluation of K and of K + contracted Gamma, side by side with the loop reference
# + central finite-difference Gamma. Writes build/bench/kernels.csv and prints a table.
set -eu
cd "$(dirname "$0")/../.."
PYTHON=${PYTHON:-/usr/bin/python3}
CC=${CC:-gcc}
out=build/bench/kernels; mkdir -p "$out"
csv=build/bench/kernels.csv
echo "N,gen_s,c_lines,gcc_s,ns_K,ns_K_gamma,ns_ref_K,ns_ref_K_fd_gamma,speedup_gamma" > "$csv"
printf '%4s %8s %8s %8s %10s %12s %12s %16s %9s\n' N gen_s lines gcc_s ns_K ns_K+Gamma ns_ref_K ns_ref+fdGamma speedup
for N in ${BENCH_MODES:-1 3 5 7 10 15 20}; do
    t0=$(date +%s.%N)
    PYTHONHASHSEED=0 "$PYTHON" generator/generate.py --modes "$N" --out "$out" --quiet
    t1=$(date +%s.%N)
    lines=$(wc -l < "$out/swim_kernel_n$N.c")
    "$CC" ${OPT:--O3 -march=native} -std=c11 -Iruntime -c "$out/swim_kernel_n$N.c" -o "$out/k$N.o"
    t2=$(date +%s.%N)
    "$CC" ${OPT:--O3 -march=native} -std=c11 -D_XOPEN_SOURCE=700 -DBENCH_N="$N" -Iruntime -Itests \
        tests/bench/bench_kernel.c tests/reference/ref_model.c "$out/k$N.o" -o "$out/bench_n$N" -lm
    row=$("$out/bench_n$N")
    gen=$(awk -v a="$t0" -v b="$t1" "BEGIN{print b-a}"); gcc_s=$(awk -v a="$t1" -v b="$t2" "BEGIN{print b-a}")
    IFS=, read -r _ nsK nsKG nsR nsRG <<<"$row"
    sp=$(awk -v a="$nsRG" -v b="$nsKG" "BEGIN{print a/b}")
    printf '%4d %8.2f %8d %8.2f %10.0f %12.0f %12.0f %16.0f %8.0fx\n' "$N" "$gen" "$lines" "$gcc_s" "$nsK" "$nsKG" "$nsR" "$nsRG" "$sp"
    printf '%d,%.3f,%d,%.3f,%s,%s,%s,%s,%.1f\n' "$N" "$gen" "$lines" "$gcc_s" "$nsK" "$nsKG" "$nsR" "$nsRG" "$sp" >> "$csv"
done
echo "(ns are medians of 7 repetitions; gen_s and gcc_s single runs; written to $csv)"

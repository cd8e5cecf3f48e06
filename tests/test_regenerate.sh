#!/usr/bin/env bash
# Regenerating the committed kernels must reproduce them byte for byte: run the generator in
# place and ask git whether generated/ changed.
set -u
cd "$(dirname "$0")/.."
pass=0; fail=0
if ! git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
    echo "test_regenerate: not a git checkout, nothing to compare"; echo "test_regenerate: 0 passed, 0 failed"; exit 0
fi
before=$(git status --porcelain generated)
make --no-print-directory -s generate-all >/dev/null || { echo "FAIL: make generate-all failed"; fail=$((fail+1)); }
after=$(git status --porcelain generated)
if [ "$before" = "$after" ]; then pass=$((pass+1)); else
    echo "FAIL: regenerating changed generated/:"; echo "$after"; fail=$((fail+1)); fi
echo "test_regenerate: $pass passed, $fail failed"
[ $fail -eq 0 ]

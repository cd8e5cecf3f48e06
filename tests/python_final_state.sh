# Sourced by the tests of an installed Python package (test_python_install.sh, test_python_pip.sh):
# the reference and the program that both compare, so that "the same bits as swim run" means one
# thing. python_reference DIR runs Example 3 to t = 5 with $SWIM into DIR/ref and prints its final
# state (t x y theta, repr of each double); PYTHON_RUN is a program that, given the scene, prints
# where swim was imported from, the library it loaded, its version and the same final state.
# ok / bad count the checks (pass, fail) both tests report.
pass=0; fail=0
ok() { pass=$((pass+1)); }
bad() { echo "FAIL: $*"; fail=$((fail+1)); }
python_reference() {
    "$SWIM" run models/example3.toml --out "$1/ref" --t-end 5 --quiet >/dev/null 2>&1
    /usr/bin/python3 -c "import json,sys; f=json.load(open(sys.argv[1]))['final_state']; print(' '.join(repr(float(f[k])) for k in ('t','x','y','theta')))" "$1/ref/summary.json"
}
# shellcheck disable=SC2034
PYTHON_RUN='import sys, swim
r = swim.run(sys.argv[1], t_end=5)
print(swim.__file__)
print(swim._L._name)
print(swim.__version__)
print(" ".join(repr(r.final_state[k]) for k in ("t", "x", "y", "theta")))'

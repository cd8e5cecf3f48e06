"""The Python package under bad input and limits (docs/trust.md, "The library, the kernel cache and
Python"): a NUL inside a string is refused, never cut; a refused override or event names its key
and the scene; a family is bounded before any member is made; a long family does not run out of
file descriptors."""
import os
import subprocess
import sys
import textwrap

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "python"))
import swim  # noqa: E402

EX3 = os.path.join(ROOT, "models", "example3.toml")


@pytest.mark.parametrize("call,key", [
    (lambda: swim.run(EX3 + "\0junk", t_end=0.1), "scene"),
    (lambda: swim.run(EX3, set={"model.rho0": "2\0junk"}, t_end=0.1), "model.rho0"),
    (lambda: swim.run(EX3, set={"model.rho0\0x": 2}, t_end=0.1), "model.rho0\0x"),
    (lambda: swim.run(EX3, t_end=0.1, events=["y:max\0junk"]), "events"),
    (lambda: swim.run(open(EX3).read() + "\0", t_end=0.1), "scene"),
    (lambda: swim.run(open(EX3).read(), name="a\0b", t_end=0.1), "name"),
], ids=["path", "value", "key", "event", "text", "name"])
def test_a_nul_is_refused_not_cut(call, key):
    with pytest.raises(swim.SceneError) as e:
        call()
    assert e.value.key == key and "NUL" in e.value.message


@pytest.mark.parametrize("value", [float("nan"), float("inf"), -float("inf"), "abc", True, "1 2"],
                         ids=["nan", "inf", "-inf", "word", "bool", "two-words"])
def test_a_refused_override_names_its_key_and_scene(value):
    with pytest.raises(swim.SceneError) as e:
        swim.run(EX3, set={"model.rho0": value}, t_end=0.1)
    assert e.value.key == "model.rho0" and e.value.file == EX3, (e.value.key, e.value.file, e.value.message)


@pytest.mark.parametrize("event", ["nosuchcolumn:max", "y:sideways", "y"])
def test_a_refused_event_names_events_and_the_scene(event):
    with pytest.raises(swim.SceneError) as e:
        swim.run(EX3, t_end=0.1, events=[event])
    assert e.value.key == "events" and e.value.file == EX3, (e.value.key, e.value.file, e.value.message)


def test_a_family_is_bounded_before_it_is_made():
    """10^9 members (one SPEC, or the product of two lists) are refused at once, nothing built."""
    with pytest.raises(swim.SceneError) as e:
        swim.sweep(EX3, vary={"model.rho0": "0.5:2:1000000000"}, t_end=0.1)
    assert e.value.key == "vary" and "1000000" in e.value.message
    with pytest.raises(swim.SceneError) as e:
        swim.sweep(EX3, vary={"model.rho0": range(1, 40001), "model.rhof": range(1, 40001)}, t_end=0.1)
    assert e.value.key == "model.rhof" and "more than 1000000" in e.value.message
    with pytest.raises(swim.SceneError):
        swim.spec_values("nan:1:3")


def test_a_long_family_keeps_no_descriptor_per_member():
    """40 members under a limit of 30 descriptors: each member's kernels are closed before the next
    is opened (a model kept per member would hold one or two descriptors each and run out)."""
    code = textwrap.dedent("""
        import resource, sys
        sys.path.insert(0, %r)
        import swim
        resource.setrlimit(resource.RLIMIT_NOFILE, (30, resource.getrlimit(resource.RLIMIT_NOFILE)[1]))
        rows = swim.sweep(%r, vary={"model.rho0": "1:2:40"}, t_end=0.05, output_step=0.05)
        print(sum(r["completed"] for r in rows))
    """) % (os.path.join(ROOT, "python"), EX3)
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0 and p.stdout.strip() == "40", (p.stdout, p.stderr[-2000:])
    assert "damaged" not in p.stderr and "rebuilding" not in p.stderr
